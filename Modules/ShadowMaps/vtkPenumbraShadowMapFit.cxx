// Fitting a shadow-mapped light's views to its receivers (Brabec 2003, ch. 4.2): the
// receiver extent from samples, tile boxes or the scene, the enclosing rectangle, and RESM's
// choice of the maps' size.
#include "vtkPenumbraShadowMapShadowsInternals.h"

#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraShadowMapEstimateFS.h"
#include "vtkPenumbraShadowMapExtentFS.h"
#include "vtkPenumbraShadowMapTilesFS.h"

namespace penumbra_shadow_maps
{
// Light-space axes: a directional light travels along axes[2], a spot light looks along it;
// axes[0] and axes[1] span the map.
void LightAxes(const LightSetup& setup, double axes[3][3])
{
  const double travel[3] = { -setup.Direction[0], -setup.Direction[1], -setup.Direction[2] };
  const double* forward = setup.Type == LightSetup::Kind::Directional ? travel : setup.Axis;
  penumbra_light_views::Basis(forward, axes[0], axes[1]);
  std::copy(forward, forward + 3, axes[2]);
}

// The slot of a receiver point (rebased): the cube face of its dominant axis from the light,
// or its paraboloid hemisphere.
int SlotOf(const LightSetup& setup, int slotMode, const double p[3])
{
  if (slotMode == SlotsOne)
  {
    return 0;
  }
  const double v[3] = { p[0] - setup.Position[0], p[1] - setup.Position[1],
    p[2] - setup.Position[2] };
  if (slotMode == SlotsParaboloid)
  {
    return v[2] >= 0.0 ? 0 : 1;
  }
  int best = 0;
  for (int c = 1; c < 3; ++c)
  {
    best = std::fabs(v[c]) > std::fabs(v[best]) ? c : best;
  }
  return 2 * best + (v[best] < 0.0);
}

void AddReceiver(const LightSetup& setup, const double axes[3][3], int slotMode, const double p[3],
  ReceiverExtent& e)
{
  ++e.Pending;
  e.Used[static_cast<size_t>(SlotOf(setup, slotMode, p))] = 1;
  for (int c = 0; c < 3; ++c)
  {
    e.Box[2 * c] = std::min(e.Box[2 * c], p[c]);
    e.Box[2 * c + 1] = std::max(e.Box[2 * c + 1], p[c]);
  }
  if (setup.Type == LightSetup::Kind::Directional)
  {
    for (int a = 0; a < 3; ++a)
    {
      const double d = vtkMath::Dot(p, axes[a]);
      e.Lo[a] = std::min(e.Lo[a], d);
      e.Hi[a] = std::max(e.Hi[a], d);
    }
    return;
  }
  const double q[3] = { p[0] - setup.Position[0], p[1] - setup.Position[1],
    p[2] - setup.Position[2] };
  e.Farthest = std::max(e.Farthest, Norm3(q));
  const double w = vtkMath::Dot(q, axes[2]);
  if (setup.Type == LightSetup::Kind::Spot && w > 0.0)
  {
    e.SpotTan = std::max(e.SpotTan,
      std::max(std::fabs(vtkMath::Dot(q, axes[0])), std::fabs(vtkMath::Dot(q, axes[1]))) / w);
  }
}

// A CPU sample's position in the geometry's rebased frame, in double.
void SamplePoint(const penumbra_light_views::FrameInputs& in, vtkIdType s, double p[3])
{
  for (int c = 0; c < 3; ++c)
  {
    p[c] = static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c];
  }
}
}

