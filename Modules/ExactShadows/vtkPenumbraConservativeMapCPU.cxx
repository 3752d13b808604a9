#include "vtkPenumbraConservativeMapCPU.h"

#include "vtkPenumbraLightViews.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

namespace penumbra_conservative
{
namespace
{
// A texel is kept when its square, grown by this many texels on each side, overlaps the
// triangle's projection: the float rounding between the reference's rays and our double
// projection (the same quarter texel the GPU program allows).
constexpr double Grow = 0.25;
constexpr int TileSize = 64;
constexpr int MaxPolygon = 8; // a triangle clipped by four planes has at most 7 vertices

// One caster triangle's projection into the view, ready to rasterize.
struct Footprint
{
  vtkIdType Id = -1;
  int NumEdges = 0;
  bool Line = false;                    // degenerate projection: Edge[0] is a two-sided line
  double Edge[MaxPolygon][3] = {};      // a x + b y + c >= 0 inside (texel units)
  int X0 = 0, X1 = -1, Y0 = 0, Y1 = -1; // texel range, inclusive
  bool PlaneOk = false;
  double Plane[3] = { 0, 0, 0 }; // orthographic: depth; perspective: 1 / depth, affine in x, y
  double VertexMin = 0.0;        // smallest stored depth over the clipped polygon
};

struct Clip
{
  double P[4]; // x, y, stored depth (orthographic) or unused, w
};

// Clips `poly` against a * x + b * y + s * w >= 0 (homogeneous; the view's side planes).
int ClipAgainst(Clip* poly, int n, double a, double b, double s)
{
  Clip out[MaxPolygon];
  int m = 0;
  for (int i = 0; i < n && m < MaxPolygon; ++i)
  {
    const Clip& p = poly[i];
    const Clip& q = poly[(i + 1) % n];
    const double dp = a * p.P[0] + b * p.P[1] + s * p.P[3];
    const double dq = a * q.P[0] + b * q.P[1] + s * q.P[3];
    if (dp >= 0.0)
    {
      out[m++] = p;
    }
    if ((dp >= 0.0) != (dq >= 0.0) && m < MaxPolygon)
    {
      const double t = dp / (dp - dq);
      Clip r;
      for (int c = 0; c < 4; ++c)
      {
        r.P[c] = p.P[c] + t * (q.P[c] - p.P[c]);
      }
      out[m++] = r;
    }
  }
  std::copy(out, out + m, poly);
  return m;
}

// Whether any of the `n` bytes from `p` is set, eight at a time (active masks are sparse).
bool AnySet(const unsigned char* p, int n)
{
  int i = 0;
  for (; i + 8 <= n; i += 8)
  {
    std::uint64_t word;
    std::memcpy(&word, p + i, sizeof(word));
    if (word != 0)
    {
      return true;
    }
  }
  for (; i < n; ++i)
  {
    if (p[i])
    {
      return true;
    }
  }
  return false;
}

// Which tiles hold an active texel, as a summed-area table over (tiles + 1)^2 entries.
struct TileCull
{
  int Tiles = 0;
  std::vector<int> Sum;

