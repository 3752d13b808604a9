// vtkPenumbraLinkedListShadows: caster culling, the casters' light-space boxes against the coarse
// occupancy of a pass's listed samples, cluster by cluster.

#include "vtkPenumbraLinkedListInternals.h"

#include "vtkSMPTools.h"

#include <algorithm>
#include <limits>

using namespace penumbra_llsm;

namespace
{
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
}

namespace penumbra_llsm
{
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

void SampleCells::Build(int size, const vtkIdType* samples, vtkIdType count,
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
bool SampleCells::Culled(const double box[4], float lower) const
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

// Any cell of `level` within the range (level-0 cells) that holds a sample not wholly in
// front of `lower`?
bool SampleCells::Live(int level, const int range[4], float lower, int px, int py) const
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

// Regroups the casters when they changed; true then.
bool CasterClusters::Update(const penumbra_casters::CasterIds& casters,
  const penumbra::SceneTriangles* vertices, vtkMTimeType time)
{
  if (this->Source == casters.Key() && this->SourceSize == casters.size() &&
    this->Vertices == vertices && this->Time == time)
  {
    return false;
  }
  this->Source = casters.Key();
  this->SourceSize = casters.size();
  this->Vertices = vertices;
  this->Time = time;
  const size_t n = casters.size();
  // Centroids are made again where needed rather than kept (24 bytes a caster).
  auto centroid = [&](size_t i, double centre[3])
  {
    double p[9];
    vertices->Get(casters[i], p);
    for (int c = 0; c < 3; ++c)
    {
      centre[c] = (p[c] + p[3 + c] + p[6 + c]) / 3.0;
    }
  };
  double lo[3] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max() };
  double hi[3] = { -lo[0], -lo[1], -lo[2] };
  for (size_t i = 0; i < n; ++i)
  {
    double centre[3];
    centroid(i, centre);
    for (int c = 0; c < 3; ++c)
    {
      lo[c] = std::min(lo[c], centre[c]);
      hi[c] = std::max(hi[c], centre[c]);
    }
  }
  // (Morton code, position in `casters`): sorted, the casters' Morton order with ties in
  // caster order (ids ascend with the position).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> keyed(n);
  for (size_t i = 0; i < n; ++i)
  {
    double centre[3];
    centroid(i, centre);
    std::uint32_t code = 0;
    std::uint32_t q[3];
    for (int c = 0; c < 3; ++c)
    {
      const double extent = hi[c] - lo[c];
      const double u = extent > 0.0 ? (centre[c] - lo[c]) / extent : 0.0;
      q[c] = static_cast<std::uint32_t>(std::min(1023.0, std::max(0.0, u * 1024.0)));
    }
    for (int b = 9; b >= 0; --b)
    {
      code =
        (code << 3) | (((q[0] >> b) & 1u) << 2) | (((q[1] >> b) & 1u) << 1) | ((q[2] >> b) & 1u);
    }
    keyed[i] = { code, static_cast<std::uint32_t>(i) };
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
      this->Order.at(i) = casters[keyed[i].second];
      double p[9];
      vertices->Get(this->Order[i], p);
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
vtkIdType CasterClusters::Cull(const View& view, int size, const SampleCells& cells,
  const penumbra::SceneTriangles& vertices, std::vector<unsigned char>& keep,
  penumbra_casters::CasterIds& kept) const
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
          double p[9];
          vertices.Get(this->Order[static_cast<size_t>(i)], p);
          keep[static_cast<size_t>(i)] =
            !(BoundPoints(view, size, p, 3, box, lower) && cells.Culled(box, lower));
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
}
