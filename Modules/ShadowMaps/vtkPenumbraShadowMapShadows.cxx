#include "vtkPenumbraShadowMapShadows.h"

#include "vtkCamera.h"
#include "vtkMatrix4x4.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraGoniometricLight.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkTextureUnitManager.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkPenumbraShadowMapClassify.h"
#include "vtkPenumbraShadowMapCompare.h"
#include "vtkPenumbraShadowMapEstimateFS.h"
#include "vtkPenumbraShadowMapExtentFS.h"
#include "vtkPenumbraShadowMapFS.h"
#include "vtkPenumbraShadowMapFrameFS.h"
#include "vtkPenumbraShadowMapLookupFS.h"
#include "vtkPenumbraShadowMapMidpointFS.h"
#include "vtkPenumbraShadowMapParaboloidFS.h"
#include "vtkPenumbraShadowMapParaboloidVS.h"
#include "vtkPenumbraShadowMapReceive.h"
#include "vtkPenumbraShadowMapSoft.h"
#include "vtkPenumbraShadowMapTileSample.h"
#include "vtkPenumbraShadowMapTilesFS.h"
#include "vtkPenumbraShadowMapVS.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraShadowMapShadows);

using penumbra_light_views::LightSetup;
using penumbra_light_views::View;

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;

constexpr unsigned char Decided = 0;
constexpr unsigned char Pending = 1;

// Paraboloid tessellation (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, ch. 6, "tessellated fine enough"): no sub-edge spans more
// than this angle seen from the light, up to MaxSubdivisions per triangle edge. A 2-degree
// chord deviates from its arc by 1.5e-4 of the map radius: 0.15 texel at 2048^2.
constexpr double ParaboloidStepRadians = 2.0 * 3.14159265358979323846 / 180.0;
constexpr int MaxSubdivisions = 32;

// Slope-scaled bias stops growing here (0.057 degrees from grazing): a receiver exactly
// edge-on to the light would otherwise get an infinite bias. Lower caps leave grazing
// receivers in their own shadow at every resolution (a cap of 20, 87 degrees, left 33 % of
// torture/grazing_light's lit samples shadowed at 2048² and 4096²; this cap: 1.5 % and
// 0.26 % at 2048² and 8192², 640 x 480).
constexpr double MaxTangent = 1000.0;

// PCSS: an area or linear light's map is a spot light's at its centre along its normal, with
// a cone just under 90 degrees (the widest a single perspective map fits).
constexpr double AreaConeDegrees = 89.0;

// Fast PCF (Brabec 2003, ch. 5.2): the 2 x 2 texels around the continuous map position
// (ms, mt) in [-1, 1], compared with `threshold` and weighted bilinearly; the taps stay
// inside the map like PCF's. vtkPenumbraShadowMapCompare.glsl has the float twin.
double BilinearLookup(
  const std::vector<float>& map, int width, int height, double ms, double mt, double threshold)
{
  const double fx = (ms * 0.5 + 0.5) * width - 0.5;
  const double fy = (mt * 0.5 + 0.5) * height - 0.5;
  const double bx = std::floor(fx), by = std::floor(fy);
  const double wx = fx - bx, wy = fy - by;
  auto lit = [&](double x, double y)
  {
    const int ix = std::min(width - 1, std::max(0, static_cast<int>(x)));
    const int iy = std::min(height - 1, std::max(0, static_cast<int>(y)));
    return map[static_cast<size_t>(iy) * width + ix] >= threshold ? 1.0 : 0.0;
  };
  const double bottom = (1.0 - wx) * lit(bx, by) + wx * lit(bx + 1.0, by);
  const double top = (1.0 - wx) * lit(bx, by + 1.0) + wx * lit(bx + 1.0, by + 1.0);
  return (1.0 - wy) * bottom + wy * top;
}

// One light's maps, kept until the light, the casters, the view or the settings change.
// Slots: 0 (directional, spot), 2 * axis + negative (cube faces), hemisphere (paraboloid).
struct LightMaps
{
  vtkWeakPointer<vtkLight> Light;
  std::vector<double> Key;
  bool Valid = false;
  bool Paraboloid = false;
  int Width = 0, Height = 0;     // texels (non-square only for one-view lights)
  double Need[2] = { 0.0, 0.0 }; // RESM: the estimate the size came from
  std::vector<View> Views;
  std::vector<std::vector<float>> Maps;                    // CPU lookup
  std::vector<vtkSmartPointer<vtkTextureObject>> Textures; // GPU lookup (compare mode)
  double Centre[3] = { 0, 0, 0 };                          // paraboloid: the light, rebased
  double Far = 1.0;                                        // paraboloid: depth = distance / Far
  double MapScale = 1.0; // paraboloid: paraboloid coordinates -> NDC
};

double Norm3(const double* v)
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// Slot layouts: one view (directional, spot), six cube faces, two paraboloid hemispheres.
constexpr int SlotsOne = 0;
constexpr int SlotsCube = 1;
constexpr int SlotsParaboloid = 2;

// What fitting a light's views needs to know of its receivers (the pending samples, facing
// the light and inside its cone): Brabec 2003, ch. 4.2. Filled on the CPU from a sample set
// or on the GPU from the G-buffer (the extent shader), merged the same way.
struct ReceiverExtent
{
  std::array<char, 6> Used{};
  double Box[6] = { std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max(), -std::numeric_limits<double>::max() };
  double Lo[3] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max() };
  double Hi[3] = { -std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    -std::numeric_limits<double>::max() };
  double Farthest = 0.0;
  double SpotTan = 0.0;
  vtkIdType Pending = 0;
  // Directional lights fitted with the minimum-area rectangle: the receivers' tile-box
  // corners in the light plane (along LightAxes' axes[0] and axes[1]).
  bool CollectPlane = false;
  bool Square = false; // the shortest longer side instead of the least area
  std::vector<std::array<double, 2>> Plane;
};

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

using TileOutputs = std::array<std::vector<float>, 4>;

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

// The scene's triangle vertices in runs of SceneChunks::Size, each with its box, so that the
// scene fit (ExtentFromScene) reads only the runs whose box could move the extent: every
// quantity of the extent is a minimum or maximum over the vertices, and a box bounds its
// vertices. Rebuilt when the triangles change (vtkPenumbraSceneGeometry::GetGeometryTime()),
// kept while only the light moves, which is when the scene fit is recomputed.
struct SceneChunks
{
  static constexpr vtkIdType Size = 256;
  vtkPenumbraSceneGeometry* Geometry = nullptr; // identity only, never dereferenced
  vtkMTimeType Time = 0;
  vtkIdType Count = 0; // vertices (3 per triangle)
  std::vector<std::array<double, 6>> Boxes;

  void Update(vtkPenumbraSceneGeometry* geometry)
  {
    vtkDoubleArray* vertices = geometry->GetVertices();
    const vtkIdType count = vertices ? 3 * geometry->GetNumberOfTriangles() : 0;
    if (geometry == this->Geometry && geometry->GetGeometryTime() == this->Time &&
      count == this->Count)
    {
      return;
    }
    this->Geometry = geometry;
    this->Time = geometry->GetGeometryTime();
    this->Count = count;
    this->Boxes.assign(static_cast<size_t>((count + Size - 1) / Size), {});
    vtkSMPTools::For(0, static_cast<vtkIdType>(this->Boxes.size()),
      [&](vtkIdType first, vtkIdType last)
      {
        for (vtkIdType c = first; c < last; ++c)
        {
          std::array<double, 6>& box = this->Boxes[static_cast<size_t>(c)];
          box = { std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
            std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
            std::numeric_limits<double>::max(), -std::numeric_limits<double>::max() };
          for (vtkIdType v = c * Size; v < std::min(count, (c + 1) * Size); ++v)
          {
            const double* p = vertices->GetPointer(3 * v);
            for (int k = 0; k < 3; ++k)
            {
              box[2 * k] = std::min(box[2 * k], p[k]);
              box[2 * k + 1] = std::max(box[2 * k + 1], p[k]);
            }
          }
        }
      });
  }
};

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