namespace
{
// Merges the per-tile extents of the point-light reduction (vtkPenumbraShadowMapExtentFS).
void MergeExtent(const TileOutputs& data, int tiles, ReceiverExtent& e)
{
  const float* t0 = data[0].data();
  const float* t1 = data[1].data();
  const float* t2 = data[2].data();
  const float* t3 = data[3].data();
  for (int i = 0; i < tiles; ++i)
  {
    const float pending = t3[4 * i + 3];
    if (!(pending > 0.0f))
    {
      continue;
    }
    e.Pending += static_cast<vtkIdType>(pending);
    const int used = static_cast<int>(t2[4 * i + 3]);
    for (size_t slot = 0; slot < e.Used.size(); ++slot)
    {
      e.Used[slot] = static_cast<char>(e.Used[slot] || (used >> slot) & 1);
    }
    for (int c = 0; c < 3; ++c)
    {
      e.Box[2 * c] = std::min(e.Box[2 * c], static_cast<double>(t0[4 * i + c]));
      e.Box[2 * c + 1] = std::max(e.Box[2 * c + 1], static_cast<double>(t1[4 * i + c]));
    }
    e.Farthest = std::max(e.Farthest, static_cast<double>(t0[4 * i + 3]));
  }
}

// The light-plane images of a box's corners (centre +- half along the world axes): their
// hull is the box's shadow on the plane, so the hull of all of them holds every receiver.
// A flat box (a tile of an axis-aligned floor or wall) has 4 distinct corners, not 8.
void AddPlaneCorners(const double axes[3][3], const double centre[3], const double half[3],
  std::vector<std::array<double, 2>>& plane)
{
  const double mid[2] = { vtkMath::Dot(centre, axes[0]), vtkMath::Dot(centre, axes[1]) };
  int used = 0;
  for (int c = 0; c < 3; ++c)
  {
    used |= half[c] > 0.0 ? 1 << c : 0;
  }
  for (int corner = 0; corner < 8; ++corner)
  {
    if (corner & ~used)
    {
      continue; // the same point as the corner without this bit
    }
    std::array<double, 2> q = { mid[0], mid[1] };
    for (int c = 0; c < 3; ++c)
    {
      const double h = (corner >> c) & 1 ? half[c] : -half[c];
      q[0] += h * axes[0][c];
      q[1] += h * axes[1][c];
    }
    plane.push_back(q);
  }
}

using PlanePoint = std::array<double, 2>;

double Cross2(const PlanePoint& o, const PlanePoint& a, const PlanePoint& b)
{
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Akl-Toussaint: the points extreme in eight directions, in counter-clockwise order, span a
// polygon inside the hull; points strictly inside it are no hull vertices. On a view's tile
// boxes this leaves few of the corners for the sort of the monotone chain. The diagonals are
// those of the points' bounding box (`size`), so a long thin set keeps few points too.
std::vector<PlanePoint> ExtremePointFilter(
  const std::vector<PlanePoint>& points, const double size[2])
{
  const double sx = size[0] > 0.0 ? 1.0 / size[0] : 1.0;
  const double sy = size[1] > 0.0 ? 1.0 / size[1] : 1.0;
  size_t extreme[8] = { 0, 0, 0, 0, 0, 0, 0, 0 };
  double best[8];
  std::fill(best, best + 8, -std::numeric_limits<double>::max());
  for (size_t i = 0; i < points.size(); ++i)
  {
    const double x = points[i][0], y = points[i][1];
    const double u = sx * x, v = sy * y;
    const double d[8] = { x, u + v, y, v - u, -x, -u - v, -y, u - v };
    for (int k = 0; k < 8; ++k)
    {
      if (d[k] > best[k])
      {
        best[k] = d[k];
        extreme[k] = i;
      }
    }
  }
  std::vector<PlanePoint> polygon;
  for (size_t index : extreme)
  {
    if (!points.empty() && (polygon.empty() || points[index] != polygon.back()))
    {
      polygon.push_back(points[index]);
    }
  }
  while (polygon.size() > 1 && polygon.front() == polygon.back())
  {
    polygon.pop_back();
  }
  if (polygon.size() < 3)
  {
    return points;
  }
  // Inside every edge: n . p > c with n the edge's left normal.
  std::vector<std::array<double, 3>> edges;
  for (size_t i = 0; i < polygon.size(); ++i)
  {
    const PlanePoint& a = polygon[i];
    const PlanePoint& b = polygon[(i + 1) % polygon.size()];
    const double nx = a[1] - b[1], ny = b[0] - a[0];
    edges.push_back({ nx, ny, nx * a[0] + ny * a[1] });
  }
  std::vector<PlanePoint> kept;
  for (const PlanePoint& p : points)
  {
    bool inside = true;
    for (const std::array<double, 3>& edge : edges)
    {
      inside &= edge[0] * p[0] + edge[1] * p[1] > edge[2];
    }
    if (!inside)
    {
      kept.push_back(p);
    }
  }
  return kept;
}

// Andrew's monotone chain (Brabec 2003, ch. 4.2.2): the convex hull, counter-clockwise,
// without collinear points.
std::vector<PlanePoint> ConvexHull(std::vector<PlanePoint> p)
{
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3)
  {
    return p;
  }
  std::vector<PlanePoint> hull(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i)
  {
    while (k >= 2 && Cross2(hull[k - 2], hull[k - 1], p[i]) <= 0.0)
    {
      --k;
    }
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i > 0; --i)
  {
    while (k >= lower && Cross2(hull[k - 2], hull[k - 1], p[i - 1]) <= 0.0)
    {
      --k;
    }
    hull[k++] = p[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

// The extent of the hull along the unit direction u and its normal: { lo_u, hi_u, lo_n, hi_n }.
std::array<double, 4> HullSpan(const std::vector<PlanePoint>& hull, const double u[2])
{
  std::array<double, 4> s = { std::numeric_limits<double>::max(),
    -std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
    -std::numeric_limits<double>::max() };
  for (const PlanePoint& p : hull)
  {
    const double a = u[0] * p[0] + u[1] * p[1], b = -u[1] * p[0] + u[0] * p[1];
    s[0] = std::min(s[0], a);
    s[1] = std::max(s[1], a);
    s[2] = std::min(s[2], b);
    s[3] = std::max(s[3], b);
  }
  return s;
}

// Rotates axes[0] and axes[1] in their plane to the best enclosing rectangle of the points
// and sets lo/hi along them. `square` false: the minimum area (Brabec 2003, ch. 4.2.2: "the
// minimum area rectangle enclosing a convex polygon P has a side collinear with an edge of
// P", so the hull's edge directions are the candidates). `square` true: the shortest longer
// side, which is what a square map's texels follow (its optimum may lie between edge
// directions, where the two sides are equal: the candidates add every degree, so it is
// within a degree's rotation of the optimum). The basis itself is a candidate too, so the
// fit never does worse than the axis-aligned one. Each candidate costs a pass over the hull;
// beyond 256 edges only every n-th edge is tried (any orientation is a valid fit, only a
// less tight one). Fewer than 3 hull points (a degenerate receiver set): axes unchanged.
void FitPlaneRectangle(
  const std::vector<PlanePoint>& points, bool square, double axes[3][3], double lo[3], double hi[3])
{
  const double size[2] = { hi[0] - lo[0], hi[1] - lo[1] };
  const std::vector<PlanePoint> hull = ConvexHull(ExtremePointFilter(points, size));
  if (hull.size() < 3)
  {
    return;
  }
  auto cost = [square](const std::array<double, 4>& s)
  {
    const double w = s[1] - s[0], h = s[3] - s[2];
    return square ? std::max(w, h) : w * h;
  };
  double best[2] = { 1.0, 0.0 };
  std::array<double, 4> span = HullSpan(hull, best);
  double bestCost = cost(span);
  auto consider = [&](const double direction[2])
  {
    // Of the four directions that give this rectangle, the one nearest the basis (no
    // needless quarter turn of the map); a candidate must win by more than rounding, so
    // ties keep the basis (and a moving light's map turns less often).
    const double turns[4][2] = { { direction[0], direction[1] }, { -direction[1], direction[0] },
      { -direction[0], -direction[1] }, { direction[1], -direction[0] } };
    const double* u = *std::max_element(std::begin(turns), std::end(turns),
      [](const double* a, const double* b) { return a[0] < b[0]; });
    const std::array<double, 4> s = HullSpan(hull, u);
    if (cost(s) < bestCost * (1.0 - 1e-9))
    {
      bestCost = cost(s);
      span = s;
      std::copy(u, u + 2, best);
    }
  };
  const size_t n = hull.size(), step = std::max<size_t>(1, n / 256);
  for (size_t i = 0; i < n; i += step)
  {
    const PlanePoint& a = hull[i];
    const PlanePoint& b = hull[(i + 1) % n];
    const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    const double u[2] = { (b[0] - a[0]) / len, (b[1] - a[1]) / len };
    consider(u);
  }
  for (int degree = 1; square && degree < 90; ++degree)
  {
    const double angle = vtkMath::RadiansFromDegrees(static_cast<double>(degree));
    const double u[2] = { std::cos(angle), std::sin(angle) };
    consider(u);
  }
  double rotated[2][3];
  for (int c = 0; c < 3; ++c)
  {
    rotated[0][c] = best[0] * axes[0][c] + best[1] * axes[1][c];
    rotated[1][c] = -best[1] * axes[0][c] + best[0] * axes[1][c];
  }
  for (int a = 0; a < 2; ++a)
  {
    std::copy(rotated[a], rotated[a] + 3, axes[a]);
    lo[a] = span[2 * a];
    hi[a] = span[2 * a + 1];
  }
}
}

namespace penumbra_shadow_maps
{
// Fits to the per-view tile boxes (vtkPenumbraShadowMapTilesFS) that may hold a receiver of a
// directional or spot light: every tile with a surface, less, for a directional light, those
// whose normals all face away from it (interval bounds with a margin above float rounding).
// A tile counts with its whole position box, a superset of its samples, so the fit covers
// every receiver. Tiles of 4 x 4 samples: 8 x 8 ones widened the fit enough to raise the
// city's mismatch at 2048^2 from 2.4e-4 to 3.3e-4 (boxes spanning depth discontinuities).
void ExtentFromTiles(const LightSetup& setup, const TileOutputs& data, int tiles, ReceiverExtent& e)
{
  double axes[3][3];
  LightAxes(setup, axes);
  const float* lo = data[0].data();
  const float* hi = data[1].data();
  const float* nlo = data[2].data();
  const float* nhi = data[3].data();
  const vtkIdType before = e.Pending;
  vtkIdType pending = 0;
  bool behind = false;
  for (int i = 0; i < tiles; ++i)
  {
    const float count = lo[4 * i + 3];
    if (!(count > 0.0f))
    {
      continue;
    }
    if (setup.Type == LightSetup::Kind::Directional)
    {
      double facing = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        facing +=
          std::max(nlo[4 * i + c] * setup.Direction[c], nhi[4 * i + c] * setup.Direction[c]);
      }
      if (facing < -1e-5)
      {
        continue; // every normal of the tile faces away from the light
      }
    }
    pending += static_cast<vtkIdType>(count);
    if (setup.Type == LightSetup::Kind::Directional)
    {
      // Linear in the box: its centre's projection +- the half extents' projections.
      e.Used[0] = 1;
      double centre[3], half[3];
      for (int c = 0; c < 3; ++c)
      {
        centre[c] = 0.5 * (static_cast<double>(lo[4 * i + c]) + hi[4 * i + c]);
        half[c] = 0.5 * (static_cast<double>(hi[4 * i + c]) - lo[4 * i + c]);
        e.Box[2 * c] = std::min(e.Box[2 * c], static_cast<double>(lo[4 * i + c]));
        e.Box[2 * c + 1] = std::max(e.Box[2 * c + 1], static_cast<double>(hi[4 * i + c]));
      }
      for (int a = 0; a < 3; ++a)
      {
        const double mid = vtkMath::Dot(centre, axes[a]);
        const double reach = std::fabs(half[0] * axes[a][0]) + std::fabs(half[1] * axes[a][1]) +
          std::fabs(half[2] * axes[a][2]);
        e.Lo[a] = std::min(e.Lo[a], mid - reach);
        e.Hi[a] = std::max(e.Hi[a], mid + reach);
      }
      if (e.CollectPlane)
      {
        AddPlaneCorners(axes, centre, half, e.Plane);
      }
      continue;
    }
    // A spot's tangent is linear-fractional in the box: its maximum is at a corner.
    for (int corner = 0; corner < 8; ++corner)
    {
      const double p[3] = { (corner & 1) ? hi[4 * i] : lo[4 * i],
        (corner & 2) ? hi[4 * i + 1] : lo[4 * i + 1],
        (corner & 4) ? hi[4 * i + 2] : lo[4 * i + 2] };
      AddReceiver(setup, axes, SlotsOne, p, e);
      const double q[3] = { p[0] - setup.Position[0], p[1] - setup.Position[1],
        p[2] - setup.Position[2] };
      behind = behind || !(vtkMath::Dot(q, axes[2]) > 0.0);
    }
  }
  e.Pending = before + pending;
  if (behind)
  {
    // A box reaching behind the spot's apex may hold receivers at any angle: the fit takes
    // the whole cone.
    e.SpotTan = std::numeric_limits<double>::max();
  }
}
}

namespace
{
// Whether a vertex inside `box` could change what AddReceiver() has gathered in `e` (the
// light-space bounds, the farthest distance, a spot's widest tangent and whether a vertex
// lies behind its apex, the slots used). Each bound is the exact extreme over the box, grown
// by far more than the rounding of the per-vertex expressions, so a chunk it skips holds no
// vertex that would change the result.
bool MayMoveExtent(const LightSetup& setup, int slotMode, const double axes[3][3],
  const std::array<double, 6>& box, const ReceiverExtent& e, bool behind)
{
  constexpr double fuzz = 1e-12;
  if (setup.Type == LightSetup::Kind::Directional)
  {
    for (int a = 0; a < 3; ++a)
    {
      double mid = 0.0, reach = 0.0, size = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        const double centre = 0.5 * (box[2 * c] + box[2 * c + 1]);
        const double half = 0.5 * (box[2 * c + 1] - box[2 * c]);
        mid += centre * axes[a][c];
        reach += half * std::fabs(axes[a][c]);
        size += (std::fabs(centre) + half) * std::fabs(axes[a][c]);
      }
      const double slack = fuzz * size + std::numeric_limits<double>::min();
      if (mid - reach - slack < e.Lo[a] || mid + reach + slack > e.Hi[a])
      {
        return true;
      }
    }
    return false;
  }
  const int slots = slotMode == SlotsCube ? 6 : (slotMode == SlotsParaboloid ? 2 : 1);
  if (std::count(e.Used.begin(), e.Used.begin() + slots, 1) < slots)
  {
    return true;
  }
  double farthest = 0.0, tangent = 0.0, lowestW = std::numeric_limits<double>::max();
  for (int corner = 0; corner < 8; ++corner)
  {
    const double q[3] = { ((corner & 1) ? box[1] : box[0]) - setup.Position[0],
      ((corner & 2) ? box[3] : box[2]) - setup.Position[1],
      ((corner & 4) ? box[5] : box[4]) - setup.Position[2] };
    farthest = std::max(farthest, Norm3(q));
    const double w = vtkMath::Dot(q, axes[2]);
    lowestW = std::min(lowestW, w);
    // |q . axes[0]| / w is linear-fractional where w > 0: its maximum over the box is at a
    // corner.
    tangent = std::max(tangent,
      std::max(std::fabs(vtkMath::Dot(q, axes[0])), std::fabs(vtkMath::Dot(q, axes[1]))) / w);
  }
  if (farthest * (1.0 + fuzz) >= e.Farthest)
  {
    return true;
  }
  if (setup.Type != LightSetup::Kind::Spot || behind)
  {
    return false; // behind the apex, the fit takes the whole cone whatever the tangents
  }
  return !(lowestW > fuzz * farthest) || tangent * (1.0 + fuzz) >= e.SpotTan;
}
}

namespace penumbra_shadow_maps
{
// The scene fit (SetFitTo(FIT_TO_SCENE)): every vertex of the scene's triangles is a
// receiver point. A spot light with a vertex behind its apex gets the whole cone (that
// triangle may reach into it), as a tile box behind it does in ExtentFromTiles(). Only the
// chunks that may move the extent are read (MayMoveExtent), after the ones whose boxes reach
// farthest, which usually hold the extremes; the result is the same as reading every vertex.
// The minimum-area rectangle needs every vertex of the plane's hull, so it reads them all.
void ExtentFromScene(const LightSetup& setup, int slotMode, vtkPenumbraSceneGeometry* geometry,
  SceneChunks& chunks, ReceiverExtent& e)
{
  const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
  const vtkIdType count = 3 * triangles.Size();
  if (count == 0)
  {
    return;
  }
  double axes[3][3];
  LightAxes(setup, axes);
  chunks.Update(geometry);
  const bool plane = e.CollectPlane && setup.Type == LightSetup::Kind::Directional;
  const vtkIdType pending = e.Pending;
  bool behind = false;
  std::vector<char> read(chunks.Boxes.size(), 0);
  auto readChunk = [&](size_t c)
  {
    read[c] = 1;
    const vtkIdType first = static_cast<vtkIdType>(c) * SceneChunks::Size;
    for (vtkIdType v = first; v < std::min(count, first + SceneChunks::Size); ++v)
    {
      double p[3];
      triangles.GetCorner(v / 3, static_cast<int>(v % 3), p);
      AddReceiver(setup, axes, slotMode, p, e);
      if (plane)
      {
        e.Plane.push_back({ vtkMath::Dot(p, axes[0]), vtkMath::Dot(p, axes[1]) });
      }
      if (setup.Type == LightSetup::Kind::Spot)
      {
        const double q[3] = { p[0] - setup.Position[0], p[1] - setup.Position[1],
          p[2] - setup.Position[2] };
        behind = behind || !(vtkMath::Dot(q, axes[2]) > 0.0);
      }
    }
  };
  // Seeds: per light axis, the chunks whose boxes reach lowest and highest along it.
  for (int a = 0; a < 3 && !plane; ++a)
  {
    auto along = [&](size_t c, int side)
    {
      const std::array<double, 6>& b = chunks.Boxes[c];
      double d = 0.0;
      for (int k = 0; k < 3; ++k)
      {
        d += (axes[a][k] * side > 0.0 ? b[2 * k + 1] : b[2 * k]) * axes[a][k];
      }
      return d * side;
    };
    for (int side = -1; side <= 1; side += 2)
    {
      size_t best = 0;
      for (size_t c = 1; c < chunks.Boxes.size(); ++c)
      {
        best = along(c, side) > along(best, side) ? c : best;
      }
      if (!read[best])
      {
        readChunk(best);
      }
    }
  }
  for (size_t c = 0; c < chunks.Boxes.size(); ++c)
  {
    if (!read[c] && (plane || MayMoveExtent(setup, slotMode, axes, chunks.Boxes[c], e, behind)))
    {
      readChunk(c);
    }
  }
  // What every vertex counts for, from the chunks' boxes: the same as reading them all.
  e.Pending = pending + count;
  for (const std::array<double, 6>& box : chunks.Boxes)
  {
    for (int k = 0; k < 6; k += 2)
    {
      e.Box[k] = std::min(e.Box[k], box[k]);
      e.Box[k + 1] = std::max(e.Box[k + 1], box[k + 1]);
    }
  }
  if (behind)
  {
    e.SpotTan = std::numeric_limits<double>::max();
  }
}

int TileCount(int width, int height)
{
  return ((width + Tile - 1) / Tile) * ((height + Tile - 1) / Tile);
}

// The tile boxes of vtkPenumbraShadowMapTilesFS, from a CPU sample set laid out as a
// width x height image (row 0 at the bottom), with the same rules: every sample with a
// surface (and shadow work) counts, whatever it faces.
TileOutputs TilesFromSamples(const penumbra_light_views::FrameInputs& in, int width, int height)
{
  const int tw = (width + Tile - 1) / Tile;
  const int tiles = TileCount(width, height);
  TileOutputs out;
  const float big = std::numeric_limits<float>::max();
  out[0].assign(static_cast<size_t>(4 * tiles), big);
  out[1].assign(static_cast<size_t>(4 * tiles), -big);
  out[2].assign(static_cast<size_t>(4 * tiles), big);
  out[3].assign(static_cast<size_t>(4 * tiles), -big);
  for (int t = 0; t < tiles; ++t)
  {
    out[0][static_cast<size_t>(4 * t + 3)] = 0.0f;
  }
  for (vtkIdType s = 0; s < in.NumberOfSamples; ++s)
  {
    double p[3];
    SamplePoint(in, s, p);
    const float* normal = in.Normals + 3 * s;
    const bool finite = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) &&
      std::isfinite(normal[0]) && std::isfinite(normal[1]) && std::isfinite(normal[2]);
    if (in.Props[s] < 0 || !finite)
    {
      continue;
    }
    const int x = static_cast<int>(s % width), y = static_cast<int>(s / width);
    const size_t t = static_cast<size_t>(4 * ((y / Tile) * tw + x / Tile));
    out[0][t + 3] += 1.0f;
    for (int c = 0; c < 3; ++c)
    {
      out[0][t + c] = std::min(out[0][t + c], static_cast<float>(p[c]));
      out[1][t + c] = std::max(out[1][t + c], static_cast<float>(p[c]));
      out[2][t + c] = std::min(out[2][t + c], normal[c]);
      out[3][t + c] = std::max(out[3][t + c], normal[c]);
    }
  }
  return out;
}

// RESM's need of one CPU sample set (Ferko 2013; the CPU twin of
// vtkPenumbraShadowMapEstimateFS.glsl, whose comment has the rule): per 4 x 4-sample tile,
// the largest number of texels across the map a pending sample on every `step`-th row and
// column needs along s and t, and the number of samples estimated; 4 floats a tile like the
// GPU pass's first output.
std::vector<float> EstimateSamples(const penumbra_light_views::FrameInputs& in, int width,
  int height, const unsigned char* state, const View& view, int step)
{
  const int tw = (width + Tile - 1) / Tile;
  std::vector<float> needs(static_cast<size_t>(4 * TileCount(width, height)), 0.0f);
  // Map coordinates of sample s, false when it cannot serve as a neighbour.
  auto mapAt = [&](vtkIdType s, double p[3], double st[2])
  {
    SamplePoint(in, s, p);
    double depth;
    return in.Props[s] >= 0 && std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]) &&
      view.Project(p, st[0], st[1], depth);
  };
  for (vtkIdType s = 0; s < in.NumberOfSamples; ++s)
  {
    double p[3], st[2];
    const int x = static_cast<int>(s % width), y = static_cast<int>(s / width);
    if ((x % Tile) % step != 0 || (y % Tile) % step != 0 || state[s] != Pending || !mapAt(s, p, st))
    {
      continue;
    }
    const double n[3] = { in.Normals[3 * s], in.Normals[3 * s + 1], in.Normals[3 * s + 2] };
    double step[2][2];
    bool found[2] = { false, false };
    for (int axis = 0; axis < 2; ++axis)
    {
      for (int side = 1; side >= -1 && !found[axis]; side -= 2)
      {
        const int qx = x + (axis == 0 ? side : 0), qy = y + (axis == 1 ? side : 0);
        if (qx < 0 || qy < 0 || qx >= width || qy >= height)
        {
          continue;
        }
        const vtkIdType q = static_cast<vtkIdType>(qy) * width + qx;
        double pq[3], sq[2];
        if (in.Props[q] != in.Props[s] || !mapAt(q, pq, sq))
        {
          continue;
        }
        const double d[3] = { pq[0] - p[0], pq[1] - p[1], pq[2] - p[2] };
        const double length = Norm3(d);
        if (length > 0.0 && std::abs(vtkMath::Dot(n, d)) <= 1e-3 * Norm3(n) * length)
        {
          step[axis][0] = side * (sq[0] - st[0]);
          step[axis][1] = side * (sq[1] - st[1]);
          found[axis] = true;
        }
      }
    }
    // Columns a = d(s,t)/dx, b = d(s,t)/dy.
    const double det = std::abs(step[0][0] * step[1][1] - step[1][0] * step[0][1]);
    if (!found[0] || !found[1] || !(det > 0.0))
    {
      continue;
    }
    float* tile = needs.data() + 4 * ((y / Tile) * tw + x / Tile);
    tile[0] = std::max(tile[0], static_cast<float>(2.0 * std::hypot(step[0][1], step[1][1]) / det));
    tile[1] = std::max(tile[1], static_cast<float>(2.0 * std::hypot(step[0][0], step[1][0]) / det));
    tile[2] += 1.0f;
  }
  return needs;
}
}