  // True when no tile that texel range [x0, x1] x [y0, y1] (clamped to the map) touches is active.
  bool Empty(int size, double x0, double x1, double y0, double y1) const
  {
    // Clamped before the conversion (huge or NaN coordinates keep the whole map).
    auto texel = [size](double v)
    {
      return std::max(0,
        std::min(
          size - 1, static_cast<int>(std::min<double>(size, std::max(-1.0, std::floor(v))))));
    };
    if (!std::isfinite(x0 + x1 + y0 + y1))
    {
      return false;
    }
    if (x1 < 0.0 || y1 < 0.0 || x0 >= size || y0 >= size)
    {
      return true;
    }
    const int tx0 = texel(x0) / TileSize, tx1 = texel(x1) / TileSize;
    const int ty0 = texel(y0) / TileSize, ty1 = texel(y1) / TileSize;
    if (tx0 > tx1 || ty0 > ty1)
    {
      return true;
    }
    const int w = this->Tiles + 1;
    return this->Sum[(ty1 + 1) * w + tx1 + 1] - this->Sum[ty0 * w + tx1 + 1] -
      this->Sum[(ty1 + 1) * w + tx0] + this->Sum[ty0 * w + tx0] ==
      0;
  }
};

// The plane of the depth quantity Q through the projected vertices (X, Y), affine in the
// texel coordinates; fp.PlaneOk stays false for a projection without area.
void FitDepthPlane(const double X[3], const double Y[3], const double Q[3], Footprint& fp)
{
  const double ex1 = X[1] - X[0], ey1 = Y[1] - Y[0], eq1 = Q[1] - Q[0];
  const double ex2 = X[2] - X[0], ey2 = Y[2] - Y[0], eq2 = Q[2] - Q[0];
  const double det = ex1 * ey2 - ex2 * ey1;
  const double scale = std::max({ ex1 * ex1 + ey1 * ey1, ex2 * ex2 + ey2 * ey2, 1e-300 });
  if (std::fabs(det) > 1e-6 * scale)
  {
    fp.Plane[0] = (eq1 * ey2 - eq2 * ey1) / det;
    fp.Plane[1] = (ex1 * eq2 - ex2 * eq1) / det;
    fp.Plane[2] = Q[0] - fp.Plane[0] * X[0] - fp.Plane[1] * Y[0];
    fp.PlaneOk =
      std::isfinite(fp.Plane[0]) && std::isfinite(fp.Plane[1]) && std::isfinite(fp.Plane[2]);
  }
}

// Sets fp's edges from the clipped polygon (px, py) of n vertices, `extent` its box's larger
// side. Separating axes of a convex polygon and a square: the square's axes (fp's texel
// range) and the polygon's edge normals. A projection without area (edge-on triangle) is a
// segment: its line is the remaining axis.
void SetSeparatingAxes(const double* px, const double* py, int n, double extent, Footprint& fp)
{
  double area = 0.0;
  for (int k = 0; k < n; ++k)
  {
    area += px[k] * py[(k + 1) % n] - px[(k + 1) % n] * py[k];
  }
  fp.NumEdges = 0;
  fp.Line = !(std::fabs(area) > 1e-9 * extent * extent);
  if (!fp.Line)
  {
    const double orient = area > 0.0 ? 1.0 : -1.0;
    for (int k = 0; k < n; ++k)
    {
      const int j = (k + 1) % n;
      const double a = -(py[j] - py[k]) * orient;
      const double b = (px[j] - px[k]) * orient;
      if (a == 0.0 && b == 0.0)
      {
        continue; // repeated vertex
      }
      double* e = fp.Edge[fp.NumEdges++];
      e[0] = a;
      e[1] = b;
      e[2] = -(a * px[k] + b * py[k]);
    }
  }
  else if (n > 0)
  {
    // The two farthest-apart vertices span the segment.
    int ia = 0, ib = 0;
    double best = -1.0;
    for (int k = 0; k < n; ++k)
    {
      for (int j = k + 1; j < n; ++j)
      {
        const double d = (px[j] - px[k]) * (px[j] - px[k]) + (py[j] - py[k]) * (py[j] - py[k]);
        if (d > best)
        {
          best = d;
          ia = k;
          ib = j;
        }
      }
    }
    if (best > 0.0)
    {
      double* e = fp.Edge[fp.NumEdges++];
      e[0] = -(py[ib] - py[ia]);
      e[1] = px[ib] - px[ia];
      e[2] = -(e[0] * px[ia] + e[1] * py[ia]);
    }
  }
}

// Projects triangle `id` into `view`. Returns 0 when it misses the view (or, with `cull`,
// every active tile), 1 when `fp` is ready to rasterize, 2 when it reaches the apex region
// (perspective views).
int MakeFootprint(const penumbra_light_views::View& view, int size, const double* tri, vtkIdType id,
  Footprint& fp, const TileCull* cull)
{
  const double slack = 1.0 + 2.0 / size; // one texel beyond the map on each side
  Clip poly[MaxPolygon];
  double wMin = std::numeric_limits<double>::infinity();
  double wMax = -wMin;
  int outside[4] = { 0, 0, 0, 0 };
  for (int k = 0; k < 3; ++k)
  {
    const double* p = tri + 3 * k;
    Clip& c = poly[k];
    c.P[0] = view.Dot(0, p);
    c.P[1] = view.Dot(1, p);
    c.P[2] = view.Perspective ? 0.0 : view.Dot(2, p);
    c.P[3] = view.Perspective ? view.Dot(3, p) : 1.0;
    const double w = slack * c.P[3];
    outside[0] += c.P[0] > w;
    outside[1] += -c.P[0] > w;
    outside[2] += c.P[1] > w;
    outside[3] += -c.P[1] > w;
    wMin = std::min(wMin, c.P[3]);
    wMax = std::max(wMax, c.P[3]);
  }
  if (outside[0] == 3 || outside[1] == 3 || outside[2] == 3 || outside[3] == 3 || !(wMax > 0.0))
  {
    return 0; // wholly outside one side plane, or behind the apex
  }
  if (view.Perspective && !(wMin >= view.NearW))
  {
    return 2;
  }
  // The plane of the depth quantity, from the unclipped vertices (affine in x, y: the depth
  // itself for orthographic views, 1 / (w / Far) for perspective ones).
  double X[3], Y[3], Q[3];
  for (int k = 0; k < 3; ++k)
  {
    const Clip& c = poly[k];
    X[k] = (c.P[0] / c.P[3] * 0.5 + 0.5) * size;
    Y[k] = (c.P[1] / c.P[3] * 0.5 + 0.5) * size;
    Q[k] = view.Perspective ? view.Far / c.P[3] : c.P[2];
  }
  // All vertices are in front of the apex here, so the projected triangle (which clipping only
  // shrinks) lies in the box of the projected vertices, widened by a texel for rounding.
  if (cull &&
    cull->Empty(size, std::min({ X[0], X[1], X[2] }) - Grow - 1.0,
      std::max({ X[0], X[1], X[2] }) + Grow + 1.0, std::min({ Y[0], Y[1], Y[2] }) - Grow - 1.0,
      std::max({ Y[0], Y[1], Y[2] }) + Grow + 1.0))
  {
    return 0;
  }
  FitDepthPlane(X, Y, Q, fp);
  int n = 3;
  n = ClipAgainst(poly, n, -1.0, 0.0, slack);
  n = n ? ClipAgainst(poly, n, 1.0, 0.0, slack) : 0;
  n = n ? ClipAgainst(poly, n, 0.0, -1.0, slack) : 0;
  n = n ? ClipAgainst(poly, n, 0.0, 1.0, slack) : 0;
  if (n == 0)
  {
    return 0;
  }
  double px[MaxPolygon], py[MaxPolygon];
  double xmin = std::numeric_limits<double>::infinity(), xmax = -xmin;
  double ymin = xmin, ymax = -xmin;
  fp.VertexMin = std::numeric_limits<double>::infinity();
  for (int k = 0; k < n; ++k)
  {
    const Clip& c = poly[k];
    px[k] = (c.P[0] / c.P[3] * 0.5 + 0.5) * size;
    py[k] = (c.P[1] / c.P[3] * 0.5 + 0.5) * size;
    xmin = std::min(xmin, px[k]);
    xmax = std::max(xmax, px[k]);
    ymin = std::min(ymin, py[k]);
    ymax = std::max(ymax, py[k]);
    fp.VertexMin = std::min(fp.VertexMin, view.Perspective ? c.P[3] / view.Far : c.P[2]);
  }
  if (!std::isfinite(xmin + xmax + ymin + ymax + fp.VertexMin))
  {
    // Cannot happen for finite input past the checks above; never lose a caster silently.
    xmin = ymin = 0.0;
    xmax = ymax = size;
    fp.VertexMin = -std::numeric_limits<double>::infinity();
    fp.PlaneOk = false;
    n = 0;
  }
  fp.Id = id;
  fp.X0 = std::max(0, static_cast<int>(std::floor(xmin - Grow)));
  fp.X1 = std::min(size - 1, static_cast<int>(std::floor(xmax + Grow)));
  fp.Y0 = std::max(0, static_cast<int>(std::floor(ymin - Grow)));
  fp.Y1 = std::min(size - 1, static_cast<int>(std::floor(ymax + Grow)));
  if (fp.X0 > fp.X1 || fp.Y0 > fp.Y1)
  {
    return 0;
  }
  SetSeparatingAxes(px, py, n, std::max(xmax - xmin, ymax - ymin), fp);
  return 1;
}

// Conservative overlap of texel square [x0, x1] x [y0, y1] with the footprint.
bool Overlaps(const Footprint& fp, double x0, double x1, double y0, double y1)
{
  for (int k = 0; k < fp.NumEdges; ++k)
  {
    const double* e = fp.Edge[k];
    const double hi = e[2] + e[0] * (e[0] > 0.0 ? x1 : x0) + e[1] * (e[1] > 0.0 ? y1 : y0);
    if (hi < 0.0)
    {
      return false;
    }
    if (fp.Line)
    {
      const double lo = e[2] + e[0] * (e[0] > 0.0 ? x0 : x1) + e[1] * (e[1] > 0.0 ? y0 : y1);
      if (lo > 0.0)
      {
        return false;
      }
    }
  }
  return true;
}

// The conservative depth of Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for
// Alias-Free Hard Shadows", Eurographics 2009 Areas Papers, §4.1: a lower bound of the
// triangle's stored depth over the square, never
// below its smallest vertex depth. The depth quantity is affine over the square, so its
// extreme is at a corner; a float result is rounded down.
float ConservativeDepth(
  const Footprint& fp, bool perspective, double x0, double x1, double y0, double y1)
{
  double depth = fp.VertexMin;
  if (fp.PlaneOk)
  {
    const double* p = fp.Plane;
    if (perspective)
    {
      // 1 / depth is affine: its maximum gives the minimum depth, if positive throughout.
      const double qmax = p[2] + p[0] * (p[0] > 0.0 ? x1 : x0) + p[1] * (p[1] > 0.0 ? y1 : y0);
      const double qmin = p[2] + p[0] * (p[0] > 0.0 ? x0 : x1) + p[1] * (p[1] > 0.0 ? y0 : y1);
      if (qmin > 0.0 && qmax > 0.0)
      {
        depth = std::max(depth, (1.0 / qmax) * (1.0 - 1e-9));
      }
    }
    else
    {
      const double dmin = p[2] + p[0] * (p[0] > 0.0 ? x0 : x1) + p[1] * (p[1] > 0.0 ? y0 : y1);
      depth = std::max(depth, dmin - 1e-9 * (1.0 + std::fabs(dmin)));
    }
  }
  float f = static_cast<float>(depth);
  if (static_cast<double>(f) > depth)
  {
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  }
  return f;
}

// Which tiles hold an active texel (all of them without `active`).
std::vector<unsigned char> ActiveTiles(const unsigned char* active, int size, int tiles)
{
  std::vector<unsigned char> tileActive(static_cast<size_t>(tiles) * tiles, active ? 0 : 1);
  if (!active)
  {
    return tileActive;
  }
  vtkSMPTools::For(0, tiles,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (int ty = static_cast<int>(begin); ty < static_cast<int>(end); ++ty)
      {
        for (int y = ty * TileSize; y < std::min(size, (ty + 1) * TileSize); ++y)
        {
          for (int tx = 0; tx < tiles; ++tx)
          {
            unsigned char& tile = tileActive[static_cast<size_t>(ty) * tiles + tx];
            tile = tile ||
              AnySet(active + static_cast<size_t>(y) * size + tx * TileSize,
                std::min(TileSize, size - tx * TileSize));
          }
        }
      }
    });
  return tileActive;
}

// The summed-area table of the active tiles, so a footprint can be culled in O(1).
TileCull MakeTileCull(const std::vector<unsigned char>& tileActive, int tiles)
{
  TileCull cull;
  cull.Tiles = tiles;
  cull.Sum.assign(static_cast<size_t>(tiles + 1) * (tiles + 1), 0);
  const size_t w = static_cast<size_t>(tiles) + 1;
  for (int ty = 0; ty < tiles; ++ty)
  {
    for (int tx = 0; tx < tiles; ++tx)
    {
      cull.Sum[(ty + 1) * w + tx + 1] = tileActive[static_cast<size_t>(ty) * tiles + tx] +
        cull.Sum[ty * w + tx + 1] + cull.Sum[(ty + 1) * w + tx] - cull.Sum[ty * w + tx];
    }
  }
  return cull;
}

// The casters binned to the active tiles their footprints touch by a counting sort (in
// parallel, caster order kept, so the result is deterministic): tile t's casters are
// binned[start[t] .. start[t + 1]), as indices into `casters`. No footprint is kept (one is
// about 260 bytes, a 1e7-triangle scene's would take 2.6 GB): the tiles make them again from
// the triangle, the same function of the same input. Triangles near a perspective apex go to
// nearTriangles.
struct Bins
{
  std::vector<vtkIdType> Start;
  std::vector<std::uint32_t> Binned;
};

// The tiles a footprint touches, inclusive.
struct TileRange
{
  std::uint16_t X0 = 1, X1 = 0, Y0 = 1, Y1 = 0;
};

Bins BinFootprints(const penumbra_light_views::View& view, int size,
  const penumbra::SceneTriangles& triangles, const penumbra_casters::CasterIds& casters,
  const std::vector<unsigned char>& tileActive, const TileCull* cull,
  std::vector<vtkIdType>& nearTriangles, CpuMapStats& stats)
{
  const int tiles = (size + TileSize - 1) / TileSize;
  Bins bins;
  std::vector<TileRange> ranges(casters.size());
  std::vector<unsigned char> status(casters.size(), 0);
  vtkSMPTools::For(0, static_cast<vtkIdType>(casters.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        Footprint fp; // made from scratch, as the tiles make it again
        const vtkIdType id = casters[static_cast<size_t>(i)];
        double v[9];
        triangles.Get(id, v);
        const int made = MakeFootprint(view, size, v, id, fp, cull);
        status[static_cast<size_t>(i)] = static_cast<unsigned char>(made);
        if (made == 1)
        {
          TileRange& r = ranges[static_cast<size_t>(i)];
          r.X0 = static_cast<std::uint16_t>(fp.X0 / TileSize);
          r.X1 = static_cast<std::uint16_t>(fp.X1 / TileSize);
          r.Y0 = static_cast<std::uint16_t>(fp.Y0 / TileSize);
          r.Y1 = static_cast<std::uint16_t>(fp.Y1 / TileSize);
        }
      }
    });
  bins.Start.assign(static_cast<size_t>(tiles) * tiles + 1, 0);
  auto forTiles = [&](const TileRange& r, auto&& f)
  {
    for (int ty = r.Y0; ty <= r.Y1; ++ty)
    {
      for (int tx = r.X0; tx <= r.X1; ++tx)
      {
        const size_t tile = static_cast<size_t>(ty) * tiles + tx;
        if (tileActive[tile])
        {
          f(tile);
        }
      }
    }
  };
  for (size_t i = 0; i < casters.size(); ++i)
  {
    if (status[i] == 2)
    {
      nearTriangles.push_back(casters[i]);
      continue;
    }
    if (status[i] != 1)
    {
      continue;
    }
    ++stats.Triangles;
    forTiles(ranges[i], [&](size_t tile) { ++bins.Start[tile + 1]; });
  }
  for (size_t t = 1; t < bins.Start.size(); ++t)
  {
    bins.Start[t] += bins.Start[t - 1];
  }
  std::vector<vtkIdType> fill(bins.Start.begin(), bins.Start.end() - 1);
  bins.Binned.resize(static_cast<size_t>(bins.Start.back()));
  for (size_t i = 0; i < casters.size(); ++i)
  {
    if (status[i] == 1)
    {
      forTiles(ranges[i],
        [&](size_t tile)
        { bins.Binned[static_cast<size_t>(fill[tile]++)] = static_cast<std::uint32_t>(i); });
    }
  }
  return bins;
}

