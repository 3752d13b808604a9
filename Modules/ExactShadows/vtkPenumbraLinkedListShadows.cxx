#include "vtkPenumbraLinkedListShadows.h"

#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkUnsignedCharArray.h"

#include "vtkPenumbraConservativeMapCPU.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraLinkedListCompute.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraLinkedListShadows);

using penumbra_light_views::View;
using penumbra_llsm::ListCompute;
using penumbra_llsm::NoNode;
using penumbra_rules::Hit;

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;

// Per-sample states. The first two are also the values of the mask the reference traces.
enum : unsigned char
{
  Settled = 0, // decided: lit, or shadowed with visibility 0 written
  Pending = 1, // to be listed; after the lists: to be traced
  Open = 2,    // listed, no triangle has decided it yet (lit if it stays so)
  Unknown = 3, // listed, a triangle could not be decided: traced unless another shadows it
  Shadowed = 4 // listed, a triangle provably blocks its ray
};

// Triangles in a perspective view's apex region are tested against every sample of the view;
// beyond this many, the view's open samples are traced instead.
constexpr size_t MaxNearTriangles = 256;

// Everything a sample test needs, for one light and call.
struct TestContext
{
  const penumbra_light_views::FrameInputs* In;
  double Diagonal;
  double Epsilon;
  double TieFactor;
  unsigned char* State;
  const double* Depth; // per sample: its stored depth in its view

  void Position(vtkIdType s, double p[3]) const
  {
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(this->In->Positions[3 * s + c]) + this->In->Shift[c];
    }
  }

  // The reference's decision for sample s and `triangle` (null: a triangle without area,
  // left to the tracer): a clear hit shadows, an undecidable one leaves it to the tracer
  // unless another triangle shadows it.
  void Test(vtkIdType s, const penumbra_rules::ExactTriangle* triangle) const
  {
    this->Test(s, this->Ray(s), triangle);
  }

  // Sample s's shadow ray, as the reference makes it.
  penumbra_light_views::ShadowRay Ray(vtkIdType s) const
  {
    double p[3];
    this->Position(s, p);
    return penumbra_light_views::MakeShadowRay(
      this->In->Light, p, this->Diagonal, this->Epsilon, this->TieFactor);
  }

  // The same with the sample's ray made already.
  void Test(vtkIdType s, const penumbra_light_views::ShadowRay& ray,
    const penumbra_rules::ExactTriangle* triangle) const
  {
    const Hit hit = triangle ? penumbra_light_views::TestShadowRay(ray, *triangle) : Hit::Unknown;
    if (hit == Hit::Clear)
    {
      this->State[s] = Shadowed;
    }
    else if (hit == Hit::Unknown)
    {
      this->State[s] = Unknown;
    }
  }
};

// The conservative depth test of Hertel et al. 2009, §4.2, as the conservative technique
// uses it: a triangle whose smallest stored depth over the texel lies beyond the sample's
// depth cannot meet the sample's ray, which runs towards smaller depths.
inline bool Behind(float triangleDepth, double sampleDepth)
{
  return triangleDepth > sampleDepth + 1e-6 * (1.0 + std::fabs(sampleDepth));
}

// The float the rasterizer's conservative depth can take at most below `depth` (a lower bound
// of the triangle's stored depth computed from its vertices): `magnitude` bounds the terms the
// depth was summed from, so the double rounding is covered; then rounded down to float like
// the rasterizer's depth.
inline float LowerDepth(double depth, double magnitude)
{
  const double d = depth - 1e-9 * (1.0 + std::fabs(depth)) - 1e-12 * magnitude;
  float f = static_cast<float>(d);
  if (static_cast<double>(f) > d)
  {
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  }
  return f;
}

// Texels a footprint's box may reach beyond the box of its projected vertices: the
// rasterizer's quarter-texel growth plus a texel for rounding (as its own tile cull).
constexpr double BoxMargin = 1.25;

// The texel box and lowest stored depth of `count` points in `view` (grid of `size` texels):
// every point of their convex hull projects into the box, no stored depth over it lies below
// `lower`. False when the points cannot be bounded so (a perspective view's apex region or
// behind its apex): such casters are never culled.
bool BoundPoints(
  const View& view, int size, const double* points, int count, double box[4], float& lower)
{
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
  double ymin = xmin, ymax = -xmin, dmin = xmin, magnitude = 0.0;
  const int depthRow = view.Perspective ? 3 : 2;
  const double depthScale = view.Perspective ? 1.0 / view.Far : 1.0;
  for (int k = 0; k < count; ++k)
  {
    const double* p = points + 3 * k;
    double x = view.Dot(0, p), y = view.Dot(1, p);
    const double d = view.Dot(depthRow, p) * depthScale;
    if (view.Perspective)
    {
      const double w = view.Dot(3, p);
      if (!(w >= view.NearW) || !(w > 0.0))
      {
        return false;
      }
      x /= w;
      y /= w;
    }
    x = (x * 0.5 + 0.5) * size;
    y = (y * 0.5 + 0.5) * size;
    xmin = std::min(xmin, x);
    xmax = std::max(xmax, x);
    ymin = std::min(ymin, y);
    ymax = std::max(ymax, y);
    dmin = std::min(dmin, d);
    const double* r = view.Row[depthRow];
    magnitude = std::max(magnitude,
      (std::fabs(r[0] * p[0]) + std::fabs(r[1] * p[1]) + std::fabs(r[2] * p[2]) + std::fabs(r[3])) *
        depthScale);
  }
  if (!std::isfinite(xmin + xmax + ymin + ymax + dmin + magnitude))
  {
    return false;
  }
  box[0] = xmin - BoxMargin;
  box[1] = xmax + BoxMargin;
  box[2] = ymin - BoxMargin;
  box[3] = ymax + BoxMargin;
  lower = LowerDepth(dmin, magnitude);
  return true;
}

// The coarse occupancy of one pass's listed samples: per cell of Cell x Cell texels the
// largest stored depth of its samples (-inf when it holds none), as a max pyramid so a box
// query visits few cells. A caster whose box covers no occupied cell, or that lies behind the
// farthest sample of every occupied cell it covers, can decide no listed sample: each of them
// would skip it (Behind), or it touches no texel with a list.
struct SampleCells
{
  int Size = 0;
  int Cell = 1;
  std::vector<int> Dim;                 // cells per side, per level
  std::vector<std::vector<double>> Max; // per level, Dim^2 cells

  void Build(int size, const vtkIdType* samples, vtkIdType count,
    const std::vector<vtkIdType>& texel, const double* depth)
  {
    this->Size = size;
    this->Cell = std::max(1, size / 256);
    const int dim = (size + this->Cell - 1) / this->Cell;
    const double empty = -std::numeric_limits<double>::infinity();
    this->Dim.assign(1, dim);
    this->Max.resize(1);
    this->Max[0].assign(static_cast<size_t>(dim) * dim, empty);
    for (vtkIdType i = 0; i < count; ++i)
    {
      const vtkIdType s = samples[i];
      const vtkIdType t = texel[static_cast<size_t>(s)];
      const size_t cell =
        static_cast<size_t>((t / size) / this->Cell) * dim + (t % size) / this->Cell;
      this->Max[0][cell] = std::max(this->Max[0][cell], depth[s]);
    }
    while (this->Dim.back() > 1)
    {
      const int below = this->Dim.back();
      const int up = (below + 1) / 2;
      std::vector<double> level(static_cast<size_t>(up) * up, empty);
      const std::vector<double>& fine = this->Max.back();
      for (int y = 0; y < below; ++y)
      {
        for (int x = 0; x < below; ++x)
        {
          double& m = level[static_cast<size_t>(y / 2) * up + x / 2];
          m = std::max(m, fine[static_cast<size_t>(y) * below + x]);
        }
      }
      this->Dim.push_back(up);
      this->Max.push_back(std::move(level));
    }
  }