namespace
{
// The Coverage quantile of the tiles' needs per axis (tiles laid out as EstimateSamples()
// returns them); false when no sample was estimated.
bool NeedQuantile(const std::vector<float>& needs, double coverage, double need[2])
{
  std::vector<float> axis[2];
  for (size_t t = 0; t + 3 < needs.size(); t += 4)
  {
    if (needs[t + 2] > 0.0f && std::isfinite(needs[t]) && std::isfinite(needs[t + 1]))
    {
      axis[0].push_back(needs[t]);
      axis[1].push_back(needs[t + 1]);
    }
  }
  if (axis[0].empty())
  {
    return false;
  }
  const size_t k = std::min(axis[0].size() - 1,
    static_cast<size_t>(std::ceil(coverage * static_cast<double>(axis[0].size()))) - 1);
  for (int a = 0; a < 2; ++a)
  {
    std::nth_element(
      axis[a].begin(), axis[a].begin() + static_cast<std::ptrdiff_t>(k), axis[a].end());
    need[a] = axis[a][k];
  }
  return true;
}

// A map side for a need: rounded up to a multiple of 64 texels, clamped to [64, largest];
// the current side is kept while the need stays between 85 % of it and it (hysteresis: a
// view or light that moves a little does not make the map shimmer between sizes).
int QuantisedSide(double need, int largest, int current)
{
  constexpr int Quantum = 64;
  const double steps = std::ceil(std::min(need, static_cast<double>(largest)) / Quantum);
  const int side = std::max(Quantum, std::min(largest, Quantum * static_cast<int>(steps)));
  if (current > 0 && current <= largest && side < current && side >= 0.85 * current)
  {
    return current;
  }
  return side;
}
}

