#include "vtkPenumbraSceneCasters.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace penumbra_scene
{
namespace
{
constexpr double Pi = 3.14159265358979323846;
}

//------------------------------------------------------------------------------
bool Inside(const Planes& planes, const Vec3& x)
{
  for (const Plane& p : planes)
  {
    if (!(PlaneValue(p, x) >= 0.0))
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool ClipSegment(const Vec3& a, const Vec3& b, const Planes& planes, double& t0, double& t1)
{
  for (const Plane& p : planes)
  {
    const double fa = PlaneValue(p, a), fb = PlaneValue(p, b);
    if (fa >= 0.0 && fb >= 0.0)
    {
      continue;
    }
    if (fa < 0.0 && fb < 0.0)
    {
      return false;
    }
    const double t = fa / (fa - fb); // where the value is zero
    if (fa < 0.0)
    {
      t0 = std::max(t0, t);
    }
    else
    {
      t1 = std::min(t1, t);
    }
    if (!(t0 < t1))
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
BaryPolygon WholeTriangle()
{
  return { { 0.0, 0.0 }, { 1.0, 0.0 }, { 0.0, 1.0 } };
}

//------------------------------------------------------------------------------
void ClipBary(BaryPolygon& polygon, const double f[3], BaryPolygon& scratch)
{
  auto value = [f](const Bary& p) { return f[0] + (f[1] - f[0]) * p[0] + (f[2] - f[0]) * p[1]; };
  scratch.clear();
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i)
  {
    const Bary& p = polygon[i];
    const Bary& q = polygon[(i + 1) % n];
    const double fp = value(p), fq = value(q);
    if (fp >= 0.0)
    {
      scratch.push_back(p);
    }
    if ((fp >= 0.0) != (fq >= 0.0))
    {
      const double t = fp / (fp - fq);
      scratch.push_back({ p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]) });
    }
  }
  if (scratch.size() < 3)
  {
    scratch.clear();
  }
  polygon.swap(scratch);
}

//------------------------------------------------------------------------------
void PlaneCorners(const Plane& p, const Vec3 v[3], double f[3])
{
  for (int k = 0; k < 3; ++k)
  {
    f[k] = PlaneValue(p, v[k]);
  }
}

//------------------------------------------------------------------------------
void AppendBaryPolygon(const Vec3 v[3], const BaryPolygon& polygon, vtkIdType cell, vtkIdType owner,
  unsigned char role, TriangleList& out)
{
  if (polygon.size() < 3)
  {
    return;
  }
  auto at = [v](const Bary& b) { return v[0] + b[0] * (v[1] - v[0]) + b[1] * (v[2] - v[0]); };
  const std::uint32_t first = out.AddPoint(at(polygon[0]));
  std::uint32_t previous = out.AddPoint(at(polygon[1]));
  for (size_t i = 1; i + 1 < polygon.size(); ++i)
  {
    const std::uint32_t next = out.AddPoint(at(polygon[i + 1]));
    out.AddIndexed(first, previous, next, cell, owner, role);
    previous = next;
  }
}

namespace
{
// A unit vector perpendicular to the unit vector w, and a second one completing a
// right-handed frame (u, v, w).
void Frame(const Vec3& w, Vec3& u, Vec3& v)
{
  const Vec3 helper = std::fabs(w.x) <= std::fabs(w.y) && std::fabs(w.x) <= std::fabs(w.z)
    ? Vec3(1, 0, 0)
    : (std::fabs(w.y) <= std::fabs(w.z) ? Vec3(0, 1, 0) : Vec3(0, 0, 1));
  u = glm::normalize(glm::cross(helper, w));
  v = glm::cross(w, u);
}
}

//------------------------------------------------------------------------------
double TubeCircumradius(double diameter)
{
  // A convex section's mean width is its perimeter over pi: 3 sqrt(3) R / pi for a regular
  // triangle. Its width then ranges over [1.5 R, sqrt(3) R], as close to round (the same
  // ratio, 2 / sqrt(3)) as a hexagon's, with 8 triangles per segment instead of 20.
  return Pi * diameter / (3.0 * std::sqrt(3.0));
}

//------------------------------------------------------------------------------
void AppendTube(const Vec3& a, const Vec3& b, double diameter, vtkIdType cell, TriangleList& out)
{
  const Vec3 axis = b - a;
  const double length = glm::length(axis);
  if (!(diameter > 0.0) || !std::isfinite(diameter) || !(length > 0.0) || !std::isfinite(length))
  {
    return;
  }
  Vec3 u, v;
  Frame(axis / length, u, v);
  const double r = TubeCircumradius(diameter);
  std::uint32_t ra[3], rb[3]; // the ring around a, and around b
  for (int k = 0; k < 3; ++k)
  {
    const double angle = 2.0 * k * Pi / 3.0;
    const Vec3 ring = r * (std::cos(angle) * u + std::sin(angle) * v);
    ra[k] = out.AddPoint(a + ring);
    rb[k] = out.AddPoint(b + ring);
  }
  for (int k = 0; k < 3; ++k)
  {
    const int j = (k + 1) % 3;
    out.AddIndexed(ra[k], ra[j], rb[j], cell, -1, ROLE_CASTS); // outward: (u, v, axis) right-handed
    out.AddIndexed(ra[k], rb[j], rb[k], cell, -1, ROLE_CASTS);
  }
  out.AddIndexed(ra[0], ra[2], ra[1], cell, -1, ROLE_CASTS);
  out.AddIndexed(rb[0], rb[1], rb[2], cell, -1, ROLE_CASTS);
}

//------------------------------------------------------------------------------
double PointSolidCircumradius(double diameter)
{
  // A convex body's mean shadow area is a quarter of its surface: 2 sqrt(3) e^2 / 4 for an
  // octahedron of edge e = sqrt(2) R, set equal to the disc's pi d^2 / 4.
  return diameter * std::sqrt(Pi / (4.0 * std::sqrt(3.0)));
}

//------------------------------------------------------------------------------
void AppendPointSolid(const Vec3& c, double diameter, vtkIdType cell, TriangleList& out)
{
  if (!(diameter > 0.0) || !std::isfinite(diameter))
  {
    return;
  }
  const double r = PointSolidCircumradius(diameter);
  // The six corners: +x, -x, +y, -y, +z, -z.
  std::uint32_t corner[6];
  for (int k = 0; k < 6; ++k)
  {
    Vec3 offset(0.0);
    offset[k / 2] = (k % 2) ? -r : r;
    corner[k] = out.AddPoint(c + offset);
  }
  for (int s = 0; s < 8; ++s)
  {
    const std::uint32_t x = corner[(s & 1) ? 1 : 0], y = corner[(s & 2) ? 3 : 2],
                        z = corner[(s & 4) ? 5 : 4];
    // (x, y, z) faces along (sx, sy, sz) when sx sy sz = 1; swap two corners otherwise.
    const bool even = (((s & 1) != 0) + ((s & 2) != 0) + ((s & 4) != 0)) % 2 == 0;
    if (even)
    {
      out.AddIndexed(x, y, z, cell, -1, ROLE_CASTS);
    }
    else
    {
      out.AddIndexed(x, z, y, cell, -1, ROLE_CASTS);
    }
  }
}

//------------------------------------------------------------------------------
void AppendEdgeStrip(const Vec3& a, const Vec3& b, const Vec3& inside, const Vec3& n,
  double halfWidth, vtkIdType cell, vtkIdType owner, TriangleList& out)
{
  const Vec3 edge = b - a;
  Vec3 out3 = glm::cross(edge, n);
  const double length = glm::length(out3);
  if (!(halfWidth > 0.0) || !std::isfinite(halfWidth) || !(length > 0.0) || !std::isfinite(length))
  {
    return;
  }
  out3 /= length;
  if (glm::dot(out3, inside - a) > 0.0)
  {
    out3 = -out3; // away from the polygon
  }
  const Vec3 d = halfWidth * out3;
  const std::uint32_t pa = out.AddPoint(a), pb = out.AddPoint(b), pbd = out.AddPoint(b + d),
                      pad = out.AddPoint(a + d);
  out.AddIndexed(pa, pb, pbd, cell, owner, ROLE_CASTS);
  out.AddIndexed(pa, pbd, pad, cell, owner, ROLE_CASTS);
}
}