  // True when a caster inside texel box `box` with no stored depth below `lower` can meet no
  // listed sample.
  bool Culled(const double box[4], float lower) const
  {
    if (box[1] < 0.0 || box[3] < 0.0 || box[0] >= this->Size || box[2] >= this->Size)
    {
      return true;
    }
    auto cell = [this](double v)
    { return std::max(0, std::min(this->Size - 1, static_cast<int>(std::floor(v)))) / this->Cell; };
    const int range[4] = { cell(std::max(box[0], 0.0)), cell(std::min<double>(box[1], this->Size)),
      cell(std::max(box[2], 0.0)), cell(std::min<double>(box[3], this->Size)) };
    int top = 0;
    while (top + 1 < static_cast<int>(this->Dim.size()) &&
      ((range[1] >> top) - (range[0] >> top) > 1 || (range[3] >> top) - (range[2] >> top) > 1))
    {
      ++top;
    }
    return !this->Live(top, range, lower);
  }

private:
  // Any cell of `level` within the range (level-0 cells) that holds a sample not wholly in
  // front of `lower`?
  bool Live(int level, const int range[4], float lower, int px = -1, int py = -1) const
  {
    const int dim = this->Dim[static_cast<size_t>(level)];
    int x0 = range[0] >> level, x1 = range[1] >> level;
    int y0 = range[2] >> level, y1 = range[3] >> level;
    if (px >= 0)
    {
      x0 = std::max(x0, 2 * px);
      x1 = std::min(x1, 2 * px + 1);
      y0 = std::max(y0, 2 * py);
      y1 = std::min(y1, 2 * py + 1);
    }
    for (int y = y0; y <= y1 && y < dim; ++y)
    {
      for (int x = x0; x <= x1 && x < dim; ++x)
      {
        const double m = this->Max[static_cast<size_t>(level)][static_cast<size_t>(y) * dim + x];
        if (m == -std::numeric_limits<double>::infinity() || Behind(lower, m))
        {
          continue;
        }
        if (level == 0 || this->Live(level - 1, range, lower, x, y))
        {
          return true;
        }
      }
    }
    return false;
  }
};

// Caster triangles grouped for culling: sorted along a Morton curve of their centroids and
// cut into runs of ClusterSize, each with its bounding box, so most of a view's culling is
// decided per cluster. Rebuilt when the caster list changes.
constexpr vtkIdType ClusterSize = 32;

struct CasterClusters
{
  const vtkIdType* Source = nullptr; // the caster list it was built from
  size_t SourceSize = 0;
  const double* Vertices = nullptr;
  vtkMTimeType Time = 0;
  std::vector<vtkIdType> Order; // caster ids, Morton order
  std::vector<double> Boxes;    // 6 per cluster: x0, x1, y0, y1, z0, z1

  // Regroups the casters when they changed; true then.
  bool Update(const std::vector<vtkIdType>& casters, const double* vertices, vtkMTimeType time)
  {
    if (this->Source == casters.data() && this->SourceSize == casters.size() &&
      this->Vertices == vertices && this->Time == time)
    {
      return false;
    }
    this->Source = casters.data();
    this->SourceSize = casters.size();
    this->Vertices = vertices;
    this->Time = time;
    const size_t n = casters.size();
    double lo[3] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
      std::numeric_limits<double>::max() };
    double hi[3] = { -lo[0], -lo[1], -lo[2] };
    std::vector<double> centre(3 * n);
    for (size_t i = 0; i < n; ++i)
    {
      const double* p = vertices + 9 * casters[i];
      for (int c = 0; c < 3; ++c)
      {
        centre[3 * i + c] = (p[c] + p[3 + c] + p[6 + c]) / 3.0;
        lo[c] = std::min(lo[c], centre[3 * i + c]);
        hi[c] = std::max(hi[c], centre[3 * i + c]);
      }
    }
    std::vector<std::pair<std::uint32_t, vtkIdType>> keyed(n);
    for (size_t i = 0; i < n; ++i)
    {
      std::uint32_t code = 0;
      std::uint32_t q[3];
      for (int c = 0; c < 3; ++c)
      {
        const double extent = hi[c] - lo[c];
        const double u = extent > 0.0 ? (centre[3 * i + c] - lo[c]) / extent : 0.0;
        q[c] = static_cast<std::uint32_t>(std::min(1023.0, std::max(0.0, u * 1024.0)));
      }
      for (int b = 9; b >= 0; --b)
      {
        code =
          (code << 3) | (((q[0] >> b) & 1u) << 2) | (((q[1] >> b) & 1u) << 1) | ((q[2] >> b) & 1u);
      }
      keyed[i] = { code, casters[i] };
    }
    std::sort(keyed.begin(), keyed.end());
    this->Order.resize(n);
    const size_t run = static_cast<size_t>(ClusterSize);
    const size_t clusters = (n + run - 1) / run;
    this->Boxes.assign(6 * clusters, 0.0);
    for (size_t c = 0; c < clusters; ++c)
    {
      double* box = this->Boxes.data() + 6 * c;
      box[0] = box[2] = box[4] = std::numeric_limits<double>::max();
      box[1] = box[3] = box[5] = -std::numeric_limits<double>::max();
      for (size_t i = c * run; i < std::min(n, (c + 1) * run); ++i)
      {
        this->Order[i] = keyed[i].second;
        const double* p = vertices + 9 * keyed[i].second;
        for (int k = 0; k < 9; ++k)
        {
          box[2 * (k % 3)] = std::min(box[2 * (k % 3)], p[k]);
          box[2 * (k % 3) + 1] = std::max(box[2 * (k % 3) + 1], p[k]);
        }
      }
    }
    return true;
  }

  // The casters of this view and pass that may decide a listed sample, in cluster order
  // (the lists' answers do not depend on the order); returns how many were culled.
  vtkIdType Cull(const View& view, int size, const SampleCells& cells, const double* vertices,
    std::vector<unsigned char>& keep, std::vector<vtkIdType>& kept) const
  {
    const vtkIdType n = static_cast<vtkIdType>(this->Order.size());
    const vtkIdType clusters = (n + ClusterSize - 1) / ClusterSize;
    keep.assign(static_cast<size_t>(n), 1);
    vtkSMPTools::For(0, clusters,
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType c = begin; c < end; ++c)
        {
          const double* b = this->Boxes.data() + 6 * c;
          double corners[24];
          for (int k = 0; k < 8; ++k)
          {
            corners[3 * k + 0] = b[(k & 1) ? 1 : 0];
            corners[3 * k + 1] = b[(k & 2) ? 3 : 2];
            corners[3 * k + 2] = b[(k & 4) ? 5 : 4];
          }
          double box[4];
          float lower;
          const vtkIdType first = c * ClusterSize, last = std::min(n, first + ClusterSize);
          if (BoundPoints(view, size, corners, 8, box, lower) && cells.Culled(box, lower))
          {
            std::fill(keep.begin() + first, keep.begin() + last, 0);
            continue;
          }
          for (vtkIdType i = first; i < last; ++i)
          {
            keep[static_cast<size_t>(i)] =
              !(BoundPoints(
                  view, size, vertices + 9 * this->Order[static_cast<size_t>(i)], 3, box, lower) &&
                cells.Culled(box, lower));
          }
        }
      });
    kept.clear();
    for (vtkIdType i = 0; i < n; ++i)
    {
      if (keep[static_cast<size_t>(i)])
      {
        kept.push_back(this->Order[static_cast<size_t>(i)]);
      }
    }
    return n - static_cast<vtkIdType>(kept.size());
  }
};

// Projects the view's pending samples into its grid: `texel` and `depth` per listable sample
// (appended to `listed`, ascending); a sample outside the grid or behind the apex, or on a
// positional light, is left to the tracer (Pending). Only the view's samples of `pending`
// (the call's pending samples, ascending; the hybrid's few) are projected.
void ProjectSamples(const View& view, int size, signed char viewIndex,
  const std::vector<signed char>& sampleView, const TestContext& ctx,
  const std::vector<vtkIdType>& pending, std::vector<vtkIdType>& texel, std::vector<double>& depth,
  std::vector<float>& point, std::vector<vtkIdType>& listed)
{
  std::vector<vtkIdType> candidates;
  for (vtkIdType s : pending)
  {
    if (sampleView[static_cast<size_t>(s)] == viewIndex)
    {
      candidates.push_back(s);
    }
  }
  vtkSMPTools::For(0, static_cast<vtkIdType>(candidates.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        const vtkIdType s = candidates[static_cast<size_t>(i)];
        texel[static_cast<size_t>(s)] = -1;
        double p[3], ms, mt, d;
        ctx.Position(s, p);
        if (!view.Project(p, ms, mt, d) || !(std::fabs(ms) <= 1.0) || !(std::fabs(mt) <= 1.0) ||
          !penumbra_light_views::MakeShadowRay(ctx.In->Light, p, 1.0, 0.0, 1.0).Ok)
        {
          continue;
        }
        // The texel rule of the conservative classification: the same map point.
        const int ix = std::min(size - 1, std::max(0, static_cast<int>((ms * 0.5 + 0.5) * size)));
        const int iy = std::min(size - 1, std::max(0, static_cast<int>((mt * 0.5 + 0.5) * size)));
        texel[static_cast<size_t>(s)] = static_cast<vtkIdType>(iy) * size + ix;
        depth[static_cast<size_t>(s)] = d;
        point[2 * static_cast<size_t>(s)] = static_cast<float>((ms * 0.5 + 0.5) * size);
        point[2 * static_cast<size_t>(s) + 1] = static_cast<float>((mt * 0.5 + 0.5) * size);
      }
    });
  for (vtkIdType s : candidates)
  {
    if (texel[static_cast<size_t>(s)] >= 0)
    {
      listed.push_back(s);
    }
  }
}