namespace penumbra_shadow_maps
{
// Whether the camera of `renderer` sees the whole box of the scene's triangles: its eight
// corners project inside the view volume (FIT_TO_AUTO).
// The extent of every process's receivers (Used, Box, Lo, Hi, Farthest, SpotTan, Pending:
// minima and maxima, one reduction; the plane corners: each process's hull, gathered), so
// that every process fits the same views. Collective.
void ShareExtent(vtkPenumbraRemoteShadows& processes, ReceiverExtent& e)
{
  std::vector<double> v;
  for (int a = 0; a < 3; ++a)
  {
    v.push_back(e.Box[2 * a]);
    v.push_back(-e.Box[2 * a + 1]);
    v.push_back(e.Lo[a]);
    v.push_back(-e.Hi[a]);
  }
  for (char used : e.Used)
  {
    v.push_back(used ? -1.0 : 0.0);
  }
  v.push_back(-e.Farthest);
  v.push_back(-e.SpotTan);
  v.push_back(-static_cast<double>(e.Pending));
  processes.ReduceMinimum(v.data(), static_cast<int>(v.size()));
  size_t i = 0;
  for (int a = 0; a < 3; ++a)
  {
    e.Box[2 * a] = v[i++];
    e.Box[2 * a + 1] = -v[i++];
    e.Lo[a] = v[i++];
    e.Hi[a] = -v[i++];
  }
  for (char& used : e.Used)
  {
    used = v[i++] < 0.0 ? 1 : 0;
  }
  e.Farthest = -v[i++];
  e.SpotTan = -v[i++];
  e.Pending = static_cast<vtkIdType>(-v[i++]);
  if (!e.CollectPlane)
  {
    return;
  }
  // The hull of the union is the hull of the processes' hulls.
  std::vector<double> corners;
  if (!e.Plane.empty())
  {
    double lo[2] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max() };
    double hi[2] = { -lo[0], -lo[1] };
    for (const PlanePoint& p : e.Plane)
    {
      for (int a = 0; a < 2; ++a)
      {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    }
    const double size[2] = { hi[0] - lo[0], hi[1] - lo[1] };
    for (const PlanePoint& p : ConvexHull(ExtremePointFilter(e.Plane, size)))
    {
      corners.push_back(p[0]);
      corners.push_back(p[1]);
    }
  }
  processes.GatherValues(corners);
  e.Plane.clear();
  for (size_t c = 0; c + 1 < corners.size(); c += 2)
  {
    e.Plane.push_back({ corners[c], corners[c + 1] });
  }
}

bool SceneInView(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry)
{
  double bounds[6];
  geometry->GetBounds(bounds);
  vtkCamera* camera = renderer ? renderer->GetActiveCamera() : nullptr;
  if (!camera || !vtkMath::AreBoundsInitialized(bounds))
  {
    return false;
  }
  vtkMatrix4x4* m =
    camera->GetCompositeProjectionTransformMatrix(renderer->GetTiledAspectRatio(), -1, 1);
  for (int c = 0; c < 8; ++c)
  {
    const double p[4] = { bounds[c & 1], bounds[2 + ((c >> 1) & 1)], bounds[4 + (c >> 2)], 1 };
    double q[4];
    m->MultiplyPoint(p, q);
    if (!(q[3] > 0) || std::abs(q[0]) > q[3] || std::abs(q[1]) > q[3] || std::abs(q[2]) > q[3])
    {
      return false;
    }
  }
  return true;
}
}
//------------------------------------------------------------------------------
// Fits the light views to the receivers (Brabec 2003, ch. 4.2: an axis-aligned rectangle in
// light space, computed exactly from the receivers instead of a control texture).
void vtkPenumbraShadowMapShadows::Internals::FitViews(
  const LightSetup& setup, const ReceiverExtent& e, int slotMode, int size, LightMaps* maps)
{
  if (setup.Type == LightSetup::Kind::Directional)
  {
    // Orthographic rows fitted to the receivers' light-space rectangle and depth span.
    // Casters in front of the near plane clamp to depth 0 (ch. 4.1.2): they still shadow.
    double axes[3][3], lo[3], hi[3];
    LightAxes(setup, axes);
    std::copy(e.Lo, e.Lo + 3, lo);
    std::copy(e.Hi, e.Hi + 3, hi);
    if (!e.Plane.empty())
    {
      FitPlaneRectangle(e.Plane, e.Square, axes, lo, hi); // ch. 4.2.2
    }
    View v;
    double extent = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      extent = std::max(extent, hi[a] - lo[a]);
    }
    const double pad = 1e-3 * extent + 1e-9 * (1.0 + Norm3(e.Box));
    for (int a = 0; a < 3; ++a)
    {
      const double l = lo[a] - pad, h = hi[a] + pad;
      const double scale = a < 2 ? 2.0 / (h - l) : 1.0 / (h - l);
      for (int c = 0; c < 3; ++c)
      {
        v.Row[a][c] = axes[a][c] * scale;
      }
      v.Row[a][3] = -l * scale + (a < 2 ? -1.0 : 0.0);
    }
    v.Row[3][3] = 1.0;
    maps->Views[0] = v;
  }
  else if (setup.Type == LightSetup::Kind::Spot)
  {
    // The field of view fitted to the receivers in the cone, never wider than the cone.
    const double coneTan = std::tan(vtkMath::RadiansFromDegrees(std::min(setup.Cone + 1.0, 89.9)));
    const double tanHalf = std::max(1e-6, std::min(coneTan, 1.01 * e.SpotTan + 1e-9));
    maps->Views[0] =
      penumbra_light_views::PerspectiveView(setup.Position, setup.Axis, tanHalf, e.Box);
  }
  else if (slotMode == SlotsCube)
  {
    for (int face = 0; face < 6; ++face)
    {
      double f[3] = { 0, 0, 0 };
      f[face / 2] = (face % 2) ? -1.0 : 1.0;
      maps->Views[static_cast<size_t>(face)] =
        penumbra_light_views::PerspectiveView(setup.Position, f, 1.0, e.Box);
    }
  }
  else
  {
    std::copy(setup.Position, setup.Position + 3, maps->Centre);
    maps->Far = e.Farthest > 0.0 ? 1.01 * e.Farthest : 1.0;
    // The rim (radius 1) sits one texel inside the map edge.
    maps->MapScale = 1.0 / (1.0 + 2.0 / size);
  }
}