// A tile's active texels, row by row: row y's x are columns[rowStart[y - ty0] ..
// rowStart[y - ty0 + 1]), ascending (empty rows of eight skipped eight bytes at a time).
void ActiveColumns(const unsigned char* active, int size, int tx0, int ty0, int tx1, int ty1,
  std::vector<int>& columns, int* rowStart)
{
  columns.clear();
  for (int y = ty0; y <= ty1; ++y)
  {
    rowStart[y - ty0] = static_cast<int>(columns.size());
    const unsigned char* row = active + static_cast<size_t>(y) * size;
    for (int x = tx0; x <= tx1;)
    {
      if (x + 8 <= tx1 + 1 && !AnySet(row + x, 8))
      {
        x += 8;
        continue;
      }
      if (row[x])
      {
        columns.push_back(x);
      }
      ++x;
    }
  }
  rowStart[ty1 - ty0 + 1] = static_cast<int>(columns.size());
}

// The conservative rasterization both users share: footprints, tile bins and the texel loop.
// `visit(texel, triangle, depth)` is called for every overlapping texel/triangle pair, tile by
// tile in parallel (a texel's pairs in caster order, from one thread); it returns the work it
// did (summed into VisitWork). Texels with active[texel] == 0 are skipped (null: all active).
// With `active`, each tile first lists its active texels per row, and a footprint's row visits
// the shorter of its texel span and that row's list: the work follows the texels that hold
// something (sparse lists), not the footprints' area.
template <class Visit>
CpuMapStats Rasterize(const penumbra_light_views::View& view, int size,
  const penumbra::SceneTriangles& triangles, const penumbra_casters::CasterIds& casters,
  const unsigned char* active, std::vector<vtkIdType>& nearTriangles, Visit&& visit)
{
  CpuMapStats stats;
  const int tiles = (size + TileSize - 1) / TileSize;
  // Tiles without an active texel get no triangles binned.
  const std::vector<unsigned char> tileActive = ActiveTiles(active, size, tiles);
  const TileCull cull = active ? MakeTileCull(tileActive, tiles) : TileCull();
  const Bins bins = BinFootprints(
    view, size, triangles, casters, tileActive, active ? &cull : nullptr, nearTriangles, stats);
  const std::vector<vtkIdType>& start = bins.Start;
  std::atomic<vtkIdType> tests(0), writes(0), work(0);
  vtkSMPTools::For(0, static_cast<vtkIdType>(tiles) * tiles,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType localTests = 0, localWrites = 0, localWork = 0;
      std::vector<int> columns;           // the tile's active texels' x, row by row
      int rowStart[TileSize + 1] = { 0 }; // per tile row: its first entry in `columns`
      auto texelPair = [&](const Footprint& fp, int x, int y)
      {
        const size_t texel = static_cast<size_t>(y) * size + x;
        if (active && !active[texel])
        {
          return;
        }
        const double x0 = x - Grow, x1 = x + 1 + Grow;
        const double y0 = y - Grow, y1 = y + 1 + Grow;
        ++localTests;
        if (!Overlaps(fp, x0, x1, y0, y1))
        {
          return;
        }
        ++localWrites;
        localWork += visit(texel, fp.Id, ConservativeDepth(fp, view.Perspective, x0, x1, y0, y1));
      };
      for (vtkIdType tile = begin; tile < end; ++tile)
      {
        const int tx0 = static_cast<int>(tile % tiles) * TileSize;
        const int ty0 = static_cast<int>(tile / tiles) * TileSize;
        const int tx1 = std::min(size - 1, tx0 + TileSize - 1);
        const int ty1 = std::min(size - 1, ty0 + TileSize - 1);
        if (start[static_cast<size_t>(tile)] == start[static_cast<size_t>(tile) + 1])
        {
          continue;
        }
        if (active)
        {
          ActiveColumns(active, size, tx0, ty0, tx1, ty1, columns, rowStart);
        }
        for (vtkIdType b = start[static_cast<size_t>(tile)];
             b < start[static_cast<size_t>(tile) + 1]; ++b)
        {
          const vtkIdType id = casters[bins.Binned[static_cast<size_t>(b)]];
          double v[9];
          triangles.Get(id, v);
          Footprint fp;
          MakeFootprint(view, size, v, id, fp, active ? &cull : nullptr);
          const int xa = std::max(tx0, fp.X0), xb = std::min(tx1, fp.X1);
          for (int y = std::max(ty0, fp.Y0); y <= std::min(ty1, fp.Y1); ++y)
          {
            if (active && rowStart[y - ty0 + 1] - rowStart[y - ty0] < xb - xa + 1)
            {
              // Ascending x, as the span below.
              for (int k = rowStart[y - ty0]; k < rowStart[y - ty0 + 1]; ++k)
              {
                const int x = columns[static_cast<size_t>(k)];
                if (x >= xa && x <= xb)
                {
                  texelPair(fp, x, y);
                }
              }
              continue;
            }
            for (int x = xa; x <= xb; ++x)
            {
              texelPair(fp, x, y);
            }
          }
        }
      }
      tests += localTests;
      writes += localWrites;
      work += localWork;
    });
  stats.TexelTests = tests.load();
  stats.TexelWrites = writes.load();
  stats.VisitWork = work.load();
  return stats;
}
}