// The per-texel lists of one pass (Johnson et al. 2005's grid of lists, as Ferko 2014 builds
// it: head pointers and a node pool of (sample, next) links). The CPU builds them as a sort
// by texel, each node linking to the next of its texel; the GPU (ListCompute) by atomic
// counter and head exchange, in any order within a list. The rasterizer walks either by the
// links. Head and Active have a value per texel and are reset only where a list was, so a
// pass with few samples costs no full-grid clear. Sample ids are pixel indices (32 bits).
struct Lists
{
  std::vector<std::uint32_t> Head;       // per texel: first node, NoNode when empty
  std::vector<unsigned char> Active;     // per texel: holds an undecided sample
  std::vector<std::uint32_t> Nodes;      // per node: sample id, next node (NoNode: list end)
  std::vector<std::uint32_t> NodeTexel;  // per node: its texel
  std::vector<vtkIdType> Samples;        // the pass's samples, in node order
  std::vector<vtkIdType> Counts;         // dense CPU passes: the counting sort's rows
  std::vector<std::uint32_t> Items;      // GPU passes: (sample, texel) pairs
  std::vector<std::uint32_t> TexelHeads; // GPU passes: per node, its texel's head

  void Reserve(int size)
  {
    const size_t texels = static_cast<size_t>(size) * size;
    if (this->Head.size() != texels)
    {
      this->Head.assign(texels, NoNode);
      this->Active.assign(texels, 0);
    }
  }

  // CPU: lists the `count` samples from `first` (texel per sample in `texel`).
  void BuildOnCPU(
    int size, const vtkIdType* first, vtkIdType count, const std::vector<vtkIdType>& texel)
  {
    const size_t texels = static_cast<size_t>(size) * size;
    this->Reserve(size);
    this->Nodes.resize(2 * static_cast<size_t>(count));
    this->NodeTexel.resize(static_cast<size_t>(count));
    auto texelOf = [&](vtkIdType i) { return texel[static_cast<size_t>(first[i])]; };
    if (static_cast<size_t>(count) * 8 >= texels)
    {
      // Dense: counting sort (counts, prefix sum, fill), linear in texels and samples.
      this->Counts.assign(texels + 1, 0);
      for (vtkIdType i = 0; i < count; ++i)
      {
        ++this->Counts[static_cast<size_t>(texelOf(i)) + 1];
      }
      for (size_t t = 0; t < texels; ++t)
      {
        this->Counts[t + 1] += this->Counts[t];
      }
      for (vtkIdType i = 0; i < count; ++i)
      {
        const size_t j = static_cast<size_t>(this->Counts[static_cast<size_t>(texelOf(i))]++);
        this->Nodes[2 * j] = static_cast<std::uint32_t>(first[i]);
        this->NodeTexel[j] = static_cast<std::uint32_t>(texelOf(i));
      }
    }
    else
    {
      // Sparse: sort the few (texel, sample) pairs instead of sweeping the grid.
      std::vector<std::pair<vtkIdType, vtkIdType>> pairs(static_cast<size_t>(count));
      for (vtkIdType i = 0; i < count; ++i)
      {
        pairs[static_cast<size_t>(i)] = { texelOf(i), first[i] };
      }
      std::sort(pairs.begin(), pairs.end());
      for (size_t j = 0; j < pairs.size(); ++j)
      {
        this->NodeTexel[j] = static_cast<std::uint32_t>(pairs[j].first);
        this->Nodes[2 * j] = static_cast<std::uint32_t>(pairs[j].second);
      }
    }
    // Link each node to the next of its texel; the first of a run is the texel's head.
    for (size_t j = 0; j < this->NodeTexel.size(); ++j)
    {
      const std::uint32_t t = this->NodeTexel[j];
      const bool last = j + 1 == this->NodeTexel.size() || this->NodeTexel[j + 1] != t;
      this->Nodes[2 * j + 1] = last ? NoNode : static_cast<std::uint32_t>(j + 1);
      if (j == 0 || this->NodeTexel[j - 1] != t)
      {
        this->Head[t] = static_cast<std::uint32_t>(j);
      }
    }
  }

  // GPU: links the view's samples of `listed` still Pending, at most `capacity` (the node
  // pool) of them; the others stay Pending for a further pass. `overflow`: the pool was too
  // small (the counter went beyond it).
  bool BuildOnGPU(ListCompute& compute, int size, const std::vector<vtkIdType>& listed,
    vtkIdType capacity, const std::vector<vtkIdType>& texel, const unsigned char* state,
    bool& overflow, std::string& why)
  {
    this->Reserve(size);
    this->Items.clear();
    for (vtkIdType s : listed)
    {
      if (state[s] == Pending)
      {
        this->Items.push_back(static_cast<std::uint32_t>(s));
        this->Items.push_back(static_cast<std::uint32_t>(texel[static_cast<size_t>(s)]));
      }
    }
    std::uint32_t requested = 0;
    if (!compute.Link(this->Items.data(), this->Items.size() / 2, this->Head.size(),
          static_cast<size_t>(capacity), this->Nodes, requested, why))
    {
      return false;
    }
    overflow = requested > capacity;
    const size_t count = this->Nodes.size() / 2;
    this->NodeTexel.resize(count);
    for (size_t j = 0; j < count; ++j)
    {
      this->NodeTexel[j] = static_cast<std::uint32_t>(texel[this->Nodes[2 * j]]);
    }
    if (!compute.Heads(this->NodeTexel, this->TexelHeads, why))
    {
      return false;
    }
    for (size_t j = 0; j < count; ++j)
    {
      this->Head[this->NodeTexel[j]] = this->TexelHeads[j];
    }
    return true;
  }

  // After either build: marks the listed samples open and their texels active, collects the
  // pass's samples; returns the longest list, and the non-empty texels in `rows`.
  vtkIdType Finish(unsigned char* state, vtkIdType& rows)
  {
    const size_t count = this->NodeTexel.size();
    this->Samples.resize(count);
    vtkIdType longest = 0;
    rows = 0;
    for (size_t j = 0; j < count; ++j)
    {
      const std::uint32_t t = this->NodeTexel[j];
      this->Samples[j] = static_cast<vtkIdType>(this->Nodes[2 * j]);
      state[this->Samples[j]] = Open;
      this->Active[t] = 1;
      if (this->Head[t] == j)
      {
        vtkIdType length = 0;
        for (std::uint32_t k = this->Head[t]; k != NoNode; k = this->Nodes[2 * k + 1])
        {
          ++length;
        }
        longest = std::max(longest, length);
        ++rows;
      }
    }
    return longest;
  }

  // Empties the texels of the last build.
  void Clear()
  {
    for (std::uint32_t t : this->NodeTexel)
    {
      this->Head[t] = NoNode;
      this->Active[t] = 0;
    }
  }
};

// Irregular rasterization (Ferko 2014; Johnson et al. 2005): every caster triangle meets the
// samples listed at each texel its conservative footprint touches. A texel whose samples are
// all shadowed drops out. Returns the number of exact tests; the apex region's triangles go
// to `nearTriangles`.
vtkIdType RasterizeLists(const View& view, int size, const TestContext& ctx,
  const std::vector<vtkIdType>& casters, Lists& lists, penumbra_light_views::ExactTriangles& exact,
  std::vector<vtkIdType>& nearTriangles)
{
  const std::vector<std::uint32_t>& nodes = lists.Nodes;
  std::vector<unsigned char>& active = lists.Active;
  const double* vertices = ctx.In->TriangleVertices;
  unsigned char* state = ctx.State;
  const penumbra_conservative::CpuMapStats stats = penumbra_conservative::RasterizeConservative(
    view, size, vertices, casters, active.data(), nearTriangles,
    [&](size_t texel, vtkIdType id, float triangleDepth) -> vtkIdType
    {
      penumbra_rules::ExactTriangle scratch;
      const penumbra_rules::ExactTriangle* triangle = nullptr;
      bool made = false;
      vtkIdType tests = 0;
      bool open = false;
      for (std::uint32_t j = lists.Head[texel]; j != NoNode; j = nodes[2 * j + 1])
      {
        const vtkIdType s = static_cast<vtkIdType>(nodes[2 * j]);
        if (state[s] == Shadowed)
        {
          continue;
        }
        if (!ctx.In->OwnCaster(id, s) && !Behind(triangleDepth, ctx.Depth[s]))
        {
          if (!made)
          {
            triangle = exact.Get(id, vertices, scratch);
            made = true;
          }
          ctx.Test(s, triangle);
          ++tests;
        }
        open = open || state[s] != Shadowed;
      }
      active[texel] = open;
      return tests;
    });
  return stats.VisitWork;
}

