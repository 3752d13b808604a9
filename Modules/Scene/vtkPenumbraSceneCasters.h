/**
 * @file    vtkPenumbraSceneCasters.h
 * @brief   Internal to Penumbra::Scene (not installed, not wrapped): the triangle lists a prop
 *          is extracted into, and the shapes that turn what VTK draws into caster triangles
 *          (tubes for lines, small solids for points and splats, flat strips for the edges of
 *          a surface drawn with edges), with the exact clipping of triangles by half-planes
 *          given in barycentric coordinates (clipping planes, texture cells).
 *
 * Every caster shape here is closed (tubes have caps, point solids are octahedra) except the
 * edge strips, which lie in their polygon's plane as VTK draws them.
 */

#ifndef vtkPenumbraSceneCasters_h
#define vtkPenumbraSceneCasters_h

#include "vtkPenumbraSceneTriangles.h"
#include "vtkType.h"

#include <glm/vec3.hpp> // glm::dvec3: the double-precision vector of every Penumbra module

#include <array>
#include <vector>

namespace penumbra_scene
{
using Vec3 = glm::dvec3;

/// What a triangle may do, before the prop's shadow keys are applied (bits as
/// vtkPenumbraSceneGeometry::TriangleFlags).
enum Role : unsigned char
{
  ROLE_NONE = 0,
  ROLE_CASTS = 1,
  ROLE_RECEIVES = 2,
  ROLE_BOTH = 3
};

/// One prop's triangles (stored indexed; see vtkPenumbraSceneTriangles.h).
using TriangleList = penumbra::TriangleList;
using penumbra::IsDegenerate;

/// A half-space kept by a clipping plane: N . x + D >= 0 (world coordinates).
using Plane = std::array<double, 4>;
using Planes = std::vector<Plane>;

inline double PlaneValue(const Plane& p, const Vec3& x)
{
  return p[0] * x.x + p[1] * x.y + p[2] * x.z + p[3];
}

/// Whether `x` is kept by every plane.
bool Inside(const Planes& planes, const Vec3& x);

/**
 * Clips the segment a + t (b - a), t in [t0, t1], to the planes; false when nothing is left.
 */
bool ClipSegment(const Vec3& a, const Vec3& b, const Planes& planes, double& t0, double& t1);

/// A point of a triangle in barycentric coordinates: (1 - B1 - B2) V0 + B1 V1 + B2 V2.
using Bary = std::array<double, 2>;
using BaryPolygon = std::vector<Bary>;

/// The whole triangle.
BaryPolygon WholeTriangle();

/**
 * Keeps the part of the convex polygon where the linear function with corner values f[0..2]
 * (at V0, V1, V2) is >= 0 (Sutherland-Hodgman, one half-plane). `scratch` is reused memory.
 */
void ClipBary(BaryPolygon& polygon, const double f[3], BaryPolygon& scratch);

/// The corner values of plane `p` on the triangle (v0, v1, v2).
void PlaneCorners(const Plane& p, const Vec3 v[3], double f[3]);

/**
 * Fans the convex polygon (barycentric in triangle v) into `out` as triangles of one cell,
 * owner and role. Polygons of fewer than three points add nothing.
 */
void AppendBaryPolygon(const Vec3 v[3], const BaryPolygon& polygon, vtkIdType cell, vtkIdType owner,
  unsigned char role, TriangleList& out);

/**
 * A line drawn `diameter` wide from a to b: a triangular prism with caps (8 triangles,
 * caster-only, owner -1) whose mean width equals `diameter` (circumradius pi d / (3 sqrt 3)),
 * so that its shadow is as wide as a `diameter`-wide band on average over light directions
 * (between 0.91 and 1.05 times, like a hexagonal prism's). Zero-length segments and zero or
 * non-finite diameters add nothing.
 */
void AppendTube(const Vec3& a, const Vec3& b, double diameter, vtkIdType cell, TriangleList& out);

/// Circumradius of the tube's triangle for a drawn width `diameter`.
double TubeCircumradius(double diameter);

/**
 * A point drawn `diameter` wide at c: an octahedron (8 triangles, caster-only, owner -1)
 * whose mean shadow area equals the area of a disc of that diameter (circumradius
 * d sqrt(pi / (4 sqrt 3))). Zero or non-finite diameters add nothing.
 */
void AppendPointSolid(const Vec3& c, double diameter, vtkIdType cell, TriangleList& out);

/// Circumradius of the point solid for a drawn width `diameter`.
double PointSolidCircumradius(double diameter);

/**
 * The flat strip a polygon edge a -> b gains outside the polygon when VTK 9.1 draws a
 * surface with edges (the triangle is grown by half the line width beyond its real edges,
 * vtkPolyDataEdgesGS): two triangles in the plane of normal `n`, extending `halfWidth`
 * away from `inside` (a point of the polygon). Caster-only, owned by `owner`.
 */
void AppendEdgeStrip(const Vec3& a, const Vec3& b, const Vec3& inside, const Vec3& n,
  double halfWidth, vtkIdType cell, vtkIdType owner, TriangleList& out);
}

#endif