//------------------------------------------------------------------------------
// Fits the light's views to its receivers and chooses the maps' size: Resolution, or for
// RESM the Coverage quantile of the receivers' estimated need (see SetResolutionMode()).
bool vtkPenumbraShadowMapShadows::Internals::PlanMaps(vtkPenumbraShadowMapShadows* self,
  const LightSetup& setup, const ReceiverExtent& extent, const Estimator& estimate, LightMaps* maps,
  int size[2], std::string& error)
{
  const int slotMode = this->SlotMode(self, setup);
  const int slots = slotMode == SlotsCube ? 6 : (slotMode == SlotsParaboloid ? 2 : 1);
  maps->Views.assign(static_cast<size_t>(slots), View());
  this->FitViews(setup, extent, slotMode, self->Resolution, maps);
  size[0] = size[1] = self->Resolution;
  self->LastEstimate[0] = self->LastEstimate[1] = maps->Need[0] = maps->Need[1] = 0.0;
  if (self->ResolutionMode != RESOLUTION_ESTIMATED || slotMode != SlotsOne || !extent.Used[0])
  {
    return true;
  }
  std::vector<float> needs;
  if (!estimate(maps->Views[0], needs, error))
  {
    return false;
  }
  double need[2];
  if (!NeedQuantile(needs, self->Coverage, need))
  {
    // No sample with a neighbour on its plane (a view of isolated pixels): the fixed size.
    size[0] = size[1] = std::min(self->Resolution, self->MaxResolution);
    return true;
  }
  const int current[2] = { maps->Valid ? maps->Width : 0, maps->Valid ? maps->Height : 0 };
  for (int a = 0; a < 2; ++a)
  {
    self->LastEstimate[a] = maps->Need[a] = need[a];
    size[a] = QuantisedSide(need[a], self->MaxResolution, current[a]);
  }
  return true;
}