// A sample's shadow ray projects to its own point in the view (see the class description),
// so a triangle that blocks it covers that point up to the rounding the rasterizer's quarter
// texel allows for; the sparse path asks for the point within this many texels of the
// triangle's projection (as BoundPoints' margin).
constexpr double PointMargin = BoxMargin;

// The unit edge lines (a, b, c: a x + b y + c >= 0 inside, distances in texels) of a
// triangle's projection into `view` (all vertices in front of a perspective apex), and the
// plane of its depth quantity over the projection (orthographic: the stored depth;
// perspective: Far / w, whose inverse is the stored depth), both affine in texel units.
// False when the projection has no area to speak of.
bool EdgeLines(const View& view, int size, const double* tri, double* edge, double* plane)
{
  double Q[3];
  double X[3], Y[3];
  for (int k = 0; k < 3; ++k)
  {
    const double* p = tri + 3 * k;
    const double w = view.Perspective ? view.Dot(3, p) : 1.0;
    X[k] = (view.Dot(0, p) / w * 0.5 + 0.5) * size;
    Y[k] = (view.Dot(1, p) / w * 0.5 + 0.5) * size;
    Q[k] = view.Perspective ? view.Far / w : view.Dot(2, p);
  }
  const double area = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
  const double extent = std::max({ X[0], X[1], X[2] }) - std::min({ X[0], X[1], X[2] }) +
    std::max({ Y[0], Y[1], Y[2] }) - std::min({ Y[0], Y[1], Y[2] });
  if (!std::isfinite(area + extent) || !(std::fabs(area) > 1e-6 * extent * extent))
  {
    return false;
  }
  const double orient = area > 0.0 ? 1.0 : -1.0;
  for (int k = 0; k < 3; ++k)
  {
    const int j = (k + 1) % 3;
    double a = -(Y[j] - Y[k]) * orient, b = (X[j] - X[k]) * orient;
    const double length = std::sqrt(a * a + b * b);
    if (!(length > 0.0))
    {
      return false;
    }
    a /= length;
    b /= length;
    edge[3 * k] = a;
    edge[3 * k + 1] = b;
    edge[3 * k + 2] = -(a * X[k] + b * Y[k]);
  }
  const double ex1 = X[1] - X[0], ey1 = Y[1] - Y[0], eq1 = Q[1] - Q[0];
  const double ex2 = X[2] - X[0], ey2 = Y[2] - Y[0], eq2 = Q[2] - Q[0];
  const double det = ex1 * ey2 - ex2 * ey1;
  plane[0] = (eq1 * ey2 - eq2 * ey1) / det;
  plane[1] = (ex1 * eq2 - ex2 * eq1) / det;
  plane[2] = Q[0] - plane[0] * X[0] - plane[1] * Y[0];
  return std::isfinite(plane[0] + plane[1] + plane[2]);
}

// Whether the triangle's depth plane lies beyond `depth` everywhere within PointMargin texels
// of `point` (then it cannot meet the sample's ray, which runs towards smaller depths); the
// margins cover the plane's rounding like Behind's.
inline bool PlaneBehind(bool perspective, const double* plane, const float* point, double depth)
{
  const double x = point[0], y = point[1];
  const double q = plane[2] + plane[0] * x + plane[1] * y;
  const double spread = PointMargin * (std::fabs(plane[0]) + std::fabs(plane[1]));
  const double slack =
    1e-7 * (std::fabs(plane[2]) + std::fabs(plane[0] * x) + std::fabs(plane[1] * y) + spread);
  double lower;
  if (perspective)
  {
    // Stored depth = 1 / q: its minimum over the box is at q's maximum, if q stays positive.
    const double qmin = q - spread - slack, qmax = q + spread + slack;
    if (!(qmin > 0.0))
    {
      return false;
    }
    lower = (1.0 / qmax) * (1.0 - 1e-9);
  }
  else
  {
    lower = q - spread - slack;
  }
  return lower > depth + 1e-6 * (1.0 + std::fabs(depth));
}

// What CasterGrid::MayBlock needs of a binned caster: edge lines and depth plane
// (EdgeLines), unit normal, the float rounding of its vertices (as ExactTriangle rounds them)
// and the texels per world unit of a lateral offset at its nearest point (`rowScale`: half
// the grid times the norm of the view's x and y rows, for perspective views plus the w row
// for |x / w| <= 1.01, divided by the nearest w). False: no area (no 2D cull).
bool ProjectionBounds(const View& view, double rowScale, const double* tri, double* edge,
  double* plane, double* normal, double& slop, double& scale, int size)
{
  if (!EdgeLines(view, size, tri, edge, plane))
  {
    return false;
  }
  double e1[3], e2[3], largest = 0.0, wmin = 1.0;
  for (int c = 0; c < 3; ++c)
  {
    e1[c] = tri[3 + c] - tri[c];
    e2[c] = tri[6 + c] - tri[c];
  }
  for (int k = 0; k < 9; ++k)
  {
    largest = std::max(largest, std::fabs(tri[k]));
  }
  if (view.Perspective)
  {
    wmin = std::min({ view.Dot(3, tri), view.Dot(3, tri + 3), view.Dot(3, tri + 6) });
  }
  vtkMath::Cross(e1, e2, normal);
  const double length = vtkMath::Normalize(normal);
  slop = 2.0 * std::ldexp(largest, -23);
  scale = rowScale / wmin;
  return length > 0.0 && wmin > 0.0 && std::isfinite(scale + slop);
}

// Passes with few listed samples for their casters (fewer than SparseFactor per caster, as the
// hybrid's hard samples): instead of every caster's conservative footprint (clipping and
// separating axes, the setup that dominates when few texels hold a list), each caster's
// light-space box (BoundPoints: its projection plus a margin for rounding) is binned to bands
// of BandRows grid rows, and meets the listed texels its box overlaps, found by a search per
// row. Per sample, MayBlock then skips the casters the exact test would call a miss (its
// depth plane beyond the sample, or the sample's point outside its projection by more than
// the test's own slack), and the rest get the exact test. A box covers every texel the
// rasterizer's footprint covers and MayBlock only drops provable misses, so each sample ends
// with the same decision as under the rasterizer (Hit::Clear is sticky, Unknown is traced).
constexpr vtkIdType SparseFactor = 2;

struct CasterGrid
{
  static constexpr int BandRows = 16;
  std::vector<double> Box;         // per caster: texel box x0, x1, y0, y1
  std::vector<float> Lower;        // per caster: lowest stored depth
  std::vector<unsigned char> Kind; // per caster: 0 cannot block, 1 binned, 2 apex region
  std::vector<double> Edge;        // per caster: 3 unit edge lines (a, b, c), inside >= 0
  std::vector<double> Plane;       // per caster: depth quantity plane (EdgeLines)
  bool Perspective = false;
  std::vector<unsigned char> Flat; // per caster: projection without area (no edge test)
  std::vector<double> Normal;      // per caster: unit normal (double vertices)
  std::vector<double> Slop;        // per caster: float rounding of its vertices (world)
  std::vector<double> Scale;       // per caster: texels per world unit at its nearest
  std::vector<double> TexelMargin; // per caster: MayBlock's margin for any pass ray, or -1

  // An upper bound of MayBlock's margin for caster i over every ray of the pass that can
  // come near it (the largest ErrPos; the smallest cosine with its normal: a directional
  // light's one direction, or for a positional light h / d, h the light's distance from the
  // triangle's plane and d its farthest vertex). -1 when the bound is too loose to use.
  double MarginBound(
    size_t i, const double* tri, const penumbra_light_views::LightSetup& light, double errPos) const
  {
    const double* n = this->Normal.data() + 3 * i;
    double cosine = 0.0, reach = 0.0;
    if (light.Type == penumbra_light_views::LightSetup::Kind::Directional)
    {
      cosine = std::fabs(vtkMath::Dot(light.Direction, n));
      reach = 1.0;
    }
    else
    {
      for (int k = 0; k < 3; ++k)
      {
        const double d[3] = { tri[3 * k] - light.Position[0], tri[3 * k + 1] - light.Position[1],
          tri[3 * k + 2] - light.Position[2] };
        reach = std::max(reach, vtkMath::Norm(d));
        if (k == 0)
        {
          cosine = std::fabs(vtkMath::Dot(d, n));
        }
      }
      cosine = reach > 0.0 ? cosine / reach : 0.0;
    }
    cosine *= 1.0 - 1e-6;
    if (!(cosine > 1e-5))
    {
      return -1.0;
    }
    const double slack = errPos * (1.0 + 1.0 / cosine) + this->Slop[i];
    if (!(slack < 1e-3 * reach) || !std::isfinite(slack * this->Scale[i]))
    {
      return -1.0; // rays that near it may leave the cosine bound
    }
    return 2.0 * slack * this->Scale[i] + 2e-3;
  }