// The scene fit (SetFitTo(FIT_TO_SCENE)): every vertex of the scene's triangles is a
// receiver point. A spot light with a vertex behind its apex gets the whole cone (that
// triangle may reach into it), as a tile box behind it does in ExtentFromTiles(). Only the
// chunks that may move the extent are read (MayMoveExtent), after the ones whose boxes reach
// farthest, which usually hold the extremes; the result is the same as reading every vertex.
// The minimum-area rectangle needs every vertex of the plane's hull, so it reads them all.
void ExtentFromScene(const LightSetup& setup, int slotMode, vtkPenumbraSceneGeometry* geometry,
  SceneChunks& chunks, ReceiverExtent& e)
{
  vtkDoubleArray* vertices = geometry->GetVertices();
  const vtkIdType count = vertices ? 3 * geometry->GetNumberOfTriangles() : 0;
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
      const double* p = vertices->GetPointer(3 * v);
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

constexpr int Tile = 4; // samples per side of a tile box (see ExtentFromTiles)

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

int CountViews(const LightMaps& maps)
{
  int views = 0;
  for (size_t slot = 0; slot < maps.Maps.size(); ++slot)
  {
    views += maps.Maps[slot].empty() && !maps.Textures[slot] ? 0 : 1;
  }
  return views;
}

// A program's source with the shared GLSL pieces in place. Only the facing rules (Classify)
// use double precision, so only programs with them need GL_ARB_gpu_shader_fp64 (core since
// GL 4.0): the tile programs run where it is missing.
std::string ComposeShader(const char* source)
{
  std::string fs = source;
  if (fs.find("//PENUMBRA::Classify") != std::string::npos)
  {
    vtkShaderProgram::Substitute(fs, "//VTK::System::Dec",
      "//VTK::System::Dec\n#extension GL_ARB_gpu_shader_fp64 : require\n", false);
  }
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::Classify", vtkPenumbraShadowMapClassify, false);
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::TileSample", vtkPenumbraShadowMapTileSample, false);
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::Compare", vtkPenumbraShadowMapCompare, false);
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::Soft", vtkPenumbraShadowMapSoft, false);
  return fs;
}

// The settings a lookup program is compiled for. The uniforms that only choose a branch
// (the slot layout, the projection, the filter, the facing rules' light kind) become
// constants, so that the compiler drops the branches a light does not take: llvmpipe runs
// every branch of an `if` under a lane mask, texture taps included, so a program that
// carries the soft lookups' and the bilinear filter's taps pays for them on every pixel.
struct LookupVariant
{
  int SlotMode = 0;
  int Perspective = 0;
  int Radius = 0;
  int Bilinear = 0;
  int AreaMode = 0;
  int LightKind = 0;
  int LightOff = 0;
  int AnyCaster = 0;

  std::vector<std::pair<const char*, int>> Constants() const
  {
    return { { "slotMode", this->SlotMode }, { "perspective", this->Perspective },
      { "radius", this->Radius }, { "bilinear", this->Bilinear }, { "areaMode", this->AreaMode },
      { "lightKind", this->LightKind }, { "lightOff", this->LightOff },
      { "anyCaster", this->AnyCaster } };
  }

  std::string Key() const
  {
    std::string key;
    for (const auto& c : this->Constants())
    {
      key += std::to_string(c.second) + ",";
    }
    return key;
  }

  // The composed source with each of these uniforms declared as a constant instead (the
  // ones a program does not declare are left out).
  std::string Specialize(std::string source) const
  {
    for (const auto& c : this->Constants())
    {
      vtkShaderProgram::Substitute(source, std::string("uniform int ") + c.first + ";",
        std::string("const int ") + c.first + " = " + std::to_string(c.second) + ";", false);
    }
    return source;
  }
};

// Lookup programs by variant, compiled on first use and kept with the technique.
class VariantPrograms
{
public:
  vtkOpenGLQuadHelper* Get(
    vtkOpenGLRenderWindow* win, const char* vs, const std::string& fs, const LookupVariant& variant)
  {
    std::unique_ptr<vtkOpenGLQuadHelper>& quad = this->Quads[variant.Key()];
    if (!quad)
    {
      quad.reset(new vtkOpenGLQuadHelper(win, vs, variant.Specialize(fs).c_str(), ""));
    }
    return quad.get();
  }
  void ReleaseGraphicsResources(vtkWindow* win)
  {
    for (auto& quad : this->Quads)
    {
      quad.second->ReleaseGraphicsResources(win);
    }
  }
  void Reset() { this->Quads.clear(); }

private:
  std::map<std::string, std::unique_ptr<vtkOpenGLQuadHelper>> Quads;
};

// An orthographic view's texel in world units, its larger side (the maps may be non-square):
// the footprint of the slope-scaled bias.
double OrthoFootprint(const View& view, const LightMaps& m)
{
  return std::max(2.0 / (Norm3(view.Row[0]) * m.Width), 2.0 / (Norm3(view.Row[1]) * m.Height));
}

// The uniforms of one slot's view (vtkPenumbraShadowMapCompare.glsl).
// `suffix` ends every name (see penumbra_light_views::SuffixGlobals).
void SetSlotUniforms(
  vtkShaderProgram* program, const LightMaps& m, int slot, const std::string& suffix = "")
{
  auto name = [&suffix](const char* base) { return base + suffix; };
  program->SetUniformi(name("slot").c_str(), slot);
  if (m.Paraboloid)
  {
    program->SetUniformf(name("invFar").c_str(), static_cast<float>(1.0 / m.Far));
    return;
  }
  const View& view = m.Views[static_cast<size_t>(slot)];
  float matrix[16];
  view.ToFloatMatrix(matrix);
  program->SetUniformMatrix4x4(name("lightMatrix").c_str(), matrix);
  program->SetUniformf(name("invFar").c_str(), static_cast<float>(1.0 / view.Far));
  program->SetUniformf(name("tanHalf").c_str(), static_cast<float>(view.TanHalf));
  program->SetUniformf(name("footprintScale").c_str(), static_cast<float>(OrthoFootprint(view, m)));
  program->SetUniformf(name("depthPerLengthOrtho").c_str(), static_cast<float>(Norm3(view.Row[2])));
}
}

