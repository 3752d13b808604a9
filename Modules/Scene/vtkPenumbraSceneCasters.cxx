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
bool IsDegenerate(const double* a, const double* b, const double* c)
{
  const Vec3 pa(a[0], a[1], a[2]), pb(b[0], b[1], b[2]), pc(c[0], c[1], c[2]);
  const Vec3 e1 = pb - pa, e2 = pc - pa, e3 = pc - pb;
  const double longest = std::max({ glm::dot(e1, e1), glm::dot(e2, e2), glm::dot(e3, e3) });
  return longest == 0.0 || glm::length(glm::cross(e1, e2)) <= 1e-12 * longest;
}

//------------------------------------------------------------------------------
void TriangleList::Add(const double* a, const double* b, const double* c, vtkIdType cell,
  vtkIdType owner, unsigned char role)
{
  this->World.insert(this->World.end(), a, a + 3);
  this->World.insert(this->World.end(), b, b + 3);
  this->World.insert(this->World.end(), c, c + 3);
  this->CellIds.push_back(cell);
  this->Owners.push_back(owner);
  this->Roles.push_back(role);
  if (IsDegenerate(a, b, c))
  {
    ++this->Degenerate;
  }
}

//------------------------------------------------------------------------------
void TriangleList::Add(
  const Vec3& a, const Vec3& b, const Vec3& c, vtkIdType cell, vtkIdType owner, unsigned char role)
{
  const double pa[3] = { a.x, a.y, a.z }, pb[3] = { b.x, b.y, b.z }, pc[3] = { c.x, c.y, c.z };
  this->Add(pa, pb, pc, cell, owner, role);
}

//------------------------------------------------------------------------------
void TriangleList::Reserve(vtkIdType count)
{
  const size_t n = static_cast<size_t>(count);
  if (n > this->CellIds.capacity())
  {
    // Geometric growth, as push_back would, without the copies of every step.
    const size_t grown = std::max(n, this->CellIds.capacity() + this->CellIds.capacity() / 2);
    this->World.reserve(9 * grown);
    this->CellIds.reserve(grown);
    this->Owners.reserve(grown);
    this->Roles.reserve(grown);
  }
}

//------------------------------------------------------------------------------
void TriangleList::Append(const TriangleList& other, vtkIdType ownerShift)
{
  this->World.insert(this->World.end(), other.World.begin(), other.World.end());
  this->CellIds.insert(this->CellIds.end(), other.CellIds.begin(), other.CellIds.end());
  this->Roles.insert(this->Roles.end(), other.Roles.begin(), other.Roles.end());
  for (vtkIdType owner : other.Owners)
  {
    this->Owners.push_back(owner >= 0 ? owner + ownerShift : owner);
  }
  this->Degenerate += other.Degenerate;
}

//------------------------------------------------------------------------------
void TriangleList::Clear()
{
  this->World.clear();
  this->CellIds.clear();
  this->Owners.clear();
  this->Roles.clear();
  this->Degenerate = 0;
}

//------------------------------------------------------------------------------
bool TriangleList::operator==(const TriangleList& o) const
{
  return this->World == o.World && this->CellIds == o.CellIds && this->Owners == o.Owners &&
    this->Roles == o.Roles;
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
  auto at = [v](const Bary& b) { return v[0] + b[0] * (v[1] - v[0]) + b[1] * (v[2] - v[0]); };
  for (size_t i = 1; i + 1 < polygon.size(); ++i)
  {
    out.Add(at(polygon[0]), at(polygon[i]), at(polygon[i + 1]), cell, owner, role);
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
  Vec3 ring[3];
  for (int k = 0; k < 3; ++k)
  {
    const double angle = 2.0 * k * Pi / 3.0;
    ring[k] = r * (std::cos(angle) * u + std::sin(angle) * v);
  }
  for (int k = 0; k < 3; ++k)
  {
    const Vec3& p = ring[k];
    const Vec3& q = ring[(k + 1) % 3];
    out.Add(a + p, a + q, b + q, cell, -1, ROLE_CASTS); // outward: (u, v, axis) right-handed
    out.Add(a + p, b + q, b + p, cell, -1, ROLE_CASTS);
  }
  out.Add(a + ring[0], a + ring[2], a + ring[1], cell, -1, ROLE_CASTS);
  out.Add(b + ring[0], b + ring[1], b + ring[2], cell, -1, ROLE_CASTS);
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
  for (int s = 0; s < 8; ++s)
  {
    const double sx = (s & 1) ? -1.0 : 1.0, sy = (s & 2) ? -1.0 : 1.0, sz = (s & 4) ? -1.0 : 1.0;
    const Vec3 x = c + Vec3(sx * r, 0, 0), y = c + Vec3(0, sy * r, 0), z = c + Vec3(0, 0, sz * r);
    // (x, y, z) faces along (sx, sy, sz) when sx sy sz = 1; swap two corners otherwise.
    if (sx * sy * sz > 0.0)
    {
      out.Add(x, y, z, cell, -1, ROLE_CASTS);
    }
    else
    {
      out.Add(x, z, y, cell, -1, ROLE_CASTS);
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
  out.Add(a, b, b + d, cell, owner, ROLE_CASTS);
  out.Add(a, b + d, a + d, cell, owner, ROLE_CASTS);
}
}