  // False when no point of texel (x, y) lies within caster i's TexelMargin of its projection:
  // then no sample of the texel passes MayBlock.
  bool TexelNear(std::uint32_t i, double x, double y) const
  {
    const double m = this->TexelMargin[i];
    if (m < 0.0)
    {
      return true;
    }
    const double* e = this->Edge.data() + 9 * i;
    for (int k = 0; k < 3; ++k, e += 3)
    {
      if (e[2] + e[0] * (e[0] > 0.0 ? x + 1.0 : x) + e[1] * (e[1] > 0.0 ? y + 1.0 : y) < -m)
      {
        return false;
      }
    }
    return true;
  }

  // False when caster i provably cannot block the sample at `point` (texel units) with stored
  // depth `depth` and shadow `ray`: its depth plane lies beyond the sample near the point, or
  // the point lies farther from its projection than the exact test's slack. SegmentTest
  // (penumbra_rules) calls a ray a miss once it passes outside an edge by more than
  // slack = ErrPos (1 + 1 / |cos|) in the triangle's plane (cos: ray against normal), so a
  // ray it does not call a miss meets the plane within that of the (float-rounded) triangle;
  // projected into the view, that is within (slack + rounding) x Scale texels of each edge
  // line, doubled here for the projection's own rounding.
  bool MayBlock(std::uint32_t i, const float* point, double depth,
    const penumbra_light_views::ShadowRay& ray) const
  {
    if (this->Flat[i])
    {
      return true;
    }
    if (PlaneBehind(this->Perspective, this->Plane.data() + 3 * i, point, depth))
    {
      return false;
    }
    const double* n = this->Normal.data() + 3 * i;
    const double cosine = std::fabs(ray.D[0] * n[0] + ray.D[1] * n[1] + ray.D[2] * n[2]);
    if (!(cosine > 1e-5))
    {
      return true; // grazing: the exact test leaves it to the tracer
    }
    const double margin =
      2.0 * (ray.ErrPos * (1.0 + 1.0 / cosine) + this->Slop[i]) * this->Scale[i] + 1e-3;
    const double* e = this->Edge.data() + 9 * i;
    const double x = point[0], y = point[1];
    return e[0] * x + e[1] * y + e[2] >= -margin && e[3] * x + e[4] * y + e[5] >= -margin &&
      e[6] * x + e[7] * y + e[8] >= -margin;
  }
  static constexpr int TileTexels = 16;
  std::vector<std::uint32_t> TileSums; // summed-area table of listed texels per tile
  int Tiles = 0;                       // tiles per side
  std::vector<std::uint32_t> Texels;   // the pass's texels with a list, ascending
  std::vector<double> TexelDepth;      // per entry of Texels: its samples' farthest depth
  std::vector<std::uint32_t> RowStart; // per grid row: its first entry in Texels (size + 1)
  std::vector<vtkIdType> BandStart;    // per band of grid rows: first entry (bands + 1)
  std::vector<std::uint32_t> Entries;  // per band: the casters whose box reaches it
  std::vector<penumbra_light_views::ShadowRay> Rays; // per node of the pass

  // Grid rows and columns of the texels whose square caster i's box overlaps
  // (x + 1 >= x0 and x <= x1).
  static int First(double v, int size)
  {
    return std::max(0, std::min(size - 1, static_cast<int>(std::ceil(v)) - 1));
  }
  static int Last(double v, int size)
  {
    return std::max(0, std::min(size - 1, static_cast<int>(std::floor(v))));
  }
  int FirstRow(size_t i, int size) const { return First(this->Box[4 * i + 2], size); }
  int LastRow(size_t i, int size) const { return Last(this->Box[4 * i + 3], size); }

  // Counts the pass's listed texels per tile of TileTexels^2 texels, as a summed-area table.
  void CountTiles(int size, const Lists& lists)
  {
    this->Tiles = (size + TileTexels - 1) / TileTexels;
    const size_t side = static_cast<size_t>(this->Tiles) + 1;
    this->TileSums.assign(side * side, 0);
    for (size_t j = 0; j < lists.NodeTexel.size(); ++j)
    {
      const std::uint32_t t = lists.NodeTexel[j];
      const size_t x = t % static_cast<std::uint32_t>(size) / TileTexels;
      const size_t y = t / static_cast<std::uint32_t>(size) / TileTexels;
      this->TileSums[(y + 1) * side + x + 1] = 1; // marked; summed below
    }
    for (size_t y = 1; y < side; ++y)
    {
      for (size_t x = 1; x < side; ++x)
      {
        this->TileSums[y * side + x] += this->TileSums[(y - 1) * side + x] +
          this->TileSums[y * side + x - 1] - this->TileSums[(y - 1) * side + x - 1];
      }
    }
  }

  // Whether caster i's box overlaps a tile with a listed texel: if not, the band walk would
  // find no listed texel under it (the same First/Last texel bounds), so it is not binned.
  bool BoxMeetsList(size_t i, int size) const
  {
    const size_t side = static_cast<size_t>(this->Tiles) + 1;
    const size_t x0 = static_cast<size_t>(First(this->Box[4 * i], size) / TileTexels);
    const size_t x1 = static_cast<size_t>(Last(this->Box[4 * i + 1], size) / TileTexels) + 1;
    const size_t y0 = static_cast<size_t>(this->FirstRow(i, size) / TileTexels);
    const size_t y1 = static_cast<size_t>(this->LastRow(i, size) / TileTexels) + 1;
    if (x1 <= x0 || y1 <= y0)
    {
      return true; // an empty span: leave it to the band walk
    }
    const std::uint32_t* t = this->TileSums.data();
    return t[y1 * side + x1] - t[y0 * side + x1] - t[y1 * side + x0] + t[y0 * side + x0] > 0;
  }