//------------------------------------------------------------------------------
// RESM's estimate over the frame's G-buffer (vtkPenumbraShadowMapEstimateFS), for the view
// PlanMaps() fitted: the tiles' needs of every layer, read back as a few kilobytes.
bool vtkPenumbraShadowMapShadows::Internals::EstimateFrame(vtkPenumbraFrame* frame,
  const LightSetup& setup, const View& view, int step, std::vector<float>& needs,
  std::string& error)
{
  if (!this->EstimateQuad)
  {
    this->EstimateQuad.reset(new vtkOpenGLQuadHelper(
      frame->GetWindow(), nullptr, ComposeShader(vtkPenumbraShadowMapEstimateFS).c_str(), ""));
  }
  auto uniforms = [&](vtkShaderProgram* program)
  {
    program->SetUniformi("step", step);
    float matrix[16];
    view.ToFloatMatrix(matrix);
    program->SetUniformMatrix4x4("lightMatrix", matrix);
    program->SetUniformi("perspective", view.Perspective ? 1 : 0);
    program->SetUniformi("lightKind",
      setup.Type == LightSetup::Kind::Directional ? 0
                                                  : (setup.Type == LightSetup::Kind::Spot ? 2 : 1));
    float direction[3], position[3], axis[3];
    for (int c = 0; c < 3; ++c)
    {
      direction[c] = static_cast<float>(setup.Direction[c]);
      position[c] = static_cast<float>(setup.Position[c]);
      axis[c] = static_cast<float>(setup.Axis[c]);
    }
    program->SetUniform3f("estimateDirection", direction);
    program->SetUniform3f("estimatePosition", position);
    program->SetUniform3f("estimateAxis", axis);
    program->SetUniformf("estimateCosCone", static_cast<float>(setup.CosCone));
  };
  if (!this->TilePass(frame, *this->EstimateQuad, uniforms, this->EstimateData))
  {
    error = "the resolution-estimate program does not compile on this OpenGL implementation";
    return false;
  }
  needs.clear();
  for (const TileOutputs& layer : this->EstimateData)
  {
    needs.insert(needs.end(), layer[0].begin(), layer[0].end());
  }
  return true;
}

