// vtkPenumbraLinkedListShadows: the exact tests of caster triangles against the listed samples, by
// irregular rasterization (Ferko 2014; Johnson et al. 2005) or, for sparse passes, by caster box.

#include "vtkPenumbraLinkedListInternals.h"

#include "vtkMath.h"
#include "vtkPenumbraCasterBuffers.h"
#include "vtkPenumbraConservativeMapCPU.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <atomic>
#include <limits>

using namespace penumbra_llsm;

namespace
{
// Triangles in a perspective view's apex region are tested against every sample of the view;
// beyond this many, the view's open samples are traced instead.
constexpr size_t MaxNearTriangles = 256;

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
}

namespace penumbra_llsm
{
// Irregular rasterization (Ferko 2014; Johnson et al. 2005): every caster triangle meets the
// samples listed at each texel its conservative footprint touches. A texel whose samples are
// all shadowed drops out. Returns the number of exact tests; the apex region's triangles go
// to `nearTriangles`.
vtkIdType RasterizeLists(const View& view, int size, const TestContext& ctx,
  const penumbra_casters::CasterIds& casters, Lists& lists, penumbra_casters::ExactTriangles& exact,
  std::vector<vtkIdType>& nearTriangles)
{
  const std::vector<std::uint32_t>& nodes = lists.Nodes;
  std::vector<unsigned char>& active = lists.Active;
  const penumbra::SceneTriangles& vertices = *ctx.In->SceneTriangles;
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

// An upper bound of MayBlock's margin for caster i over every ray of the pass that can
// come near it (the largest ErrPos; the smallest cosine with its normal: a directional
// light's one direction, or for a positional light h / d, h the light's distance from the
// triangle's plane and d its farthest vertex). -1 when the bound is too loose to use.
double CasterGrid::MarginBound(const Description& d, const double* tri,
  const penumbra_light_views::LightSetup& light, double errPos)
{
  const double* n = d.Normal;
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
  const double slack = errPos * (1.0 + 1.0 / cosine) + d.Slop;
  if (!(slack < 1e-3 * reach) || !std::isfinite(slack * d.Scale))
  {
    return -1.0; // rays that near it may leave the cosine bound
  }
  return 2.0 * slack * d.Scale + 2e-3;
}

// False when no point of texel (x, y) lies within caster i's TexelMargin of its projection:
// then no sample of the texel passes MayBlock.
bool CasterGrid::TexelNear(const Description& d, double x, double y)
{
  const double m = d.TexelMargin;
  if (m < 0.0)
  {
    return true;
  }
  const double* e = d.Edge;
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
bool CasterGrid::MayBlock(const Description& d, const float* point, double depth,
  const penumbra_light_views::ShadowRay& ray) const
{
  if (d.Flat)
  {
    return true;
  }
  if (PlaneBehind(this->Perspective, d.Plane, point, depth))
  {
    return false;
  }
  const double* n = d.Normal;
  const double cosine = std::fabs(ray.D[0] * n[0] + ray.D[1] * n[1] + ray.D[2] * n[2]);
  if (!(cosine > 1e-5))
  {
    return true; // grazing: the exact test leaves it to the tracer
  }
  const double margin = 2.0 * (ray.ErrPos * (1.0 + 1.0 / cosine) + d.Slop) * d.Scale + 1e-3;
  const double* e = d.Edge;
  const double x = point[0], y = point[1];
  return e[0] * x + e[1] * y + e[2] >= -margin && e[3] * x + e[4] * y + e[5] >= -margin &&
    e[6] * x + e[7] * y + e[8] >= -margin;
}

// Counts the pass's listed texels per tile of TileTexels^2 texels, as a summed-area table.
void CasterGrid::CountTiles(int size, const Lists& lists)
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

// Whether a caster's `box` overlaps a tile with a listed texel: if not, the band walk would
// find no listed texel under it (the same First/Last texel bounds), so it is not binned.
bool CasterGrid::BoxMeetsList(const double box[4], int size) const
{
  const size_t side = static_cast<size_t>(this->Tiles) + 1;
  const size_t x0 = static_cast<size_t>(First(box[0], size) / TileTexels);
  const size_t x1 = static_cast<size_t>(Last(box[1], size) / TileTexels) + 1;
  const size_t y0 = static_cast<size_t>(First(box[2], size) / TileTexels);
  const size_t y1 = static_cast<size_t>(Last(box[3], size) / TileTexels) + 1;
  if (x1 <= x0 || y1 <= y0)
  {
    return true; // an empty span: leave it to the band walk
  }
  const std::uint32_t* t = this->TileSums.data();
  return t[y1 * side + x1] - t[y0 * side + x1] - t[y1 * side + x0] + t[y0 * side + x0] > 0;
}

// What each caster is for the pass (0 cannot block, 1 binned, 2 apex region), from its box
// alone. Nothing else is kept per caster: the binning and the band walk make a binned
// caster's box and description again from its triangle (BoxOf, Describe).
void CasterGrid::Classify(const View& view, int size, const TestContext& ctx,
  const penumbra_casters::CasterIds& casters, std::vector<unsigned char>& kinds) const
{
  const size_t n = casters.size();
  kinds.assign(n, 0);
  vtkSMPTools::For(0, static_cast<vtkIdType>(n),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        double tri[9];
        ctx.In->Triangle(casters[static_cast<size_t>(i)], tri);
        unsigned char& kind = kinds[static_cast<size_t>(i)];
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
        double box[4];
        float lower;
        if (!BoundPoints(view, size, tri, 3, box, lower))
        {
          kind = 2;
        }
        else if (box[1] >= 0.0 && box[3] >= 0.0 && box[0] < size && box[2] < size &&
          this->BoxMeetsList(box, size))
        {
          kind = 1;
        }
      }
    });
}

// A binned caster's texel range (x0, x1, y0, y1) and lowest stored depth, from its triangle.
void CasterGrid::BoxOf(const double tri[9], int range[4], float& lower) const
{
  double box[4];
  BoundPoints(this->PassView, this->Size, tri, 3, box, lower);
  range[0] = First(box[0], this->Size);
  range[1] = Last(box[1], this->Size);
  range[2] = First(box[2], this->Size);
  range[3] = Last(box[3], this->Size);
}

// One binned caster described for MayBlock (see Description), from its triangle.
void CasterGrid::Describe(
  const double tri[9], const penumbra_light_views::LightSetup& light, Description& d) const
{
  d.Flat = !ProjectionBounds(
    this->PassView, this->RowScale, tri, d.Edge, d.Plane, d.Normal, d.Slop, d.Scale, this->Size);
  d.TexelMargin = d.Flat ? -1.0 : MarginBound(d, tri, light, this->ErrPos);
}

// The listed samples' rays (80 bytes each): the CPU lists hold their nodes in texel order,
// so a band's nodes are one run and the band walk makes their rays (RaysOfBand); lists in
// any other order (the GPU's) keep every ray, made here. Either way their largest
// positional slack is needed first (ErrPos).
void CasterGrid::MakeRays(const TestContext& ctx, const Lists& lists)
{
  this->NodesByTexel = std::is_sorted(lists.NodeTexel.begin(), lists.NodeTexel.end());
  const size_t nodes = lists.Samples.size();
  std::vector<penumbra_light_views::ShadowRay>().swap(this->Rays);
  if (!this->NodesByTexel)
  {
    this->Rays.resize(nodes);
  }
  constexpr size_t Chunk = 4096;
  std::vector<double> chunkErr((nodes + Chunk - 1) / Chunk, 0.0);
  vtkSMPTools::For(0, static_cast<vtkIdType>(chunkErr.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (size_t c = static_cast<size_t>(begin); c < static_cast<size_t>(end); ++c)
      {
        for (size_t j = c * Chunk; j < std::min(nodes, (c + 1) * Chunk); ++j)
        {
          const penumbra_light_views::ShadowRay ray = ctx.Ray(lists.Samples[j]);
          chunkErr[c] = std::max(chunkErr[c], ray.ErrPos);
          if (!this->NodesByTexel)
          {
            this->Rays[j] = ray;
          }
        }
      }
    });
  this->ErrPos = 0.0;
  for (double e : chunkErr)
  {
    this->ErrPos = std::max(this->ErrPos, e);
  }
}

// Bins `casters` by band, lists the pass's texels and makes the listed samples' rays; the
// apex region's casters go to `nearTriangles` (as with the rasterizer). Returns the binned.
vtkIdType CasterGrid::Build(const View& view, int size, const TestContext& ctx,
  const penumbra_casters::CasterIds& casters, const Lists& lists,
  std::vector<vtkIdType>& nearTriangles)
{
  this->MakeRays(ctx, lists);
  this->CountTiles(size, lists);
  this->Perspective = view.Perspective;
  this->PassView = view;
  this->Size = size;
  auto norm3 = [](const double* r) { return std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]); };
  const double w3 = view.Perspective ? 1.01 * norm3(view.Row[3]) : 0.0;
  this->RowScale = 0.5 * size *
    std::sqrt((norm3(view.Row[0]) + w3) * (norm3(view.Row[0]) + w3) +
      (norm3(view.Row[1]) + w3) * (norm3(view.Row[1]) + w3));
  std::vector<unsigned char> kinds;
  this->Classify(view, size, ctx, casters, kinds);
  vtkIdType binned = 0;
  for (size_t i = 0; i < casters.size(); ++i)
  {
    if (kinds[i] == 2)
    {
      nearTriangles.push_back(casters[i]);
    }
    binned += kinds[i] == 1 ? 1 : 0;
  }
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
  // Casters per band of BandRows grid rows, by their boxes' rows: a counting sort in caster
  // order, counted and then filled per chunk of casters in parallel, each caster's box made
  // again (BoxOf) rather than kept.
  const int bands = (size + BandRows - 1) / BandRows;
  const size_t n = casters.size();
  constexpr size_t Chunk = 65536;
  const size_t chunks = (n + Chunk - 1) / Chunk;
  std::vector<vtkIdType> offsets(chunks * static_cast<size_t>(bands), 0);
  auto forBands = [&](size_t i, auto&& f)
  {
    if (kinds[i] != 1)
    {
      return;
    }
    double tri[9];
    ctx.In->Triangle(casters[i], tri);
    int range[4];
    float lower;
    this->BoxOf(tri, range, lower);
    for (int b = range[2] / BandRows; b <= range[3] / BandRows; ++b)
    {
      f(static_cast<size_t>(b));
    }
  };
  auto forChunks = [&](auto&& f)
  {
    vtkSMPTools::For(0, static_cast<vtkIdType>(chunks),
      [&](vtkIdType begin, vtkIdType end)
      {
        for (size_t c = static_cast<size_t>(begin); c < static_cast<size_t>(end); ++c)
        {
          vtkIdType* chunkOffsets = offsets.data() + c * static_cast<size_t>(bands);
          for (size_t i = c * Chunk; i < std::min(n, (c + 1) * Chunk); ++i)
          {
            f(i, chunkOffsets);
          }
        }
      });
  };
  forChunks([&](size_t i, vtkIdType* counts) { forBands(i, [&](size_t b) { ++counts[b]; }); });
  // Counts to positions: band by band, chunk by chunk.
  this->BandStart.assign(static_cast<size_t>(bands) + 1, 0);
  vtkIdType position = 0;
  for (size_t b = 0; b < static_cast<size_t>(bands); ++b)
  {
    this->BandStart[b] = position;
    for (size_t c = 0; c < chunks; ++c)
    {
      vtkIdType& slot = offsets[c * static_cast<size_t>(bands) + b];
      const vtkIdType count = slot;
      slot = position;
      position += count;
    }
  }
  this->BandStart[static_cast<size_t>(bands)] = position;
  std::vector<std::uint32_t>().swap(this->Entries); // no copy of the last pass's entries
  this->Entries.resize(static_cast<size_t>(position));
  forChunks(
    [&](size_t i, vtkIdType* next)
    {
      forBands(i,
        [&](size_t b)
        { this->Entries[static_cast<size_t>(next[b]++)] = static_cast<std::uint32_t>(i); });
    });
  return binned;
}