  // Bins `casters` by band, lists the pass's texels and makes the listed samples' rays; the
  // apex region's casters go to `nearTriangles` (as with the rasterizer). Returns the binned.
  vtkIdType Build(const View& view, int size, const TestContext& ctx,
    const std::vector<vtkIdType>& casters, const Lists& lists,
    std::vector<vtkIdType>& nearTriangles)
  {
    // Each listed sample's ray, once per pass (node order).
    this->Rays.resize(lists.Samples.size());
    vtkSMPTools::For(0, static_cast<vtkIdType>(lists.Samples.size()),
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType j = begin; j < end; ++j)
        {
          this->Rays[static_cast<size_t>(j)] = ctx.Ray(lists.Samples[static_cast<size_t>(j)]);
        }
      });
    double errPos = 0.0; // the largest positional slack of the pass's rays
    for (const penumbra_light_views::ShadowRay& ray : this->Rays)
    {
      errPos = std::max(errPos, ray.ErrPos);
    }
    this->CountTiles(size, lists);
    const size_t n = casters.size();
    this->TexelMargin.assign(n, -1.0);
    this->Box.resize(4 * n);
    this->Lower.resize(n);
    this->Kind.assign(n, 0);
    this->Edge.resize(9 * n);
    this->Plane.resize(3 * n);
    this->Flat.assign(n, 1);
    this->Normal.resize(3 * n);
    this->Slop.resize(n);
    this->Scale.resize(n);
    this->Perspective = view.Perspective;
    auto norm3 = [](const double* r) { return std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]); };
    const double w3 = view.Perspective ? 1.01 * norm3(view.Row[3]) : 0.0;
    const double rowScale = 0.5 * size *
      std::sqrt((norm3(view.Row[0]) + w3) * (norm3(view.Row[0]) + w3) +
        (norm3(view.Row[1]) + w3) * (norm3(view.Row[1]) + w3));
    vtkSMPTools::For(0, static_cast<vtkIdType>(n),
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType i = begin; i < end; ++i)
        {
          const double* tri = ctx.In->TriangleVertices + 9 * casters[static_cast<size_t>(i)];
          unsigned char& kind = this->Kind[static_cast<size_t>(i)];
          if (view.Perspective)
          {
            const double w[3] = { view.Dot(3, tri), view.Dot(3, tri + 3), view.Dot(3, tri + 6) };
            if (!(std::max({ w[0], w[1], w[2] }) > 0.0))
            {
              continue; // wholly behind the apex: no ray in front of it meets it
            }
            if (!(std::min({ w[0], w[1], w[2] }) >= view.NearW))
            {
              kind = 2;
              continue;
            }
          }
          double* box = this->Box.data() + 4 * i;
          if (!BoundPoints(view, size, tri, 3, box, this->Lower[static_cast<size_t>(i)]))
          {
            kind = 2;
          }
          else if (box[1] >= 0.0 && box[3] >= 0.0 && box[0] < size && box[2] < size &&
            this->BoxMeetsList(static_cast<size_t>(i), size))
          {
            kind = 1;
            this->Flat[static_cast<size_t>(i)] = !ProjectionBounds(view, rowScale, tri,
              this->Edge.data() + 9 * i, this->Plane.data() + 3 * i, this->Normal.data() + 3 * i,
              this->Slop[static_cast<size_t>(i)], this->Scale[static_cast<size_t>(i)], size);
            if (!this->Flat[static_cast<size_t>(i)])
            {
              this->TexelMargin[static_cast<size_t>(i)] =
                this->MarginBound(static_cast<size_t>(i), tri, ctx.In->Light, errPos);
            }
          }
        }
      });
    // The pass's texels with a list, ascending (row-major), and where each row's begin.
    this->Texels.clear();
    for (size_t j = 0; j < lists.NodeTexel.size(); ++j)
    {
      if (lists.Head[lists.NodeTexel[j]] == j)
      {
        this->Texels.push_back(lists.NodeTexel[j]);
      }
    }
    if (!std::is_sorted(this->Texels.begin(), this->Texels.end()))
    {
      std::sort(this->Texels.begin(), this->Texels.end()); // GPU lists: any node order
    }
    this->TexelDepth.resize(this->Texels.size());
    for (size_t k = 0; k < this->Texels.size(); ++k)
    {
      double farthest = -std::numeric_limits<double>::infinity();
      for (std::uint32_t j = lists.Head[this->Texels[k]]; j != NoNode; j = lists.Nodes[2 * j + 1])
      {
        const double depth = ctx.Depth[lists.Nodes[2 * j]];
        farthest = depth <= farthest ? farthest : depth; // a NaN depth stays (never Behind)
      }
      this->TexelDepth[k] = farthest;
    }
    this->RowStart.assign(static_cast<size_t>(size) + 1, 0);
    for (std::uint32_t t : this->Texels)
    {
      ++this->RowStart[t / static_cast<std::uint32_t>(size) + 1];
    }
    for (int y = 0; y < size; ++y)
    {
      this->RowStart[static_cast<size_t>(y) + 1] += this->RowStart[static_cast<size_t>(y)];
    }
    // Casters per band of BandRows grid rows, by their boxes' rows (a counting sort).
    const int bands = (size + BandRows - 1) / BandRows;
    this->BandStart.assign(static_cast<size_t>(bands) + 1, 0);
    auto forBands = [&](size_t i, auto&& f)
    {
      for (int b = this->FirstRow(i, size) / BandRows; b <= this->LastRow(i, size) / BandRows; ++b)
      {
        f(static_cast<size_t>(b));
      }
    };
    vtkIdType binned = 0;
    for (size_t i = 0; i < n; ++i)
    {
      if (this->Kind[i] == 2)
      {
        nearTriangles.push_back(casters[i]);
      }
      else if (this->Kind[i] == 1)
      {
        ++binned;
        forBands(i, [&](size_t b) { ++this->BandStart[b + 1]; });
      }
    }
    for (size_t b = 1; b < this->BandStart.size(); ++b)
    {
      this->BandStart[b] += this->BandStart[b - 1];
    }
    std::vector<vtkIdType> fill(this->BandStart.begin(), this->BandStart.end() - 1);
    this->Entries.resize(static_cast<size_t>(this->BandStart.back()));
    for (size_t i = 0; i < n; ++i)
    {
      if (this->Kind[i] == 1)
      {
        forBands(i,
          [&](size_t b)
          { this->Entries[static_cast<size_t>(fill[b]++)] = static_cast<std::uint32_t>(i); });
      }
    }
    return binned;
  }
};

// The sparse form of RasterizeLists: per band, each binned caster meets the samples of the
// listed texels its box overlaps (MayBlock first, then the exact test). Returns the number of
// exact tests.
vtkIdType TestListsByBands(int size, const TestContext& ctx, const std::vector<vtkIdType>& casters,
  const Lists& lists, const CasterGrid& grid, const float* point,
  penumbra_light_views::ExactTriangles& exact)
{
  const double* vertices = ctx.In->TriangleVertices;
  unsigned char* state = ctx.State;
  const int bands = static_cast<int>(grid.BandStart.size()) - 1;
  std::atomic<vtkIdType> tests(0);
  // Bands in parallel: a texel's samples belong to one band, so to one thread.
  vtkSMPTools::For(0, bands,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType local = 0;
      penumbra_rules::ExactTriangle scratch;
      for (vtkIdType b = begin; b < end; ++b)
      {
        const int rowLo = static_cast<int>(b) * CasterGrid::BandRows;
        const int rowHi = std::min(size - 1, rowLo + CasterGrid::BandRows - 1);
        for (vtkIdType e = grid.BandStart[static_cast<size_t>(b)];
             e < grid.BandStart[static_cast<size_t>(b) + 1]; ++e)
        {
          const std::uint32_t i = grid.Entries[static_cast<size_t>(e)];
          const vtkIdType id = casters[i];
          const std::uint32_t x0 =
            static_cast<std::uint32_t>(CasterGrid::First(grid.Box[4 * i], size));
          const std::uint32_t x1 =
            static_cast<std::uint32_t>(CasterGrid::Last(grid.Box[4 * i + 1], size));
          const penumbra_rules::ExactTriangle* triangle = nullptr;
          bool made = false;
          for (int y = std::max(rowLo, grid.FirstRow(i, size));
               y <= std::min(rowHi, grid.LastRow(i, size)); ++y)
          {
            const auto rowBegin = grid.Texels.begin() + grid.RowStart[static_cast<size_t>(y)];
            const auto rowEnd = grid.Texels.begin() + grid.RowStart[static_cast<size_t>(y) + 1];
            const std::uint32_t base =
              static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(size);
            for (auto it = rowBegin == rowEnd ? rowEnd
                                              : std::lower_bound(rowBegin, rowEnd, base + x0);
                 it != rowEnd && *it <= base + x1; ++it)
            {
              // Behind grows with the sample's depth: a caster behind the texel's farthest
              // sample is behind each of its samples (the per-sample test below).
              const size_t k = static_cast<size_t>(it - grid.Texels.begin());
              if (Behind(grid.Lower[i], grid.TexelDepth[k]) || !grid.TexelNear(i, *it - base, y))
              {
                continue;
              }
              for (std::uint32_t j = lists.Head[*it]; j != NoNode; j = lists.Nodes[2 * j + 1])
              {
                const vtkIdType s = static_cast<vtkIdType>(lists.Nodes[2 * j]);
                const penumbra_light_views::ShadowRay& ray = grid.Rays[j];
                if (state[s] == Shadowed || ctx.In->OwnCaster(id, s) ||
                  Behind(grid.Lower[i], ctx.Depth[s]) ||
                  !grid.MayBlock(i, point + 2 * s, ctx.Depth[s], ray))
                {
                  continue;
                }
                if (!made)
                {
                  triangle = exact.Get(id, vertices, scratch);
                  made = true;
                }
                ctx.Test(s, ray, triangle);
                ++local;
              }
            }
          }
        }
      }
      tests += local;
    });
  return tests.load();
}

// The apex region's triangles would cover the whole view: each is tested against every
// listed sample still undecided (up to MaxNearTriangles; beyond, those samples are traced).
vtkIdType TestNearTriangles(const TestContext& ctx, const vtkIdType* listed, vtkIdType count,
  const std::vector<vtkIdType>& nearTriangles)
{
  if (nearTriangles.empty())
  {
    return 0;
  }
  const bool testable = nearTriangles.size() <= MaxNearTriangles;
  std::vector<penumbra_rules::ExactTriangle> triangles(nearTriangles.size());
  std::vector<unsigned char> made(nearTriangles.size(), 0);
  for (size_t k = 0; testable && k < nearTriangles.size(); ++k)
  {
    const vtkIdType id = nearTriangles[k];
    made[k] =
      penumbra_rules::MakeExactTriangle(ctx.In->TriangleVertices + 9 * id, id, triangles[k]);
  }
  std::atomic<vtkIdType> tests(0);
  vtkSMPTools::For(0, count,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType local = 0;
      for (vtkIdType i = begin; i < end; ++i)
      {
        const vtkIdType s = listed[i];
        for (size_t k = 0; k < nearTriangles.size() && ctx.State[s] != Shadowed; ++k)
        {
          if (!testable)
          {
            ctx.State[s] = Unknown;
            break;
          }
          if (!ctx.In->OwnCaster(nearTriangles[k], s))
          {
            ctx.Test(s, made[k] ? &triangles[k] : nullptr);
            ++local;
          }
        }
      }
      tests += local;
    });
  return tests.load();
}
}