//------------------------------------------------------------------------------
// Runs a tile program (each fragment reduces Tile x Tile samples) over every layer's
// G-buffer and reads its four RGBA outputs back into data[layer][output].
bool vtkPenumbraShadowMapShadows::Internals::TilePass(vtkPenumbraFrame* frame,
  vtkOpenGLQuadHelper& quad, const std::function<void(vtkShaderProgram*)>& uniforms,
  std::vector<TileOutputs>& data)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  vtkShaderProgram* program = quad.Program;
  if (!program || !program->GetCompiled())
  {
    return false;
  }
  if (!this->ExtentFBO)
  {
    this->ExtentFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->ExtentFBO->SetContext(win);
  }
  const int w = frame->GetWidth(), h = frame->GetHeight();
  const int tw = (w + ExtentTile - 1) / ExtentTile, th = (h + ExtentTile - 1) / ExtentTile;
  std::vector<vtkTextureObject*> targets;
  for (auto& tex : this->ExtentTextures)
  {
    if (!tex)
    {
      tex = Internals::FloatTexture(win);
      tex->SetInternalFormat(GL_RGBA32F);
      tex->SetFormat(GL_RGBA);
      tex->SetDataType(GL_FLOAT);
    }
    if (static_cast<int>(tex->GetWidth()) != tw || static_cast<int>(tex->GetHeight()) != th)
    {
      tex->Allocate2D(tw, th, 4, VTK_FLOAT);
    }
    targets.push_back(tex);
  }
  data.resize(static_cast<size_t>(frame->GetNumberOfLayers()));
  for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
  {
    vtkPenumbraViewSamplesPass* gbuffer = frame->GetLayer(layer);
    penumbra_gl::QuadPassState pass(win->GetState(), this->ExtentFBO, targets, tw, th);
    win->GetShaderCache()->ReadyShaderProgram(program);
    gbuffer->GetPositionTexture()->Activate();
    gbuffer->GetNormalTexture()->Activate();
    program->SetUniformi("samplePositions", gbuffer->GetPositionTexture()->GetTextureUnit());
    program->SetUniformi("sampleNormals", gbuffer->GetNormalTexture()->GetTextureUnit());
    const int sampleSize[2] = { w, h };
    program->SetUniform2i("sampleSize", sampleSize);
    program->SetUniformi("tile", ExtentTile);
    uniforms(program);
    quad.Render();
    gbuffer->GetPositionTexture()->Deactivate();
    gbuffer->GetNormalTexture()->Deactivate();
    for (int a = 0; a < 4; ++a)
    {
      std::vector<float>& out = data[static_cast<size_t>(layer)][static_cast<size_t>(a)];
      out.resize(static_cast<size_t>(4) * tw * th);
      this->ExtentFBO->ActivateReadBuffer(static_cast<unsigned int>(a));
      glPixelStorei(GL_PACK_ALIGNMENT, 4);
      glReadPixels(0, 0, tw, th, GL_RGBA, GL_FLOAT, out.data());
    }
  }
  return true;
}