// The rays of the nodes of grid rows [rowLo, rowHi]: the kept ones, or (nodes in texel order)
// the band's run of nodes, made into `scratch`.
RayRun CasterGrid::RaysOfBand(const TestContext& ctx, const Lists& lists, int size, int rowLo,
  int rowHi, std::vector<penumbra_light_views::ShadowRay>& scratch) const
{
  if (!this->NodesByTexel)
  {
    return { this->Rays.data(), 0 };
  }
  const std::uint32_t lo = static_cast<std::uint32_t>(rowLo) * static_cast<std::uint32_t>(size);
  const std::uint32_t hi = static_cast<std::uint32_t>(rowHi + 1) * static_cast<std::uint32_t>(size);
  const auto first = std::lower_bound(lists.NodeTexel.begin(), lists.NodeTexel.end(), lo);
  const auto last = std::lower_bound(first, lists.NodeTexel.end(), hi);
  const size_t j0 = static_cast<size_t>(first - lists.NodeTexel.begin());
  scratch.resize(static_cast<size_t>(last - first));
  for (size_t k = 0; k < scratch.size(); ++k)
  {
    scratch[k] = ctx.Ray(lists.Samples[j0 + k]);
  }
  return { scratch.data(), j0 };
}

// The sparse form of RasterizeLists: per band, each binned caster meets the samples of the
// listed texels its box overlaps (MayBlock first, then the exact test). Returns the number of
// exact tests.
vtkIdType TestListsByBands(int size, const TestContext& ctx,
  const penumbra_casters::CasterIds& casters, const Lists& lists, const CasterGrid& grid,
  const float* point, penumbra_casters::ExactTriangles& exact)
{
  const penumbra::SceneTriangles& vertices = *ctx.In->SceneTriangles;
  unsigned char* state = ctx.State;
  const int bands = static_cast<int>(grid.BandStart.size()) - 1;
  std::atomic<vtkIdType> tests(0);
  // Bands in parallel: a texel's samples belong to one band, so to one thread.
  vtkSMPTools::For(0, bands,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType local = 0;
      penumbra_rules::ExactTriangle scratch;
      std::vector<penumbra_light_views::ShadowRay> bandRays;
      for (vtkIdType b = begin; b < end; ++b)
      {
        const int rowLo = static_cast<int>(b) * CasterGrid::BandRows;
        const int rowHi = std::min(size - 1, rowLo + CasterGrid::BandRows - 1);
        const RayRun rays = grid.RaysOfBand(ctx, lists, size, rowLo, rowHi, bandRays);
        for (vtkIdType e = grid.BandStart[static_cast<size_t>(b)];
             e < grid.BandStart[static_cast<size_t>(b) + 1]; ++e)
        {
          const vtkIdType id = casters[grid.Entries[static_cast<size_t>(e)]];
          double tri[9];
          ctx.In->Triangle(id, tri);
          int range[4];
          float lower;
          grid.BoxOf(tri, range, lower);
          const std::uint32_t x0 = static_cast<std::uint32_t>(range[0]);
          const std::uint32_t x1 = static_cast<std::uint32_t>(range[1]);
          const penumbra_rules::ExactTriangle* triangle = nullptr;
          bool made = false;
          CasterGrid::Description d;
          bool described = false;
          for (int y = std::max(rowLo, range[2]); y <= std::min(rowHi, range[3]); ++y)
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
              if (Behind(lower, grid.TexelDepth[k]))
              {
                continue;
              }
              if (!described)
              {
                grid.Describe(tri, ctx.In->Light, d);
                described = true;
              }
              if (!CasterGrid::TexelNear(d, *it - base, y))
              {
                continue;
              }
              for (std::uint32_t j = lists.Head[*it]; j != NoNode; j = lists.Nodes[2 * j + 1])
              {
                const vtkIdType s = static_cast<vtkIdType>(lists.Nodes[2 * j]);
                const penumbra_light_views::ShadowRay& ray = rays.Rays[j - rays.First];
                if (state[s] == Shadowed || ctx.In->OwnCaster(id, s) ||
                  Behind(lower, ctx.Depth[s]) ||
                  !grid.MayBlock(d, point + 2 * s, ctx.Depth[s], ray))
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
    double v[9];
    ctx.In->Triangle(id, v);
    made[k] = penumbra_rules::MakeExactTriangle(v, id, triangles[k]);
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