struct vtkPenumbraLinkedListShadows::Internals
{
  penumbra_light_views::CasterBuffers Casters; // CPU lists only, never uploaded
  vtkNew<vtkUnsignedCharArray> State;
  std::vector<double> Depth;       // per sample
  std::vector<vtkIdType> Texel;    // per sample, its texel in its view
  std::vector<float> Point;        // per sample, its point in its view (texel units)
  std::vector<vtkIdType> ToDecide; // the call's samples to decide, ascending
  std::vector<vtkIdType> Listed;   // the view's listable samples, ascending
  std::vector<vtkIdType> Pick;     // CPU passes: the pass's samples
  Lists Grid;
  ListCompute Compute;             // the GPU list path
  bool UseGpu = false;             // this call's lists are built on the GPU
  std::string ReportedProblem;     // the last reason the GPU path could not run
  vtkNew<vtkIdTypeArray> Recorded; // RecordLists: (view, texel, sample)
  std::vector<vtkIdType> Near;     // the apex region's triangles
  SampleCells Cells;               // the pass's listed samples, coarse
  CasterGrid Bands;                // sparse passes: the casters binned by box
  CasterClusters Clusters;         // the casters, grouped for culling
  std::vector<unsigned char> Keep; // per caster (cluster order): not culled
  std::vector<vtkIdType> Kept;     // the pass's casters after culling

  // The phases of ComputeVisibility, in the order it runs them (defined below it).
  void ChooseListPath(vtkPenumbraLinkedListShadows* self, vtkRenderer* renderer, vtkIdType n);
  bool BuildPass(vtkPenumbraLinkedListShadows* self, int view, vtkIdType capacity,
    unsigned char* state, vtkIdType& rows);
  void ListView(vtkPenumbraLinkedListShadows* self, const View& view, int vi,
    const TestContext& ctx, vtkIdType& rows);
  void ReportListPath(vtkPenumbraLinkedListShadows* self, const std::string& why);
};

//------------------------------------------------------------------------------
vtkPenumbraLinkedListShadows::vtkPenumbraLinkedListShadows()
  : Classifier(vtkPenumbraConservativeShadows::New())
  , Reference(vtkPenumbraReference::New())
  , Impl(new Internals)
{
  this->Classifier->SetLayers(3); // see GetClassifier()
}

//------------------------------------------------------------------------------
vtkPenumbraLinkedListShadows::~vtkPenumbraLinkedListShadows()
{
  this->Classifier->Delete();
  this->Reference->Delete();
}