//------------------------------------------------------------------------------
// The receiver extent of every layer of the frame, reduced on the GPU. Directional and spot
// lights are fitted to per-view tile boxes (computed once per view, so a moving light costs
// no pass over the samples); point lights, whose cube faces need each sample's direction, to
// a per-sample reduction with the light's facing rules.
bool vtkPenumbraShadowMapShadows::Internals::ReduceExtent(vtkPenumbraShadowMapShadows* self,
  vtkPenumbraFrame* frame, const LightSetup& setup, ReceiverExtent& extent, std::string& error)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  const int tiles = ((frame->GetWidth() + ExtentTile - 1) / ExtentTile) *
    ((frame->GetHeight() + ExtentTile - 1) / ExtentTile);
  if (setup.Type != LightSetup::Kind::Point)
  {
    const std::vector<double> key = { static_cast<double>(frame->GetSamplesTime()),
      static_cast<double>(frame->GetWidth()), static_cast<double>(frame->GetHeight()),
      static_cast<double>(frame->GetNumberOfLayers()) };
    if (key != this->TileKey)
    {
      if (!this->TilesQuad)
      {
        this->TilesQuad.reset(new vtkOpenGLQuadHelper(
          win, nullptr, ComposeShader(vtkPenumbraShadowMapTilesFS).c_str(), ""));
      }
      if (!this->TilePass(
            frame, *this->TilesQuad, [](vtkShaderProgram*) {}, this->TileData))
      {
        error = "the tile-summary program does not compile on this OpenGL implementation";
        return false;
      }
      this->TileKey = key;
    }
    for (const TileOutputs& layer : this->TileData)
    {
      ExtentFromTiles(setup, layer, tiles, extent);
    }
    return true;
  }
  if (!this->ExtentQuad)
  {
    this->ExtentQuad.reset(new vtkOpenGLQuadHelper(
      win, nullptr, ComposeShader(vtkPenumbraShadowMapExtentFS).c_str(), ""));
  }
  const int slotMode = this->SlotMode(self, setup);
  auto uniforms = [&](vtkShaderProgram* program)
  {
    program->SetUniformi("slotMode", slotMode);
    const float position[3] = { static_cast<float>(setup.Position[0]),
      static_cast<float>(setup.Position[1]), static_cast<float>(setup.Position[2]) };
    program->SetUniform3f("lightPosition", position);
  };
  if (!this->TilePass(frame, *this->ExtentQuad, uniforms, this->ExtentData))
  {
    error = "the receiver-extent program does not compile on this OpenGL implementation";
    return false;
  }
  for (const TileOutputs& layer : this->ExtentData)
  {
    MergeExtent(layer, tiles, extent);
  }
  return true;
}