//------------------------------------------------------------------------------
CpuMapStats BuildConservativeMap(const penumbra_light_views::View& view, int size, int layers,
  const penumbra::SceneTriangles& triangles, const penumbra_casters::CasterIds& casters,
  std::vector<float>* depth, std::vector<std::uint32_t>* ids, std::vector<vtkIdType>& nearTriangles)
{
  const size_t texels = static_cast<size_t>(size) * size;
  for (int k = 0; k < layers; ++k)
  {
    depth[k].assign(texels, std::numeric_limits<float>::infinity());
    ids[k].assign(texels, 0u);
  }
  // Each texel keeps its `layers` smallest conservative depths, sorted; equal depths keep
  // caster order.
  return Rasterize(view, size, triangles, casters, nullptr, nearTriangles,
    [&](size_t texel, vtkIdType triangle, float d) -> vtkIdType
    {
      const std::uint32_t id = static_cast<std::uint32_t>(triangle) + 1u;
      for (int k = 0; k < layers; ++k)
      {
        if (d < depth[k][texel])
        {
          for (int j = layers - 1; j > k; --j)
          {
            depth[j][texel] = depth[j - 1][texel];
            ids[j][texel] = ids[j - 1][texel];
          }
          depth[k][texel] = d;
          ids[k][texel] = id;
          break;
        }
      }
      return 0;
    });
}

//------------------------------------------------------------------------------
CpuMapStats RasterizeConservative(const penumbra_light_views::View& view, int size,
  const penumbra::SceneTriangles& triangles, const penumbra_casters::CasterIds& casters,
  const unsigned char* active, std::vector<vtkIdType>& nearTriangles, const TexelVisitor& visit)
{
  return Rasterize(view, size, triangles, casters, active, nearTriangles, visit);
}
}