//------------------------------------------------------------------------------
int vtkPenumbraLinkedListShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  this->NumberOfValidSamples = this->NumberOfListedSamples = this->MaxListLength = 0;
  this->NumberOfTests = this->NumberOfTracedSamples = 0;
  this->MeanListLength = 0.0;
  this->NumberOfPasses = this->NumberOfViews = this->NumberOfOverflows = 0;
  this->NumberOfSparsePasses = 0;
  impl.Recorded->SetNumberOfComponents(3);
  impl.Recorded->SetNumberOfTuples(0);
  this->NumberOfCulledCasters = this->NumberOfRasterizedCasters = 0;
  this->ClassifyTimeMs = this->ListTimeMs = this->RasterTimeMs = this->TraceTimeMs = 0.0;

  penumbra_light_views::FrameInputs in;
  {
    std::string inputError;
    if (!in.Read(renderer, geometry, samples, light, visibility, inputError))
    {
      PENUMBRA_FAIL("linked-list shadows: " << inputError);
    }
  }
  const vtkIdType n = in.NumberOfSamples;
  impl.Casters.Update(geometry, false);
  const bool anyCaster = !impl.Casters.TriangleIds.empty();

  // ---- 1. The samples to decide (Pending): facing the light, or the hybrid's hard ones
  // (the classifier's uncertain samples, mask value 1).
  const auto classifyStart = Clock::now();
  vtkUnsignedCharArray* mask = impl.State;
  if (this->Hybrid &&
    !this->Classifier->Classify(renderer, geometry, samples, light, visibility, mask))
  {
    PENUMBRA_FAIL("linked-list shadows: the hybrid's classification failed");
  }
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  mask->SetNumberOfComponents(1);
  mask->SetNumberOfTuples(n);
  float* vis = n ? visibility->GetPointer(0) : nullptr;
  unsigned char* state = n ? mask->GetPointer(0) : nullptr;
  // The pending samples, listed once: every later phase visits only them. The hybrid's
  // classifier lists and counts them already (its uncertain samples, mask value 1 =
  // Pending; lit + shadowed + uncertain = the valid samples), so its samples are not scanned
  // again.
  impl.ToDecide.clear();
  if (this->Hybrid)
  {
    const std::vector<vtkIdType>& uncertain = this->Classifier->GetUncertainSamples();
    impl.ToDecide.assign(uncertain.begin(), uncertain.end());
    this->NumberOfValidSamples = this->Classifier->GetNumberOfLitSamples() +
      this->Classifier->GetNumberOfShadowedSamples() + static_cast<vtkIdType>(uncertain.size());
  }
  else
  {
    penumbra_light_views::ClassifyFacing(in.Light, n, in.Positions, in.Normals, in.Props, in.Shift,
      anyCaster, vis, state, Pending, Settled);
    for (vtkIdType s = 0; s < n; ++s)
    {
      this->NumberOfValidSamples += vis[s] >= 0.0f;
      if (state[s] == Pending)
      {
        impl.ToDecide.push_back(s);
      }
    }
  }
  std::vector<View> views;
  std::vector<signed char> sampleView;
  penumbra_light_views::FitViews(
    in.Light, n, in.Positions, in.Shift, state, Pending, views, sampleView, &impl.ToDecide);
  this->NumberOfViews = static_cast<int>(views.size());
  this->ClassifyTimeMs = ElapsedMs(classifyStart);

  // ---- 2.-4. Per view and pass: lists, irregular rasterization, apex-region triangles.
  impl.Depth.resize(static_cast<size_t>(n));
  impl.Texel.resize(static_cast<size_t>(n));
  impl.Point.resize(2 * static_cast<size_t>(n));
  const TestContext ctx = { &in, penumbra_rules::SceneDiagonal(geometry),
    this->Reference->GetRelativeEpsilon(), this->Reference->GetTieFactor(), state,
    impl.Depth.data() };
  vtkIdType rows = 0;
  if (!views.empty())
  {
    impl.Clusters.Update(impl.Casters.TriangleIds, in.TriangleVertices,
      std::max(geometry->GetGeometryTime(), geometry->GetFlagsTime()));
  }
  impl.ChooseListPath(this, renderer, n);
  for (size_t vi = 0; vi < views.size(); ++vi)
  {
    const auto listStart = Clock::now();
    impl.Listed.clear();
    ProjectSamples(views[vi], this->Resolution, static_cast<signed char>(vi), sampleView, ctx,
      impl.ToDecide, impl.Texel, impl.Depth, impl.Point, impl.Listed);
    this->ListTimeMs += ElapsedMs(listStart);
    impl.ListView(this, views[vi], static_cast<int>(vi), ctx, rows);
    this->NumberOfListedSamples += static_cast<vtkIdType>(impl.Listed.size());
  }
  this->LastListBuilder = impl.UseGpu ? LISTS_GPU : LISTS_CPU;
  this->MeanListLength = rows > 0 ? static_cast<double>(this->NumberOfListedSamples) / rows : 0.0;

  // ---- 5. Settle the lists' answers; the unknown and unlisted samples are traced.
  vtkIdType traced = 0;
  // Only pending samples changed state; the others are settled (0) already.
  for (vtkIdType s : impl.ToDecide)
  {
    if (state[s] == Shadowed)
    {
      vis[s] = 0.0f;
    }
    state[s] = (state[s] == Pending || state[s] == Unknown) ? 1 : 0;
    traced += state[s];
  }
  if (traced > 0)
  {
    const auto traceStart = Clock::now();
    this->Reference->SetGeometry(geometry);
    if (!this->Reference->ComputeVisibility(samples, light, visibility, mask))
    {
      PENUMBRA_FAIL("tracing the unknown samples failed: " << this->Reference->GetErrorMessage());
    }
    this->TraceTimeMs = ElapsedMs(traceStart);
  }
  this->NumberOfTracedSamples = traced;
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
// The list path of this call: the GPU when asked for and its context runs compute shaders
// (sample ids must fit its 32-bit nodes), else the CPU.
void vtkPenumbraLinkedListShadows::Internals::ChooseListPath(
  vtkPenumbraLinkedListShadows* self, vtkRenderer* renderer, vtkIdType n)
{
  this->UseGpu = false;
  if (self->ListBuilder != LISTS_GPU)
  {
    return;
  }
  std::string why;
  auto* window =
    renderer ? vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow()) : nullptr;
  if (n >= static_cast<vtkIdType>(NoNode))
  {
    why = "more view samples than 32-bit node links can name";
  }
  else if (self->Resolution > 4096)
  {
    why = "a grid beyond 4096^2 texels";
  }
  else
  {
    this->UseGpu = this->Compute.Prepare(window, why);
  }
  if (!this->UseGpu)
  {
    this->ReportListPath(self, why);
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraLinkedListShadows::Internals::ReportListPath(
  vtkPenumbraLinkedListShadows* self, const std::string& why)
{
  // Said once per reason: the CPU lists give the same answer, so rendering goes on.
  if (why != this->ReportedProblem)
  {
    this->ReportedProblem = why;
    vtkErrorWithObjectMacro(self,
      "GPU list construction (lists \"gpu\") cannot run: " << why << "; the CPU builds the lists");
  }
  this->UseGpu = false;
}

//------------------------------------------------------------------------------
// One pass's lists of the view's samples still pending: on the GPU (a pool of `capacity`
// nodes; the samples beyond it stay pending), or on the CPU (the first `capacity` pending).
// Returns false when nothing was pending.
bool vtkPenumbraLinkedListShadows::Internals::BuildPass(vtkPenumbraLinkedListShadows* self,
  int view, vtkIdType capacity, unsigned char* state, vtkIdType& rows)
{
  bool built = false;
  if (this->UseGpu)
  {
    std::string why;
    bool overflow = false;
    built = this->Grid.BuildOnGPU(
      this->Compute, self->Resolution, this->Listed, capacity, this->Texel, state, overflow, why);
    if (!built)
    {
      this->ReportListPath(self, why);
    }
    self->NumberOfOverflows += overflow ? 1 : 0;
  }
  if (!built)
  {
    this->Pick.clear();
    for (size_t i = 0;
         i < this->Listed.size() && static_cast<vtkIdType>(this->Pick.size()) < capacity; ++i)
    {
      if (state[this->Listed[i]] == Pending)
      {
        this->Pick.push_back(this->Listed[i]);
      }
    }
    this->Grid.BuildOnCPU(
      self->Resolution, this->Pick.data(), static_cast<vtkIdType>(this->Pick.size()), this->Texel);
  }
  vtkIdType passRows = 0;
  self->MaxListLength = std::max(self->MaxListLength, this->Grid.Finish(state, passRows));
  rows += passRows;
  if (self->RecordLists)
  {
    for (size_t j = 0; j < this->Grid.Samples.size(); ++j)
    {
      const vtkIdType entry[3] = { view, this->Grid.NodeTexel[j], this->Grid.Samples[j] };
      this->Recorded->InsertNextTypedTuple(entry);
    }
  }
  return !this->Grid.Samples.empty();
}

//------------------------------------------------------------------------------
// Per pass of one view: the lists, caster culling, the irregular rasterization and the apex
// region's triangles.
void vtkPenumbraLinkedListShadows::Internals::ListView(vtkPenumbraLinkedListShadows* self,
  const View& view, int vi, const TestContext& ctx, vtkIdType& rows)
{
  const int size = self->Resolution;
  const vtkIdType listed = static_cast<vtkIdType>(this->Listed.size());
  const vtkIdType capacity =
    self->ListCapacity > 0 ? self->ListCapacity : std::max<vtkIdType>(listed, 1);
  for (vtkIdType remaining = listed; remaining > 0;)
  {
    const auto listStart = Clock::now();
    const bool any = this->BuildPass(self, vi, capacity, ctx.State, rows);
    self->ListTimeMs += ElapsedMs(listStart);
    if (!any)
    {
      break;
    }
    const vtkIdType count = static_cast<vtkIdType>(this->Grid.Samples.size());
    remaining -= count;
    const auto rasterStart = Clock::now();
    const std::vector<vtkIdType>* casters = &this->Casters.TriangleIds;
    // Sparse lists (the hybrid's hard samples) are tested caster by caster box (CasterGrid),
    // which needs no coarse culling first: its bands skip the casters whose box meets no
    // listed texel, and MayBlock's depth test is per sample. Dense ones, where the per-caster
    // setup of the footprints pays off, are culled and rasterized.
    const bool sparse = count < SparseFactor * static_cast<vtkIdType>(casters->size());
    if (self->CullCasters && !sparse)
    {
      // Only casters that can reach a listed sample are rasterized (see SampleCells).
      this->Cells.Build(size, this->Grid.Samples.data(), count, this->Texel, this->Depth.data());
      self->NumberOfCulledCasters += this->Clusters.Cull(
        view, size, this->Cells, ctx.In->TriangleVertices, this->Keep, this->Kept);
      casters = &this->Kept;
    }
    self->NumberOfRasterizedCasters += static_cast<vtkIdType>(casters->size());
    this->Near.clear();
    if (sparse)
    {
      this->Bands.Build(view, size, ctx, *casters, this->Grid, this->Near);
      self->NumberOfTests += TestListsByBands(
        size, ctx, *casters, this->Grid, this->Bands, this->Point.data(), this->Casters.Exact);
      ++self->NumberOfSparsePasses;
    }
    else
    {
      self->NumberOfTests +=
        RasterizeLists(view, size, ctx, *casters, this->Grid, this->Casters.Exact, this->Near);
    }
    self->NumberOfTests += TestNearTriangles(ctx, this->Grid.Samples.data(), count, this->Near);
    this->Grid.Clear();
    self->RasterTimeMs += ElapsedMs(rasterStart);
    ++self->NumberOfPasses;
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraLinkedListShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Compute.Release(window);
}

//------------------------------------------------------------------------------
vtkIdTypeArray* vtkPenumbraLinkedListShadows::GetRecordedLists()
{
  vtkIdTypeArray* recorded = this->Impl->Recorded;
  // Sorted tuples: the per-texel sample sets, independent of node order and pass split.
  const vtkIdType n = recorded->GetNumberOfTuples();
  std::vector<std::array<vtkIdType, 3>> tuples(static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    recorded->GetTypedTuple(i, tuples[static_cast<size_t>(i)].data());
  }
  std::sort(tuples.begin(), tuples.end());
  for (vtkIdType i = 0; i < n; ++i)
  {
    recorded->SetTypedTuple(i, tuples[static_cast<size_t>(i)].data());
  }
  return recorded;
}

//------------------------------------------------------------------------------
double vtkPenumbraLinkedListShadows::GetListedFraction()
{
  return this->NumberOfValidSamples > 0
    ? static_cast<double>(this->NumberOfListedSamples) / this->NumberOfValidSamples
    : 0.0;
}

//------------------------------------------------------------------------------
double vtkPenumbraLinkedListShadows::GetUncertainFraction()
{
  if (this->Hybrid)
  {
    return this->GetListedFraction();
  }
  return this->NumberOfValidSamples > 0
    ? static_cast<double>(this->NumberOfTracedSamples) / this->NumberOfValidSamples
    : 0.0;
}

//------------------------------------------------------------------------------
void vtkPenumbraLinkedListShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "ListCapacity: " << this->ListCapacity << "\n";
  os << indent << "Hybrid: " << (this->Hybrid ? "on" : "off") << "\n";
  os << indent << "NumberOfValidSamples: " << this->NumberOfValidSamples << "\n";
  os << indent << "NumberOfListedSamples: " << this->NumberOfListedSamples << "\n";
  os << indent << "MaxListLength: " << this->MaxListLength << "\n";
  os << indent << "MeanListLength: " << this->MeanListLength << "\n";
  os << indent << "NumberOfTests: " << this->NumberOfTests << "\n";
  os << indent << "NumberOfTracedSamples: " << this->NumberOfTracedSamples << "\n";
  os << indent << "NumberOfPasses: " << this->NumberOfPasses << "\n";
  os << indent << "NumberOfViews: " << this->NumberOfViews << "\n";
  os << indent << "ListBuilder: " << (this->ListBuilder == LISTS_GPU ? "gpu" : "cpu") << "\n";
  os << indent << "NumberOfOverflows: " << this->NumberOfOverflows << "\n";
  os << indent << "NumberOfSparsePasses: " << this->NumberOfSparsePasses << "\n";
  os << indent << "CullCasters: " << (this->CullCasters ? "on" : "off") << "\n";
  os << indent << "NumberOfCulledCasters: " << this->NumberOfCulledCasters << "\n";
  os << indent << "NumberOfRasterizedCasters: " << this->NumberOfRasterizedCasters << "\n";
  os << indent << "ClassifyTimeMs: " << this->ClassifyTimeMs << "\n";
  os << indent << "ListTimeMs: " << this->ListTimeMs << "\n";
  os << indent << "RasterTimeMs: " << this->RasterTimeMs << "\n";
  os << indent << "TraceTimeMs: " << this->TraceTimeMs << "\n";
}