namespace
{
bool AreaAsSpot(vtkPenumbraAreaLight* area, LightSetup& setup, std::string& error)
{
  const std::string problem = area->GetValidityMessage();
  double u[3], v[3], n[3];
  if (!problem.empty() || !area->GetAxes(u, v, n))
  {
    error = "invalid area light: " + problem;
    return false;
  }
  setup.Type = LightSetup::Kind::Spot;
  setup.Area = true;
  const bool line = area->GetShape() == vtkPenumbraAreaLight::Line;
  for (int c = 0; c < 3; ++c)
  {
    setup.HalfU[c] = 0.5 * area->GetWidth() * u[c];
    setup.HalfV[c] = line ? 0.0 : 0.5 * area->GetHeight() * v[c];
  }
  std::copy(n, n + 3, setup.Axis);
  setup.Cone = AreaConeDegrees;
  setup.CosCone = std::cos(vtkMath::RadiansFromDegrees(AreaConeDegrees));
  return true;
}

// A depth map read as raw depth on its own texture unit (every lookup's texelFetch compare,
// vtkPenumbraShadowMapCompare.glsl), through a sampler object that turns the texture's
// compare mode off; also bound for programs that read no map, so that the sampler2D never
// shares a unit with the G-buffer's samplers.
class RawDepthBinding
{
public:
  RawDepthBinding(vtkOpenGLRenderWindow* win, GLuint& sampler, vtkTextureObject* map)
  {
    if (!sampler)
    {
      glGenSamplers(1, &sampler);
      glSamplerParameteri(sampler, GL_TEXTURE_COMPARE_MODE, GL_NONE);
      glSamplerParameteri(sampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glSamplerParameteri(sampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glSamplerParameteri(sampler, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glSamplerParameteri(sampler, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    // An alias of the map (not owning its handle), bound through VTK so that its texture
    // unit bookkeeping stays right; the sampler object overrides the compare mode there.
    // Its parameters are the map's (VTK sends them to the shared texture on binding).
    this->Alias->SetContext(win);
    this->Alias->SetMinificationFilter(vtkTextureObject::Nearest);
    this->Alias->SetMagnificationFilter(vtkTextureObject::Nearest);
    this->Alias->SetWrapS(vtkTextureObject::ClampToEdge);
    this->Alias->SetWrapT(vtkTextureObject::ClampToEdge);
    this->Alias->SetDepthTextureCompare(true);
    this->Alias->SetDepthTextureCompareFunction(vtkTextureObject::Lequal);
    this->Alias->AssignToExistingTexture(map->GetHandle(), GL_TEXTURE_2D);
    this->Alias->Activate();
    glBindSampler(static_cast<GLuint>(this->Alias->GetTextureUnit()), sampler);
  }
  ~RawDepthBinding()
  {
    glBindSampler(static_cast<GLuint>(this->Alias->GetTextureUnit()), 0);
    this->Alias->Deactivate();
  }
  int GetUnit() { return this->Alias->GetTextureUnit(); }

private:
  vtkNew<vtkTextureObject> Alias;
};
}

namespace
{
// Whether the camera of `renderer` sees the whole box of the scene's triangles: its eight
// corners project inside the view volume (FIT_TO_AUTO).
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

struct vtkPenumbraShadowMapShadows::Internals
{
  // Half width of the PCF kernel (0 without PCF): the taps of the box filter.
  static int TapRadius(vtkPenumbraShadowMapShadows* self)
  {
    return self->Filter == FILTER_PCF ? (self->PCFKernel | 1) / 2 : 0;
  }
  // Texels the filter reaches from the sample's texel, for the slope bias: Fast PCF's
  // 2 x 2 taps reach one texel.
  static int BiasRadius(vtkPenumbraShadowMapShadows* self)
  {
    return self->Filter == FILTER_BILINEAR ? 1 : TapRadius(self);
  }

  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  penumbra_light_views::CasterBuffers Casters;
  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  vtkSmartPointer<vtkTextureObject> DepthTextures[2]; // first layer, second (midpoint) layer
  int MapSize[2] = { 0, 0 };

  // Paraboloid casters: per hemisphere, clipped and tessellated, relative to the light
  // (3 floats position + 4 floats plane per vertex).
  GLuint ParaboloidArray = 0;
  GLuint ParaboloidBuffers[2] = { 0, 0 };
  GLsizei ParaboloidCounts[2] = { 0, 0 };
  std::vector<double> ParaboloidKey;

  std::vector<LightMaps> Cache;
  SceneChunks Chunks; // the scene fit's vertex runs (ExtentFromScene)
  std::vector<unsigned char> State;
  std::vector<float> SecondLayer;
  // GPU lookup staging (pending-sample list, its positions, normals and answers), kept between
  // frames: allocated afresh they cost more in page faults than the lookup itself.
  std::vector<vtkIdType> List;
  std::vector<float> ListPositionData, ListNormalData, ListResult;

  // GPU lookup: the compacted pending samples, their visibility, and the programs.
  vtkSmartPointer<vtkOpenGLFramebufferObject> LookupFBO;
  vtkSmartPointer<vtkTextureObject> ListPositions, ListNormals, ListVisibility;
  VariantPrograms LookupPrograms;
  std::unique_ptr<vtkOpenGLQuadHelper> MidpointQuad;

  // GPU-resident frames: the receiver-extent reduction (tile results and their read-back)
  // and the G-buffer lookup with its stand-in map.
  std::unique_ptr<vtkOpenGLQuadHelper> ExtentQuad;
  VariantPrograms FramePrograms;
  vtkSmartPointer<vtkOpenGLFramebufferObject> ExtentFBO;
  vtkSmartPointer<vtkTextureObject> ExtentTextures[4];
  std::vector<TileOutputs> ExtentData; // per layer: the point-light reduction's outputs
  // Per-view tile boxes for directional and spot lights, and the view they belong to.
  std::unique_ptr<vtkOpenGLQuadHelper> TilesQuad;
  // RESM: the per-light resolution estimate over the G-buffer (tile needs and read-back).
  std::unique_ptr<vtkOpenGLQuadHelper> EstimateQuad;
  std::vector<TileOutputs> EstimateData;
  std::vector<TileOutputs> TileData;
  std::vector<double> TileKey;
  vtkSmartPointer<vtkTextureObject> NoMap;
  GLuint RawDepthSampler = 0; // soft lookups: read the compare-mode maps as raw depth
  // The soft lookups' adaptive sampling: the block corners' values.
  vtkSmartPointer<vtkOpenGLFramebufferObject> CoarseFBO;
  vtkSmartPointer<vtkTextureObject> CoarseValues;
  static constexpr int ExtentTile = Tile;

  // Phases (see the definitions).
  bool UpdateCasters(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    vtkPenumbraSceneGeometry* geometry);
  int SlotMode(vtkPenumbraShadowMapShadows* self, const LightSetup& setup);
  static int SoftMode(vtkPenumbraShadowMapShadows* self, const LightMaps& m);
  LookupVariant Variant(vtkPenumbraShadowMapShadows* self, const LightSetup& setup, bool anyCaster,
    const LightMaps* maps);
  std::vector<double> MapKey(vtkPenumbraShadowMapShadows* self, vtkRenderer* renderer,
    vtkLight* light, vtkPenumbraSceneGeometry* geometry, const double shift[3], double samples,
    double pending);
  // Whether the maps are fitted to the scene (SetFitTo()), not to the view.
  static bool FitsScene(
    vtkPenumbraShadowMapShadows* self, vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry)
  {
    return self->ResolutionMode == RESOLUTION_FIXED &&
      (self->FitTo == FIT_TO_SCENE ||
        (self->FitTo == FIT_TO_AUTO && SceneInView(renderer, geometry)));
  }
  void FitViews(
    const LightSetup& setup, const ReceiverExtent& e, int slotMode, int size, LightMaps* maps);
  using Estimator = std::function<bool(const View&, std::vector<float>&, std::string&)>;
  bool PlanMaps(vtkPenumbraShadowMapShadows* self, const LightSetup& setup,
    const ReceiverExtent& extent, const Estimator& estimate, LightMaps* maps, int size[2],
    std::string& error);
  bool RenderMaps(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    vtkPenumbraSceneGeometry* geometry, const LightSetup& setup, const ReceiverExtent& extent,
    const int size[2], LightMaps* maps, std::string& error);
  vtkShaderProgram* MapProgram(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    const LightSetup& setup, bool paraboloid);
  void BindCasters(vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program,
    vtkPenumbraSceneGeometry* geometry, const LightSetup& setup, const LightMaps& maps);
  GLsizei BindSlot(vtkShaderProgram* program, const LightMaps& maps, int slot);
  vtkTextureObject* SlotTexture(
    vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, LightMaps* maps, int slot);
  void DrawSlotLayers(vtkPenumbraShadowMapShadows* self, vtkOpenGLState* ostate,
    vtkShaderProgram* program, GLsizei count, vtkTextureObject* slotTexture, LightMaps* maps,
    int slot);
  void ResolveMidpoint(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    vtkShaderProgram* program, vtkTextureObject* slotTexture, LightMaps* maps, int slot);
  bool EstimateFrame(vtkPenumbraFrame* frame, const LightSetup& setup, const View& view, int step,
    std::vector<float>& needs, std::string& error);
  void SetCompareUniforms(vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program,
    const LightSetup& setup, const LightMaps& m, const std::string& suffix = "");
  std::shared_ptr<vtkPenumbraFrame::ShaderLookup> ShaderLookup(
    vtkPenumbraShadowMapShadows* self, const LightSetup& setup, const LightMaps& maps);
  void SetSoftUniforms(
    vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program, const LightMaps& m);
  static void SetAreaUniforms(vtkShaderProgram* program, const LightSetup& setup);
  void DrawLookup(vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int layer,
    const LightSetup& setup, const LightMaps* maps, const std::vector<int>& slots,
    vtkOpenGLQuadHelper* quad, int adaptivePass, int block);
  bool LookupList(vtkPenumbraShadowMapShadows* self, const penumbra_light_views::FrameInputs& in,
    const LightSetup& setup, const LightMaps& m, const unsigned char* state, float* vis,
    std::string& error);
  void LookupCPU(vtkPenumbraShadowMapShadows* self, const penumbra_light_views::FrameInputs& in,
    const LightSetup& setup, const LightMaps& m, const unsigned char* state, float* vis);
  bool FrameLight(
    vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int k, std::string& error);
  bool ReduceExtent(vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame,
    const LightSetup& setup, ReceiverExtent& extent, std::string& error);
  bool TilePass(vtkPenumbraFrame* frame, vtkOpenGLQuadHelper& quad,
    const std::function<void(vtkShaderProgram*)>& uniforms, std::vector<TileOutputs>& data);
  bool LookupFrame(vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int k,
    const LightSetup& setup, bool anyCaster, const LightMaps* maps, std::string& error);

  static vtkSmartPointer<vtkTextureObject> FloatTexture(vtkOpenGLRenderWindow* win)
  {
    auto tex = vtkSmartPointer<vtkTextureObject>::New();
    tex->SetContext(win);
    tex->SetMinificationFilter(vtkTextureObject::Nearest);
    tex->SetMagnificationFilter(vtkTextureObject::Nearest);
    tex->SetWrapS(vtkTextureObject::ClampToEdge);
    tex->SetWrapT(vtkTextureObject::ClampToEdge);
    return tex;
  }

  // A depth texture the lookup samples with the hardware compare.
  static vtkSmartPointer<vtkTextureObject> CompareTexture(
    vtkOpenGLRenderWindow* win, int width, int height)
  {
    auto tex = FloatTexture(win);
    tex->SetDepthTextureCompare(true);
    tex->SetDepthTextureCompareFunction(vtkTextureObject::Lequal);
    tex->AllocateDepth(width, height, vtkTextureObject::Float32);
    return tex;
  }

  void Release(vtkWindow* window)
  {
    if (this->Window && (!window || window == this->Window))
    {
      this->Window->MakeCurrent();
      this->Casters.Release();
      if (this->ParaboloidArray)
      {
        glDeleteVertexArrays(1, &this->ParaboloidArray);
        glDeleteBuffers(2, this->ParaboloidBuffers);
      }
      for (auto& tex : this->DepthTextures)
      {
        if (tex)
        {
          tex->ReleaseGraphicsResources(this->Window);
        }
      }
      if (this->FBO)
      {
        this->FBO->ReleaseGraphicsResources(this->Window);
      }
      for (auto& entry : this->Cache)
      {
        for (auto& tex : entry.Textures)
        {
          if (tex)
          {
            tex->ReleaseGraphicsResources(this->Window);
          }
        }
      }
      for (vtkTextureObject* tex :
        { this->ListPositions.Get(), this->ListNormals.Get(), this->ListVisibility.Get() })
      {
        if (tex)
        {
          tex->ReleaseGraphicsResources(this->Window);
        }
      }
      if (this->LookupFBO)
      {
        this->LookupFBO->ReleaseGraphicsResources(this->Window);
      }
      for (vtkTextureObject* tex : { this->ExtentTextures[0].Get(), this->ExtentTextures[1].Get(),
             this->ExtentTextures[2].Get(), this->ExtentTextures[3].Get(), this->NoMap.Get() })
      {
        if (tex)
        {
          tex->ReleaseGraphicsResources(this->Window);
        }
      }
      if (this->ExtentFBO)
      {
        this->ExtentFBO->ReleaseGraphicsResources(this->Window);
      }
      this->LookupPrograms.ReleaseGraphicsResources(this->Window);
      this->FramePrograms.ReleaseGraphicsResources(this->Window);
      for (auto* quad : { this->MidpointQuad.get(), this->ExtentQuad.get(), this->TilesQuad.get(),
             this->EstimateQuad.get() })
      {
        if (quad)
        {
          quad->ReleaseGraphicsResources(this->Window);
        }
      }
    }
    if (this->RawDepthSampler && this->Window)
    {
      glDeleteSamplers(1, &this->RawDepthSampler);
    }
    this->RawDepthSampler = 0;
    this->LookupFBO = nullptr;
    this->ListPositions = this->ListNormals = this->ListVisibility = nullptr;
    this->LookupPrograms.Reset();
    this->MidpointQuad.reset();
    this->ExtentQuad.reset();
    this->FramePrograms.Reset();
    this->TilesQuad.reset();
    this->EstimateQuad.reset();
    this->TileKey.clear();
    this->ExtentFBO = nullptr;
    this->NoMap = nullptr;
    for (auto& tex : this->ExtentTextures)
    {
      tex = nullptr;
    }
    this->Casters.Forget();
    this->ParaboloidArray = 0;
    this->ParaboloidBuffers[0] = this->ParaboloidBuffers[1] = 0;
    this->ParaboloidKey.clear();
    this->FBO = nullptr;
    for (auto& tex : this->DepthTextures)
    {
      tex = nullptr;
    }
    this->MapSize[0] = this->MapSize[1] = 0;
    this->Window = nullptr;
    // Cached maps were fitted to this window's samples (and their textures are gone).
    this->Cache.clear();
  }

  void AllocateMaps(vtkOpenGLRenderWindow* win, int width, int height)
  {
    if (this->FBO && this->MapSize[0] == width && this->MapSize[1] == height)
    {
      return;
    }
    this->FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->FBO->SetContext(win);
    for (auto& tex : this->DepthTextures)
    {
      tex = vtkSmartPointer<vtkTextureObject>::New();
      tex->SetContext(win);
      tex->SetMinificationFilter(vtkTextureObject::Nearest);
      tex->SetMagnificationFilter(vtkTextureObject::Nearest);
      tex->SetWrapS(vtkTextureObject::ClampToEdge);
      tex->SetWrapT(vtkTextureObject::ClampToEdge);
      tex->AllocateDepth(width, height, vtkTextureObject::Float32);
    }
    this->MapSize[0] = width;
    this->MapSize[1] = height;
  }

  // Clips every caster against each hemisphere's equator plane (in light space, before the
  // mapping, so that triangles straddling z = 0 do not map their far vertices near the
  // singularity) and tessellates what is left (Brabec 2003, ch. 6).
  void BuildParaboloidCasters(const double centre[3])
  {
    std::vector<float> data[2];
    const std::vector<float>& v = this->Casters.Vertices;
    for (size_t tri = 0; tri + 9 <= v.size(); tri += 9)
    {
      for (int h = 0; h < 2; ++h)
      {
        const double sign = h ? -1.0 : 1.0;
        double q[3][3];
        for (int k = 0; k < 3; ++k)
        {
          for (int c = 0; c < 3; ++c)
          {
            q[k][c] = static_cast<double>(v[tri + 3 * k + c]) - centre[c];
          }
          q[k][2] *= sign;
        }
        double e1[3], e2[3], n[3];
        for (int c = 0; c < 3; ++c)
        {
          e1[c] = q[1][c] - q[0][c];
          e2[c] = q[2][c] - q[0][c];
        }
        vtkMath::Cross(e1, e2, n);
        if (!(vtkMath::Normalize(n) > 0.0))
        {
          continue;
        }
        const double planeC = vtkMath::Dot(n, q[0]);
        // Sutherland-Hodgman against z >= 0.
        std::array<std::array<double, 3>, 4> poly;
        int count = 0;
        for (int k = 0; k < 3; ++k)
        {
          const double* a = q[k];
          const double* b = q[(k + 1) % 3];
          if (a[2] >= 0.0)
          {
            poly[count++] = { a[0], a[1], a[2] };
          }
          if ((a[2] >= 0.0) != (b[2] >= 0.0))
          {
            const double t = a[2] / (a[2] - b[2]);
            poly[count++] = { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), 0.0 };
          }
        }
        for (int f = 1; f + 1 < count; ++f)
        {
          const double* corner[3] = { poly[0].data(), poly[f].data(), poly[f + 1].data() };
          double widest = 0.0;
          for (int k = 0; k < 3; ++k)
          {
            const double* a = corner[k];
            const double* b = corner[(k + 1) % 3];
            const double la = Norm3(a), lb = Norm3(b);
            if (la > 0.0 && lb > 0.0)
            {
              const double cosine = std::max(-1.0, std::min(1.0, vtkMath::Dot(a, b) / (la * lb)));
              widest = std::max(widest, std::acos(cosine));
            }
            else
            {
              widest = 3.2; // touches the light: as fine as allowed
            }
          }
          const int steps = std::max(1,
            std::min(MaxSubdivisions, static_cast<int>(std::ceil(widest / ParaboloidStepRadians))));
          auto emit = [&](int i, int j)
          {
            for (int c = 0; c < 3; ++c)
            {
              const double x = corner[0][c] + (corner[1][c] - corner[0][c]) * i / steps +
                (corner[2][c] - corner[0][c]) * j / steps;
              data[h].push_back(static_cast<float>(x));
            }
            for (int c = 0; c < 3; ++c)
            {
              data[h].push_back(static_cast<float>(n[c]));
            }
            data[h].push_back(static_cast<float>(planeC));
          };
          for (int j = 0; j < steps; ++j)
          {
            for (int i = 0; i + j < steps; ++i)
            {
              emit(i, j);
              emit(i + 1, j);
              emit(i, j + 1);
              if (i + j + 2 <= steps)
              {
                emit(i + 1, j);
                emit(i + 1, j + 1);
                emit(i, j + 1);
              }
            }
          }
        }
      }
    }
    if (!this->ParaboloidArray)
    {
      glGenVertexArrays(1, &this->ParaboloidArray);
      glGenBuffers(2, this->ParaboloidBuffers);
    }
    for (int h = 0; h < 2; ++h)
    {
      glBindBuffer(GL_ARRAY_BUFFER, this->ParaboloidBuffers[h]);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data[h].size() * sizeof(float)),
        data[h].empty() ? nullptr : data[h].data(), GL_STATIC_DRAW);
      this->ParaboloidCounts[h] = static_cast<GLsizei>(data[h].size() / 7);
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
  }
};

//------------------------------------------------------------------------------
vtkPenumbraShadowMapShadows::vtkPenumbraShadowMapShadows()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraShadowMapShadows::~vtkPenumbraShadowMapShadows()
{
  this->Impl->Release(nullptr);
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::ParaboloidFromDirection(const double d[3], double xy[2])
{
  const int hemisphere = d[2] >= 0.0 ? 0 : 1;
  const double denominator = 1.0 + std::fabs(d[2]);
  xy[0] = d[0] / denominator;
  xy[1] = d[1] / denominator;
  return hemisphere;
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::DirectionFromParaboloid(
  const double xy[2], int hemisphere, double d[3])
{
  const double r2 = xy[0] * xy[0] + xy[1] * xy[1];
  d[0] = 2.0 * xy[0] / (1.0 + r2);
  d[1] = 2.0 * xy[1] / (1.0 + r2);
  d[2] = (1.0 - r2) / (1.0 + r2) * (hemisphere ? -1.0 : 1.0);
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  this->NumberOfViews = 0;
  this->MapTimeMs = this->LookupTimeMs = 0.0;

  // ---- Input checks: nothing is written before they pass.
  penumbra_light_views::FrameInputs in;
  {
    std::string inputError;
    if (!in.Read(renderer, geometry, samples, light, visibility, inputError))
    {
      PENUMBRA_FAIL("shadow maps: " << inputError);
    }
  }
  const LightSetup& setup = in.Light;
  const vtkIdType n = in.NumberOfSamples;
  const bool anyCaster = !setup.Off && impl.UpdateCasters(this, in.Window, geometry);

  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  float* vis = n ? visibility->GetPointer(0) : nullptr;
  impl.State.resize(static_cast<size_t>(n));
  unsigned char* state = impl.State.data();
  const penumbra_light_views::FacingCounts facing = penumbra_light_views::ClassifyFacing(setup, n,
    in.Positions, in.Normals, in.Props, in.Shift, anyCaster, vis, state, Pending, Decided);
  if (facing.Pending == 0)
  {
    visibility->Modified();
    this->LastTimeMs = ElapsedMs(start);
    return 1;
  }

  // ---- The maps: kept while everything they depend on is unchanged (see MapKey()).
  const int slotMode = impl.SlotMode(this, setup);
  std::vector<double> key = impl.MapKey(this, renderer, light, geometry, in.Shift,
    static_cast<double>(n), static_cast<double>(facing.Pending));
  LightMaps* maps = &penumbra_light_views::LightCacheEntry(impl.Cache, light);
  if (!maps->Valid || maps->Key != key)
  {
    ReceiverExtent extent;
    extent.CollectPlane = this->FitRectangle != FIT_AXIS;
    extent.Square = this->FitRectangle == FIT_SQUARE;
    if (Internals::FitsScene(this, renderer, geometry))
    {
      ExtentFromScene(setup, slotMode, geometry, impl.Chunks, extent);
    }
    else if (slotMode == SlotsOne)
    {
      // The same tile boxes the GPU frame path fits to, so both lookups use the same maps.
      ExtentFromTiles(setup, TilesFromSamples(in, samples->GetWidth(), samples->GetHeight()),
        TileCount(samples->GetWidth(), samples->GetHeight()), extent);
    }
    else
    {
      double axes[3][3];
      LightAxes(setup, axes);
      for (vtkIdType s = 0; s < n; ++s)
      {
        if (state[s] == Pending)
        {
          double p[3];
          SamplePoint(in, s, p);
          AddReceiver(setup, axes, slotMode, p, extent);
        }
      }
    }
    std::string error;
    maps->Key.swap(key);
    const int width = samples->GetWidth(), height = samples->GetHeight();
    auto estimate = [&](const View& view, std::vector<float>& needs, std::string&)
    {
      needs = EstimateSamples(in, width, height, state, view, this->AnalysisStep);
      return true;
    };
    int size[2];
    if (!impl.PlanMaps(this, setup, extent, estimate, maps, size, error) ||
      !impl.RenderMaps(this, in.Window, geometry, setup, extent, size, maps, error))
    {
      PENUMBRA_FAIL("shadow maps: " << error);
    }
  }
  this->LastMapSize[0] = maps->Width;
  this->LastMapSize[1] = maps->Height;
  this->NumberOfViews = CountViews(*maps);

  const auto lookupStart = Clock::now();
  if (this->Lookup != LOOKUP_CPU)
  {
    std::string error;
    if (!impl.LookupList(this, in, setup, *maps, state, vis, error))
    {
      PENUMBRA_FAIL("shadow maps: " << error);
    }
  }
  else
  {
    impl.LookupCPU(this, in, setup, *maps, state, vis);
  }
  this->LookupTimeMs = ElapsedMs(lookupStart);
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::ComputeFrame(vtkPenumbraFrame* frame)
{
  if (this->Lookup == LOOKUP_CPU)
  {
    return this->Superclass::ComputeFrame(frame); // the maps are compared on the CPU
  }
  return this->ComputeFrameLights(frame, "shadow maps",
    [this, frame](int k, std::string& error)
    { return this->Impl->FrameLight(this, frame, k, error); });
}

//------------------------------------------------------------------------------
bool vtkPenumbraShadowMapShadows::Internals::UpdateCasters(
  vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry)
{
  win->MakeCurrent();
  if (this->Window && this->Window != win)
  {
    this->Release(nullptr);
  }
  this->Window = win;
  if (this->Casters.Update(geometry))
  {
    ++self->NumberOfUploads;
  }
  return this->Casters.VertexCount > 0;
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::Internals::SlotMode(
  vtkPenumbraShadowMapShadows* self, const LightSetup& setup)
{
  if (setup.Type != LightSetup::Kind::Point)
  {
    return SlotsOne;
  }
  return self->PointMode == POINT_CUBE ? SlotsCube : SlotsParaboloid;
}

//------------------------------------------------------------------------------
// The soft lookup of a light's maps: AREA_NONE for hard lights, else the area light mode.
int vtkPenumbraShadowMapShadows::Internals::SoftMode(
  vtkPenumbraShadowMapShadows* self, const LightMaps& m)
{
  return vtkPenumbraAreaLight::SafeDownCast(m.Light.Get()) ? self->AreaLightMode : AREA_NONE;
}

//------------------------------------------------------------------------------
// The lookup program a light needs (see LookupVariant); maps is null when no sample is
// pending (no map is read).
LookupVariant vtkPenumbraShadowMapShadows::Internals::Variant(
  vtkPenumbraShadowMapShadows* self, const LightSetup& setup, bool anyCaster, const LightMaps* maps)
{
  LookupVariant v;
  v.LightKind = setup.Type == LightSetup::Kind::Directional
    ? 0
    : (setup.Type == LightSetup::Kind::Spot ? (setup.Area ? 3 : 2) : 1);
  v.LightOff = setup.Off ? 1 : 0;
  v.AnyCaster = anyCaster ? 1 : 0;
  if (!maps)
  {
    return v;
  }
  v.SlotMode = this->SlotMode(self, setup);
  // Every view of a light has the same projection (one view, or perspective cube faces).
  v.Perspective = !maps->Paraboloid && !maps->Views.empty() && maps->Views[0].Perspective ? 1 : 0;
  v.Bilinear = self->Filter == FILTER_BILINEAR ? 1 : 0;
  v.Radius = v.Bilinear ? 0 : TapRadius(self);
  v.AreaMode = SoftMode(self, *maps);
  return v;
}

//------------------------------------------------------------------------------
// Everything the maps depend on, by value (a spurious Modified() on the camera or light does
// not force a re-render; a real change always does): the light, the casters, the frames,
// the view the receivers are fitted to, the window size and the settings.
std::vector<double> vtkPenumbraShadowMapShadows::Internals::MapKey(
  vtkPenumbraShadowMapShadows* self, vtkRenderer* renderer, vtkLight* light,
  vtkPenumbraSceneGeometry* geometry, const double shift[3], double samples, double pending)
{
  std::vector<double> key;
  double lp[3], lf[3], origin[3];
  light->GetTransformedPosition(lp);
  light->GetTransformedFocalPoint(lf);
  geometry->GetOrigin(origin);
  key.insert(key.end(), lp, lp + 3);
  key.insert(key.end(), lf, lf + 3);
  key.push_back(light->GetPositional());
  key.push_back(light->GetConeAngle());
  key.push_back(static_cast<double>(geometry->GetGeometryTime()));
  key.push_back(static_cast<double>(geometry->GetFlagsTime()));
  key.insert(key.end(), origin, origin + 3);
  key.push_back(static_cast<double>(self->GetMTime()));
  if (FitsScene(self, renderer, geometry))
  {
    return key; // nothing of the view
  }
  key.insert(key.end(), shift, shift + 3);
  key.push_back(samples);
  key.push_back(pending);
  if (vtkCamera* camera = renderer->GetActiveCamera())
  {
    key.insert(key.end(), camera->GetPosition(), camera->GetPosition() + 3);
    key.insert(key.end(), camera->GetFocalPoint(), camera->GetFocalPoint() + 3);
    key.insert(key.end(), camera->GetViewUp(), camera->GetViewUp() + 3);
    key.push_back(camera->GetViewAngle());
    key.push_back(camera->GetParallelProjection());
    key.push_back(camera->GetParallelScale());
    key.insert(key.end(), camera->GetClippingRange(), camera->GetClippingRange() + 2);
  }
  const int* size = renderer->GetSize();
  key.push_back(size[0]);
  key.push_back(size[1]);
  return key;
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
// The map program for a light: paraboloid, or perspective/orthographic; orthographic views
// with linear depth store clip z as it is (linear already), the others write the linear
// depth per fragment. Null when it does not compile.
vtkShaderProgram* vtkPenumbraShadowMapShadows::Internals::MapProgram(
  vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, const LightSetup& setup,
  bool paraboloid)
{
  const bool hardwareDepth =
    setup.Type == LightSetup::Kind::Directional && self->DepthMode == DEPTH_LINEAR;
  auto variant = [hardwareDepth](const char* source)
  {
    std::string text = source;
    if (hardwareDepth)
    {
      vtkShaderProgram::Substitute(
        text, "//VTK::System::Dec", "//VTK::System::Dec\n#define PENUMBRA_HARDWARE_DEPTH\n", false);
    }
    return text;
  };
  vtkShaderProgram* program = paraboloid
    ? win->GetShaderCache()->ReadyShaderProgram(
        vtkPenumbraShadowMapParaboloidVS, vtkPenumbraShadowMapParaboloidFS, "")
    : win->GetShaderCache()->ReadyShaderProgram(
        variant(vtkPenumbraShadowMapVS).c_str(), variant(vtkPenumbraShadowMapFS).c_str(), "");
  return program && program->GetCompiled() ? program : nullptr;
}

//------------------------------------------------------------------------------
// Binds the casters to the map program: the paraboloid casters (clipped and tessellated per
// hemisphere, rebuilt when the light or the casters change) or the uploaded caster vertices,
// with the uniforms every slot shares.
void vtkPenumbraShadowMapShadows::Internals::BindCasters(vtkPenumbraShadowMapShadows* self,
  vtkShaderProgram* program, vtkPenumbraSceneGeometry* geometry, const LightSetup& setup,
  const LightMaps& maps)
{
  if (maps.Paraboloid)
  {
    double origin[3];
    geometry->GetOrigin(origin);
    std::vector<double> paraboloidKey = { setup.Position[0], setup.Position[1], setup.Position[2],
      static_cast<double>(geometry->GetGeometryTime()),
      static_cast<double>(geometry->GetFlagsTime()), origin[0], origin[1], origin[2] };
    if (paraboloidKey != this->ParaboloidKey || !this->ParaboloidArray)
    {
      this->BuildParaboloidCasters(setup.Position);
      this->ParaboloidKey = paraboloidKey;
    }
    const float mapSize[2] = { static_cast<float>(maps.Width), static_cast<float>(maps.Height) };
    program->SetUniformf("mapScale", static_cast<float>(maps.MapScale));
    program->SetUniformf("invMapScale", static_cast<float>(1.0 / maps.MapScale));
    program->SetUniformf("invFar", static_cast<float>(1.0 / maps.Far));
    program->SetUniform2f("mapSize", mapSize);
    glBindVertexArray(this->ParaboloidArray);
  }
  else
  {
    this->Casters.Bind(program);
  }
  program->SetUniformf("peelGap", static_cast<float>(std::max(self->Bias, 1e-6)));
}

//------------------------------------------------------------------------------
// Points the map program at one slot: the slot's paraboloid hemisphere buffer, or its view's
// matrix. Returns the number of vertices to draw.
GLsizei vtkPenumbraShadowMapShadows::Internals::BindSlot(
  vtkShaderProgram* program, const LightMaps& maps, int slot)
{
  // The midpoint pass draws with its own vertex array.
  glBindVertexArray(maps.Paraboloid ? this->ParaboloidArray : this->Casters.VertexArray);
  if (!maps.Paraboloid)
  {
    const View& view = maps.Views[static_cast<size_t>(slot)];
    float matrix[16];
    view.ToFloatMatrix(matrix);
    program->SetUniformMatrix4x4("lightMatrix", matrix);
    program->SetUniformi("perspective", view.Perspective ? 1 : 0);
    program->SetUniformf("invFar", static_cast<float>(1.0 / view.Far));
    return this->Casters.VertexCount;
  }
  const GLint posLoc = glGetAttribLocation(program->GetHandle(), "vertexLight");
  const GLint planeLoc = glGetAttribLocation(program->GetHandle(), "trianglePlane");
  glBindBuffer(GL_ARRAY_BUFFER, this->ParaboloidBuffers[slot]);
  const GLsizei stride = 7 * sizeof(float);
  if (posLoc >= 0)
  {
    glEnableVertexAttribArray(static_cast<GLuint>(posLoc));
    glVertexAttribPointer(static_cast<GLuint>(posLoc), 3, GL_FLOAT, GL_FALSE, stride, nullptr);
  }
  if (planeLoc >= 0)
  {
    glEnableVertexAttribArray(static_cast<GLuint>(planeLoc));
    glVertexAttribPointer(static_cast<GLuint>(planeLoc), 4, GL_FLOAT, GL_FALSE, stride,
      reinterpret_cast<const void*>(3 * sizeof(float)));
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  return this->ParaboloidCounts[slot];
}

//------------------------------------------------------------------------------
// Draws one slot's depth layers (the second, depth-peeled, for midpoint maps): with the GPU
// lookup and linear depth straight into the slot's compare texture, otherwise into the
// scratch layers, read back for the CPU lookup.
void vtkPenumbraShadowMapShadows::Internals::DrawSlotLayers(vtkPenumbraShadowMapShadows* self,
  vtkOpenGLState* ostate, vtkShaderProgram* program, GLsizei count, vtkTextureObject* slotTexture,
  LightMaps* maps, int slot)
{
  const bool gpuLookup = self->Lookup != LOOKUP_CPU;
  const bool midpoint = self->DepthMode == DEPTH_MIDPOINT;
  const size_t texels = static_cast<size_t>(maps->Width) * maps->Height;
  std::vector<float>& map = maps->Maps[static_cast<size_t>(slot)];
  map.resize(gpuLookup ? 0 : texels);
  for (int layer = 0; layer < (midpoint ? 2 : 1); ++layer)
  {
    this->FBO->AddDepthAttachment(
      gpuLookup && !midpoint ? slotTexture : this->DepthTextures[layer].Get());
    ostate->vtkglDrawBuffer(GL_NONE);
    ostate->vtkglReadBuffer(GL_NONE);
    const GLfloat one = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &one);
    program->SetUniformi("peel", layer);
    if (layer == 1)
    {
      this->DepthTextures[0]->Activate();
      program->SetUniformi("firstLayer", this->DepthTextures[0]->GetTextureUnit());
    }
    if (count > 0)
    {
      glDrawArrays(GL_TRIANGLES, 0, count);
    }
    if (layer == 1)
    {
      this->DepthTextures[0]->Deactivate();
    }
    if (gpuLookup)
    {
      continue; // the maps stay on the GPU
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    float* target = map.data();
    if (layer == 1)
    {
      this->SecondLayer.resize(texels);
      target = this->SecondLayer.data();
    }
    glReadPixels(0, 0, maps->Width, maps->Height, GL_DEPTH_COMPONENT, GL_FLOAT, target);
  }
}

//------------------------------------------------------------------------------
// Woo's midpoint (Brabec 2003, ch. 4.1.1) of a slot's two layers: on the GPU written as the
// slot's depth, on the CPU into its map. No second surface leaves the far value 1 as the
// second depth, so a lone surface stays lit by a half-range margin.
void vtkPenumbraShadowMapShadows::Internals::ResolveMidpoint(vtkPenumbraShadowMapShadows* self,
  vtkOpenGLRenderWindow* win, vtkShaderProgram* program, vtkTextureObject* slotTexture,
  LightMaps* maps, int slot)
{
  if (self->Lookup != LOOKUP_CPU)
  {
    vtkOpenGLQuadHelper& quad = *this->MidpointQuad;
    vtkOpenGLState* ostate = win->GetState();
    win->GetShaderCache()->ReadyShaderProgram(quad.Program);
    this->FBO->AddDepthAttachment(slotTexture);
    ostate->vtkglDepthFunc(GL_ALWAYS);
    this->DepthTextures[0]->Activate();
    this->DepthTextures[1]->Activate();
    quad.Program->SetUniformi("firstLayer", this->DepthTextures[0]->GetTextureUnit());
    quad.Program->SetUniformi("secondLayer", this->DepthTextures[1]->GetTextureUnit());
    quad.Render();
    this->DepthTextures[0]->Deactivate();
    this->DepthTextures[1]->Deactivate();
    ostate->vtkglDepthFunc(GL_LESS);
    // The map program is current again for the next slot.
    win->GetShaderCache()->ReadyShaderProgram(program);
    return;
  }
  std::vector<float>& map = maps->Maps[static_cast<size_t>(slot)];
  const float* second = this->SecondLayer.data();
  vtkSMPTools::For(0, static_cast<vtkIdType>(map.size()),
    [&](vtkIdType b, vtkIdType e)
    {
      for (vtkIdType i = b; i < e; ++i)
      {
        map[static_cast<size_t>(i)] = 0.5f * (map[static_cast<size_t>(i)] + second[i]);
      }
    });
}

//------------------------------------------------------------------------------
// The compare texture a slot's map is drawn into for the GPU lookup: the slot's kept texture
// while its size still fits, a new one otherwise; null for the CPU lookup.
vtkTextureObject* vtkPenumbraShadowMapShadows::Internals::SlotTexture(
  vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, LightMaps* maps, int slot)
{
  const bool gpuLookup = self->Lookup != LOOKUP_CPU;
  auto& kept = maps->Textures[static_cast<size_t>(slot)];
  if (kept &&
    (!gpuLookup || static_cast<int>(kept->GetWidth()) != maps->Width ||
      static_cast<int>(kept->GetHeight()) != maps->Height))
  {
    kept->ReleaseGraphicsResources(win);
    kept = nullptr;
  }
  if (gpuLookup && !kept)
  {
    kept = Internals::CompareTexture(win, maps->Width, maps->Height);
  }
  return kept;
}

//------------------------------------------------------------------------------
// Renders every slot a receiver needs (Brabec 2003, ch. 4-6) into the views PlanMaps()
// fitted: linear float depth, depth clamping, the midpoint layer on request; the maps stay on
// the GPU for the GPU lookup and are read back for the CPU one.
bool vtkPenumbraShadowMapShadows::Internals::RenderMaps(vtkPenumbraShadowMapShadows* self,
  vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry, const LightSetup& setup,
  const ReceiverExtent& extent, const int size[2], LightMaps* maps, std::string& error)
{
  const auto mapStart = Clock::now();
  const int slotMode = this->SlotMode(self, setup);
  const bool paraboloid = slotMode == SlotsParaboloid;
  const int slots = slotMode == SlotsCube ? 6 : (paraboloid ? 2 : 1);
  maps->Valid = false;
  maps->Width = size[0];
  maps->Height = size[1];
  maps->Paraboloid = paraboloid;
  maps->Maps.assign(static_cast<size_t>(slots), std::vector<float>());
  // GPU lookup: the slots' compare textures are kept and redrawn when their size still fits.
  for (size_t slot = static_cast<size_t>(slots); slot < maps->Textures.size(); ++slot)
  {
    if (maps->Textures[slot])
    {
      maps->Textures[slot]->ReleaseGraphicsResources(win);
    }
  }
  maps->Textures.resize(static_cast<size_t>(slots));
  vtkShaderProgram* program = this->MapProgram(self, win, setup, paraboloid);
  if (!program)
  {
    error = "the shadow map shaders do not compile or link on this OpenGL implementation";
    return false;
  }
  this->AllocateMaps(win, maps->Width, maps->Height);
  const bool midpoint = self->DepthMode == DEPTH_MIDPOINT;
  vtkOpenGLState* ostate = win->GetState();
  penumbra_light_views::MapRenderState renderState(
    ostate, this->FBO, maps->Width, maps->Height, false);
  this->BindCasters(self, program, geometry, setup, *maps);
  if (self->Lookup == LOOKUP_GPU && midpoint && !this->MidpointQuad)
  {
    this->MidpointQuad.reset(
      new vtkOpenGLQuadHelper(win, nullptr, vtkPenumbraShadowMapMidpointFS, ""));
    // Building it bound its program; the map program draws next.
    win->GetShaderCache()->ReadyShaderProgram(program);
  }
  for (int slot = 0; slot < slots; ++slot)
  {
    auto& texture = maps->Textures[static_cast<size_t>(slot)];
    if (!extent.Used[static_cast<size_t>(slot)])
    {
      if (texture)
      {
        texture->ReleaseGraphicsResources(win);
        texture = nullptr;
      }
      continue;
    }
    const GLsizei count = this->BindSlot(program, *maps, slot);
    vtkTextureObject* slotTexture = this->SlotTexture(self, win, maps, slot);
    this->DrawSlotLayers(self, ostate, program, count, slotTexture, maps, slot);
    if (midpoint)
    {
      this->ResolveMidpoint(self, win, program, slotTexture, maps, slot);
    }
    ++self->NumberOfMapRenders;
  }
  maps->Valid = true;
  self->MapTimeMs = ElapsedMs(mapStart);
  return true;
}

//------------------------------------------------------------------------------
// Per-sample lookup on the GPU for a CPU sample set (Brabec 2003, ch. 5: hardware depth
// compare): the pending samples as a compacted list, one fragment each, one draw per slot.
bool vtkPenumbraShadowMapShadows::Internals::LookupList(vtkPenumbraShadowMapShadows* self,
  const penumbra_light_views::FrameInputs& in, const LightSetup& setup, const LightMaps& m,
  const unsigned char* state, float* vis, std::string& error)
{
  vtkOpenGLRenderWindow* win = in.Window;
  const vtkIdType n = in.NumberOfSamples;
  const float* nrm = in.Normals;
  // ---- Per-sample lookup on the GPU (Brabec 2003, ch. 5: hardware depth compare): the
  // pending samples as a compacted list, one fragment each, one draw per slot.
  std::vector<vtkIdType>& list = this->List;
  list.clear();
  for (vtkIdType s = 0; s < n; ++s)
  {
    if (state[s] == Pending)
    {
      list.push_back(s);
    }
  }
  const vtkIdType count = static_cast<vtkIdType>(list.size());
  const int listWidth = static_cast<int>(std::min<vtkIdType>(count, 2048));
  const int listHeight = static_cast<int>((count + listWidth - 1) / listWidth);
  std::vector<float>& positions = this->ListPositionData;
  std::vector<float>& normals = this->ListNormalData;
  positions.assign(static_cast<size_t>(4) * listWidth * listHeight, 0.0f);
  normals.assign(positions.size(), 0.0f);
  vtkSMPTools::For(0, count,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        const vtkIdType s = list[static_cast<size_t>(i)];
        double p[3];
        SamplePoint(in, s, p);
        for (int c = 0; c < 3; ++c)
        {
          positions[static_cast<size_t>(4 * i + c)] = static_cast<float>(p[c]);
          normals[static_cast<size_t>(4 * i + c)] = nrm[3 * s + c];
        }
      }
    });
  if (!this->LookupFBO)
  {
    this->LookupFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->LookupFBO->SetContext(win);
    this->ListPositions = Internals::FloatTexture(win);
    this->ListNormals = Internals::FloatTexture(win);
    this->ListVisibility = Internals::FloatTexture(win);
  }
  for (vtkTextureObject* tex : { this->ListPositions.Get(), this->ListNormals.Get() })
  {
    tex->SetInternalFormat(GL_RGBA32F);
    tex->SetFormat(GL_RGBA);
    tex->SetDataType(GL_FLOAT);
  }
  this->ListPositions->Create2DFromRaw(listWidth, listHeight, 4, VTK_FLOAT, positions.data());
  this->ListNormals->Create2DFromRaw(listWidth, listHeight, 4, VTK_FLOAT, normals.data());
  this->ListVisibility->SetInternalFormat(GL_R32F);
  this->ListVisibility->SetFormat(GL_RED);
  this->ListVisibility->SetDataType(GL_FLOAT);
  this->ListVisibility->Allocate2D(listWidth, listHeight, 1, VTK_FLOAT);

  vtkOpenGLQuadHelper& quad = *this->LookupPrograms.Get(win, nullptr,
    ComposeShader(vtkPenumbraShadowMapLookupFS), this->Variant(self, setup, true, &m));
  win->GetShaderCache()->ReadyShaderProgram(quad.Program);
  vtkShaderProgram* program = quad.Program;
  if (!program || !program->GetCompiled())
  {
    error = "the shadow map lookup program does not compile or link on this OpenGL "
            "implementation (texelFetch of depth textures is required)";
    return false;
  }
  std::vector<float>& result = this->ListResult;
  result.assign(static_cast<size_t>(listWidth) * listHeight, 1.0f);
  {
    vtkOpenGLState* ostate = win->GetState();
    vtkOpenGLState::ScopedglClearColor clearColor(ostate);
    penumbra_light_views::QuadPassState pass(
      ostate, this->LookupFBO, { this->ListVisibility.Get() }, listWidth, listHeight);
    ostate->vtkglClearColor(1.0, 1.0, 1.0, 1.0);
    ostate->vtkglClear(GL_COLOR_BUFFER_BIT);

    this->ListPositions->Activate();
    this->ListNormals->Activate();
    program->SetUniformi("samplePositions", this->ListPositions->GetTextureUnit());
    program->SetUniformi("sampleNormals", this->ListNormals->GetTextureUnit());
    program->SetUniformi("sampleCount", static_cast<int>(count));
    program->SetUniformi("listWidth", listWidth);
    this->SetCompareUniforms(self, program, setup, m);
    for (size_t slot = 0; slot < m.Textures.size(); ++slot)
    {
      vtkTextureObject* map = m.Textures[slot];
      if (!map)
      {
        continue; // no pending sample falls into this slot
      }
      SetSlotUniforms(program, m, static_cast<int>(slot));
      RawDepthBinding raw(win, this->RawDepthSampler, map);
      program->SetUniformi("depthMap", raw.GetUnit());
      quad.Render();
    }
    this->ListPositions->Deactivate();
    this->ListNormals->Deactivate();
    this->LookupFBO->ActivateReadBuffer(0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, listWidth, listHeight, GL_RED, GL_FLOAT, result.data());
  }
  for (vtkIdType i = 0; i < count; ++i)
  {
    vis[list[static_cast<size_t>(i)]] = result[static_cast<size_t>(i)];
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::Internals::LookupCPU(vtkPenumbraShadowMapShadows* self,
  const penumbra_light_views::FrameInputs& in, const LightSetup& setup, const LightMaps& m,
  const unsigned char* state, float* vis)
{
  const vtkIdType n = in.NumberOfSamples;
  const float* nrm = in.Normals;
  const int width = m.Width, height = m.Height;
  const int slotMode = this->SlotMode(self, setup);
  const int radius = TapRadius(self);
  const bool bilinear = self->Filter == FILTER_BILINEAR;
  const double slopeBias = self->SlopeBias * (1.0 + BiasRadius(self));
  const double constantBias = self->Bias;
  // ---- Per-sample lookup on the CPU, double precision (see the class description).
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType s = begin; s < end; ++s)
      {
        if (state[s] != Pending)
        {
          continue;
        }
        double p[3];
        SamplePoint(in, s, p);
        const int slot = SlotOf(setup, slotMode, p);
        const std::vector<float>& map = m.Maps[static_cast<size_t>(slot)];
        if (map.empty())
        {
          continue; // cannot happen: every pending sample's slot was rendered
        }
        double ms = 0.0, mt = 0.0, depth = 0.0, footprint = 0.0, depthPerLength = 1.0;
        double toLight[3] = { 0, 0, 0 };
        if (m.Paraboloid)
        {
          double q[3] = { p[0] - m.Centre[0], p[1] - m.Centre[1], p[2] - m.Centre[2] };
          const double distance = Norm3(q);
          if (!(distance > 0.0))
          {
            continue;
          }
          for (int c = 0; c < 3; ++c)
          {
            q[c] /= distance;
            toLight[c] = -q[c];
          }
          double xy[2];
          ParaboloidFromDirection(q, xy);
          ms = xy[0] * m.MapScale;
          mt = xy[1] * m.MapScale;
          depth = distance / m.Far;
          depthPerLength = 1.0 / m.Far;
          // d(angle)/d(radius) = 2 / (1 + r^2) on the paraboloid.
          footprint =
            distance * 2.0 / (1.0 + xy[0] * xy[0] + xy[1] * xy[1]) * 2.0 / (width * m.MapScale);
        }
        else
        {
          const View& view = m.Views[static_cast<size_t>(slot)];
          if (!view.Project(p, ms, mt, depth))
          {
            continue;
          }
          if (view.Perspective)
          {
            depthPerLength = 1.0 / view.Far;
            footprint = 2.0 * view.TanHalf * depth * view.Far / std::min(width, height);
            for (int c = 0; c < 3; ++c)
            {
              toLight[c] = setup.Position[c] - p[c];
            }
          }
          else
          {
            depthPerLength = Norm3(view.Row[2]);
            footprint = OrthoFootprint(view, m);
            std::copy(setup.Direction, setup.Direction + 3, toLight);
          }
        }
        double normal[3] = { nrm[3 * s], nrm[3 * s + 1], nrm[3 * s + 2] };
        vtkMath::Normalize(normal);
        vtkMath::Normalize(toLight);
        const double cosine = std::max(1e-9, vtkMath::Dot(normal, toLight));
        const double tangent =
          std::min(MaxTangent, std::sqrt(std::max(0.0, 1.0 - cosine * cosine)) / cosine);
        const double threshold =
          depth - constantBias - slopeBias * footprint * tangent * depthPerLength;
        if (bilinear)
        {
          vis[s] = static_cast<float>(BilinearLookup(map, width, height, ms, mt, threshold));
          continue;
        }
        const int ix =
          std::min(width - 1, std::max(0, static_cast<int>(std::floor((ms * 0.5 + 0.5) * width))));
        const int iy = std::min(
          height - 1, std::max(0, static_cast<int>(std::floor((mt * 0.5 + 0.5) * height))));
        int litTaps = 0, taps = 0;
        for (int dy = -radius; dy <= radius; ++dy)
        {
          // PCF stays inside the map: it never reads across a cube face or paraboloid rim.
          const int y = std::min(height - 1, std::max(0, iy + dy));
          for (int dx = -radius; dx <= radius; ++dx)
          {
            const int x = std::min(width - 1, std::max(0, ix + dx));
            litTaps += map[static_cast<size_t>(y) * width + x] >= threshold;
            ++taps;
          }
        }
        vis[s] = static_cast<float>(litTaps) / static_cast<float>(taps);
      }
    });
}

//------------------------------------------------------------------------------
// The uniforms every slot shares (vtkPenumbraShadowMapCompare.glsl).
void vtkPenumbraShadowMapShadows::Internals::SetCompareUniforms(vtkPenumbraShadowMapShadows* self,
  vtkShaderProgram* program, const LightSetup& setup, const LightMaps& m, const std::string& suffix)
{
  auto name = [&suffix](const char* base) { return base + suffix; };
  penumbra_light_views::SetLightUniforms(program, setup, suffix);
  program->SetUniformf(name("mapScale").c_str(), static_cast<float>(m.MapScale));
  const float mapSize[2] = { static_cast<float>(m.Width), static_cast<float>(m.Height) };
  program->SetUniform2f(name("mapSize").c_str(), mapSize);
  program->SetUniformf(name("constantBias").c_str(), static_cast<float>(self->Bias));
  program->SetUniformf(
    name("slopeBias").c_str(), static_cast<float>(self->SlopeBias * (1.0 + BiasRadius(self))));
  program->SetUniformf(name("maxTangent").c_str(), static_cast<float>(MaxTangent));
  this->SetSoftUniforms(self, program, m);
}

//------------------------------------------------------------------------------
// The soft lookups' uniforms (vtkPenumbraShadowMapSoft.glsl): the taps, the search depth,
// the tap radius in NDC and the single-sample mode's radii. The light's extents are set by
// SetAreaUniforms().
void vtkPenumbraShadowMapShadows::Internals::SetSoftUniforms(
  vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program, const LightMaps& m)
{
  if (SoftMode(self, m) == AREA_NONE)
  {
    return;
  }
  program->SetUniformi("searchTaps", self->SearchTaps);
  program->SetUniformi("filterTaps", self->FilterTaps);
  program->SetUniformf("searchDepth", static_cast<float>(self->SearchDepth));
  const int side = std::max(1, std::min(m.Width, m.Height));
  program->SetUniformf("maxRadius", static_cast<float>(2.0 * self->MaxRadius / side));
  program->SetUniformi("physical", self->Physical ? 1 : 0);
  const float radii[3] = { static_cast<float>(self->RScale), static_cast<float>(self->RBias),
    static_cast<float>(self->RShrink) };
  program->SetUniform3f("thesisRadius", radii);
}

//------------------------------------------------------------------------------
// An area light's centre and half extents (vtkPenumbraShadowMapSoft.glsl), also when no map
// is read: the horizon term applies to samples without casters too.
void vtkPenumbraShadowMapShadows::Internals::SetAreaUniforms(
  vtkShaderProgram* program, const LightSetup& setup)
{
  if (!setup.Area)
  {
    return;
  }
  penumbra_light_views::SetLightUniforms(program, setup);
  float hu[3], hv[3];
  for (int c = 0; c < 3; ++c)
  {
    hu[c] = static_cast<float>(setup.HalfU[c]);
    hv[c] = static_cast<float>(setup.HalfV[c]);
  }
  program->SetUniform3f("lightU", hu);
  program->SetUniform3f("lightV", hv);
}

//------------------------------------------------------------------------------
// One light of a GPU-resident frame: the maps are fitted to the G-buffer's receivers on the
// GPU (a tile reduction, read back as a few kilobytes) when they must be rebuilt, and looked
// up straight from the G-buffer into the light's visibility channel. No sample is read back.
bool vtkPenumbraShadowMapShadows::Internals::FrameLight(
  vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int k, std::string& error)
{
  const auto start = Clock::now();
  self->NumberOfViews = 0;
  self->MapTimeMs = self->LookupTimeMs = 0.0;
  vtkLight* light = frame->GetShadowedLight(k);
  vtkPenumbraSceneGeometry* geometry = frame->GetGeometry();
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  if (!light || !geometry || !win)
  {
    error = "the frame has no light, geometry or OpenGL window";
    return false;
  }
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  if (area && self->AreaLightMode == AREA_NONE)
  {
    error = "area and linear lights need a soft-shadow technique (gears, raytraced, pcss, "
            "single-sample-soft)";
    return false;
  }
  double origin[3];
  geometry->GetOrigin(origin);
  LightSetup setup;
  if (!setup.Read(light, origin, error) || (area && !AreaAsSpot(area, setup, error)))
  {
    return false;
  }
  const bool anyCaster = !setup.Off && this->UpdateCasters(self, win, geometry);
  win->MakeCurrent();
  LightMaps* maps = nullptr;
  if (anyCaster)
  {
    const double noShift[3] = { 0, 0, 0 };
    const double samples = static_cast<double>(frame->GetWidth()) * frame->GetHeight();
    std::vector<double> key = this->MapKey(
      self, frame->GetRenderer(), light, geometry, noShift, -samples, frame->GetNumberOfLayers());
    maps = &penumbra_light_views::LightCacheEntry(this->Cache, light);
    if (!maps->Valid || maps->Key != key)
    {
      ReceiverExtent extent;
      extent.CollectPlane = self->FitRectangle != FIT_AXIS;
      extent.Square = self->FitRectangle == FIT_SQUARE;
      if (FitsScene(self, frame->GetRenderer(), geometry))
      {
        ExtentFromScene(setup, this->SlotMode(self, setup), geometry, this->Chunks, extent);
      }
      else if (!this->ReduceExtent(self, frame, setup, extent, error))
      {
        return false;
      }
      maps->Key.swap(key);
      auto estimate = [&](const View& view, std::vector<float>& needs, std::string& why)
      { return this->EstimateFrame(frame, setup, view, self->AnalysisStep, needs, why); };
      int size[2];
      if (!this->PlanMaps(self, setup, extent, estimate, maps, size, error) ||
        !this->RenderMaps(self, win, geometry, setup, extent, size, maps, error))
      {
        return false;
      }
    }
    self->LastMapSize[0] = maps->Width;
    self->LastMapSize[1] = maps->Height;
    self->NumberOfViews = CountViews(*maps);
  }
  const auto lookupStart = Clock::now();
  bool ok = true;
  if (self->Lookup == LOOKUP_GPU && maps && CountViews(*maps) == 1 && !maps->Textures.empty() &&
    maps->Textures[0] && SoftMode(self, *maps) == AREA_NONE &&
    !vtkPenumbraGoniometricLight::SafeDownCast(light))
  {
    frame->SetShaderLookup(k, this->ShaderLookup(self, setup, *maps));
  }
  else
  {
    ok = this->LookupFrame(self, frame, k, setup, anyCaster, maps, error);
  }
  self->LookupTimeMs = ElapsedMs(lookupStart);
  self->LastTimeMs = ElapsedMs(start);
  return ok;
}

//------------------------------------------------------------------------------
// The GPU lookup of a light with one map (directional and spot lights), made by the
// receivers' own fragment shaders while they are shaded (vtkPenumbraShadowMapReceive.glsl),
// as VTK's vtkShadowMapPass does: no full-screen pass, no visibility texture. LookupFrame()
// writes the same values from the G-buffer when they are asked for.
std::shared_ptr<vtkPenumbraFrame::ShaderLookup>
vtkPenumbraShadowMapShadows::Internals::ShaderLookup(
  vtkPenumbraShadowMapShadows* self, const LightSetup& setup, const LightMaps& maps)
{
  class MapLookup : public vtkPenumbraFrame::ShaderLookup
  {
  public:
    vtkSmartPointer<vtkPenumbraShadowMapShadows> Self;
    Internals* Impl = nullptr;
    LightSetup Setup;
    vtkWeakPointer<vtkLight> Light;
    LookupVariant Variant;
    std::unique_ptr<RawDepthBinding> Raw; // between Activate() and Deactivate()

    // The light's cache entry while it still holds this light's map.
    const LightMaps* Maps() const
    {
      for (const LightMaps& m : this->Impl->Cache)
      {
        if (this->Light && m.Light == this->Light && m.Valid && !m.Textures.empty() &&
          m.Textures[0])
        {
          return &m;
        }
      }
      return nullptr;
    }
    std::string GetKey() override { return this->Variant.Key(); }
    std::string GetSource(const std::string& suffix) override
    {
      return penumbra_light_views::SuffixGlobals(
        this->Variant.Specialize(ComposeShader(vtkPenumbraShadowMapReceive)), suffix);
    }
    void Activate() override
    {
      const LightMaps* m = this->Maps();
      if (m && this->Impl->Window)
      {
        this->Raw.reset(
          new RawDepthBinding(this->Impl->Window, this->Impl->RawDepthSampler, m->Textures[0]));
      }
    }
    void Deactivate() override { this->Raw.reset(); }
    void SetUniforms(vtkShaderProgram* program, const std::string& suffix) override
    {
      const LightMaps* m = this->Maps();
      if (!m)
      {
        return;
      }
      penumbra_light_views::SetClassifyUniforms(program, this->Setup, suffix);
      this->Impl->SetCompareUniforms(this->Self, program, this->Setup, *m, suffix);
      SetSlotUniforms(program, *m, 0, suffix);
      if (this->Raw)
      {
        program->SetUniformi(("depthMap" + suffix).c_str(), this->Raw->GetUnit());
      }
    }
    bool Resolve(vtkPenumbraFrame* frame, std::string& error) override
    {
      const LightMaps* m = this->Maps();
      if (!m)
      {
        error = "its shadow map was released";
        return false;
      }
      return this->Impl->LookupFrame(this->Self, frame, 0, this->Setup, true, m, error);
    }
  };
  auto lookup = std::make_shared<MapLookup>();
  lookup->Self = self;
  lookup->Impl = this;
  lookup->Setup = setup;
  lookup->Light = maps.Light;
  lookup->Variant = this->Variant(self, setup, true, &maps);
  return lookup;
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
    penumbra_light_views::QuadPassState pass(win->GetState(), this->ExtentFBO, targets, tw, th);
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

//------------------------------------------------------------------------------
// The lookup on every layer's G-buffer, into light k's visibility channel: one draw per
// rendered slot (the first also writes the samples the facing rules decide), or one draw
// without a map when nothing is pending.
bool vtkPenumbraShadowMapShadows::Internals::LookupFrame(vtkPenumbraShadowMapShadows* self,
  vtkPenumbraFrame* frame, int k, const LightSetup& setup, bool anyCaster, const LightMaps* maps,
  std::string& error)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  vtkOpenGLQuadHelper* quad = this->FramePrograms.Get(win, vtkPenumbraFrame::GetSurfaceQuadVS(),
    ComposeShader(vtkPenumbraShadowMapFrameFS), this->Variant(self, setup, anyCaster, maps));
  if (!this->NoMap)
  {
    // The depth sampler must never share a unit with the G-buffer's samplers, even when
    // no map is read: a 1 x 1 stand-in is bound when there is none.
    this->NoMap = Internals::CompareTexture(win, 1, 1);
  }
  vtkShaderProgram* program = quad->Program;
  if (!program || !program->GetCompiled())
  {
    error = "the shadow map lookup program does not compile on this OpenGL implementation "
            "(texelFetch of depth textures and GL_ARB_gpu_shader_fp64 are required)";
    return false;
  }
  std::vector<int> slots;
  for (size_t slot = 0; maps && slot < maps->Textures.size(); ++slot)
  {
    if (maps->Textures[slot])
    {
      slots.push_back(static_cast<int>(slot));
    }
  }
  // Soft lookups with adaptive sampling: the block corners first.
  const int block = maps && SoftMode(self, *maps) != AREA_NONE ? self->AdaptiveBlock : 1;
  for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
  {
    if (block > 1)
    {
      const int cw = (frame->GetWidth() - 1) / block + 2;
      const int ch = (frame->GetHeight() - 1) / block + 2;
      if (!this->CoarseValues)
      {
        this->CoarseFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
        this->CoarseFBO->SetContext(win);
        this->CoarseValues = Internals::FloatTexture(win);
        this->CoarseValues->SetInternalFormat(GL_RGBA32F);
        this->CoarseValues->SetFormat(GL_RGBA);
        this->CoarseValues->SetDataType(GL_FLOAT);
      }
      if (static_cast<int>(this->CoarseValues->GetWidth()) != cw ||
        static_cast<int>(this->CoarseValues->GetHeight()) != ch)
      {
        this->CoarseValues->Allocate2D(cw, ch, 4, VTK_FLOAT);
      }
      penumbra_light_views::QuadPassState pass(
        win->GetState(), this->CoarseFBO, { this->CoarseValues.Get() }, cw, ch);
      this->DrawLookup(self, frame, layer, setup, maps, slots, quad, 1, block);
    }
    vtkPenumbraFrame::VisibilityTarget target = frame->BindVisibilityTarget(layer, k);
    if (block > 1)
    {
      this->CoarseValues->Activate();
      win->GetShaderCache()->ReadyShaderProgram(program);
      program->SetUniformi("coarseValues", this->CoarseValues->GetTextureUnit());
    }
    this->DrawLookup(self, frame, layer, setup, maps, slots, quad, block > 1 ? 2 : 0, block);
    if (block > 1)
    {
      this->CoarseValues->Deactivate();
    }
  }
  return true;
}

//------------------------------------------------------------------------------
// One lookup draw per rendered slot on one layer's G-buffer into the bound target (the
// first also writes the samples the facing rules decide); `adaptivePass` as in
// vtkPenumbraShadowMapSoft.glsl.
void vtkPenumbraShadowMapShadows::Internals::DrawLookup(vtkPenumbraShadowMapShadows* self,
  vtkPenumbraFrame* frame, int layer, const LightSetup& setup, const LightMaps* maps,
  const std::vector<int>& slots, vtkOpenGLQuadHelper* quad, int adaptivePass, int block)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  vtkShaderProgram* program = quad->Program;
  vtkPenumbraViewSamplesPass* gbuffer = frame->GetLayer(layer);
  win->GetShaderCache()->ReadyShaderProgram(program);
  gbuffer->GetPositionTexture()->Activate();
  gbuffer->GetNormalTexture()->Activate();
  program->SetUniformi("samplePositions", gbuffer->GetPositionTexture()->GetTextureUnit());
  program->SetUniformi("sampleNormals", gbuffer->GetNormalTexture()->GetTextureUnit());
  program->SetUniformi("adaptivePass", adaptivePass);
  program->SetUniformi("adaptiveBlock", block);
  const int image[2] = { frame->GetWidth(), frame->GetHeight() };
  program->SetUniform2i("adaptiveImage", image);
  penumbra_light_views::SetClassifyUniforms(program, setup);
  if (maps)
  {
    this->SetCompareUniforms(self, program, setup, *maps);
  }
  this->SetAreaUniforms(program, setup);
  for (size_t i = 0; i < std::max<size_t>(1, slots.size()); ++i)
  {
    vtkTextureObject* map =
      slots.empty() ? this->NoMap.Get() : maps->Textures[static_cast<size_t>(slots[i])].Get();
    program->SetUniformi("writeDecided", i == 0 ? 1 : 0);
    if (slots.empty())
    {
      program->SetUniformi("slot", -1);
    }
    else
    {
      SetSlotUniforms(program, *maps, slots[i]);
    }
    RawDepthBinding raw(win, this->RawDepthSampler, map);
    program->SetUniformi("depthMap", raw.GetUnit());
    quad->Render();
  }
  gbuffer->GetPositionTexture()->Deactivate();
  gbuffer->GetNormalTexture()->Deactivate();
}

//------------------------------------------------------------------------------
bool vtkPenumbraShadowMapShadows::GetMapSize(vtkLight* light, int size[2], double need[2])
{
  for (const LightMaps& maps : this->Impl->Cache)
  {
    if (light && maps.Light == light && maps.Valid)
    {
      size[0] = maps.Width;
      size[1] = maps.Height;
      std::copy(maps.Need, maps.Need + 2, need);
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
bool vtkPenumbraShadowMapShadows::GetMapFootprint(vtkLight* light, double sides[2])
{
  for (const LightMaps& maps : this->Impl->Cache)
  {
    if (light && maps.Light == light && maps.Valid && maps.Views.size() == 1 &&
      !maps.Views[0].Perspective && !maps.Paraboloid)
    {
      // Orthographic rows: NDC x = Row[a] . p, so a side of 2 NDC units is 2 / |Row[a]|.
      for (int a = 0; a < 2; ++a)
      {
        sides[a] = 2.0 / Norm3(maps.Views[0].Row[a]);
      }
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "ResolutionMode: " << this->ResolutionMode << "\n";
  os << indent << "MaxResolution: " << this->MaxResolution << "\n";
  os << indent << "Coverage: " << this->Coverage << "\n";
  os << indent << "AnalysisStep: " << this->AnalysisStep << "\n";
  os << indent << "Filter: "
     << (this->Filter == FILTER_PCF           ? "pcf"
            : this->Filter == FILTER_BILINEAR ? "bilinear"
                                              : "none")
     << "\n";
  os << indent << "PCFKernel: " << this->PCFKernel << "\n";
  os << indent << "Bias: " << this->Bias << "\n";
  os << indent << "SlopeBias: " << this->SlopeBias << "\n";
  os << indent << "DepthMode: " << (this->DepthMode == DEPTH_MIDPOINT ? "midpoint" : "linear")
     << "\n";
  os << indent << "FitRectangle: "
     << (this->FitRectangle == FIT_SQUARE
            ? "square"
            : (this->FitRectangle == FIT_MINIMUM ? "minimum" : "axis"))
     << "\n";
  os << indent << "PointMode: " << (this->PointMode == POINT_PARABOLOID ? "paraboloid" : "cube")
     << "\n";
  os << indent << "NumberOfMapRenders: " << this->NumberOfMapRenders << "\n";
  os << indent << "NumberOfViews: " << this->NumberOfViews << "\n";
  os << indent << "NumberOfUploads: " << this->NumberOfUploads << "\n";
  os << indent << "MapTimeMs: " << this->MapTimeMs << "\n";
  os << indent << "LookupTimeMs: " << this->LookupTimeMs << "\n";
}

//------------------------------------------------------------------------------
const char* vtkPenumbraShadowMapShadows::GetTechniqueNameFor(vtkLight* light)
{
  return this->AreaLightMode != AREA_NONE && !vtkPenumbraAreaLight::SafeDownCast(light)
    ? "shadowmap"
    : this->GetTechniqueName();
}
