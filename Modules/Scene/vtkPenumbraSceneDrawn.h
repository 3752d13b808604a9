/**
 * @file    vtkPenumbraSceneDrawn.h
 * @brief   Internal to Penumbra::Scene (not installed, not wrapped): what VTK 9.1's
 *          vtkOpenGLPolyDataMapper draws of one polydata, as triangles.
 *
 * The primitives mirrored (vtkOpenGLPolyDataMapper::BuildIBO, vtkOpenGLIndexBufferObject):
 * - vertex cells are points in every representation;
 * - Points representation: every point of every line, polygon and strip is a point;
 * - Wireframe: line cells are segments (consecutive point pairs), polygons are their closed
 *   outline (only the edges whose first point has a non-zero edge flag when the point data
 *   has a one-component unsigned char EDGEFLAG attribute), strips are the edges of their
 *   triangles; an edge two cells share is drawn twice and cast once;
 * - Surface: polygons fanned (p0, p_i, p_i+1) and strips as triangles, line cells as
 *   segments. With EdgeVisibility each triangle is grown by half the line width beyond its
 *   real edges (polygon outline edges, edge flags applied; every edge of a strip triangle):
 *   those edges gain a flat strip in the polygon's plane. VertexVisibility adds every point
 *   used by a cell as a point, drawn only together with edges.
 * Lines become tubes LineWidth pixels wide and points solids PointSize pixels wide, with the
 * world size of a pixel the caller gives (vtkPenumbraSceneGeometry: at the camera's focal
 * point). Clipping planes discard fragments outside them: triangles are clipped exactly,
 * segments along their length, points by their centre (VTK's clip distances are per
 * vertex). Scalar and texture alpha cut surfaces (vtkPenumbraSceneCutouts.h).
 */

#ifndef vtkPenumbraSceneDrawn_h
#define vtkPenumbraSceneDrawn_h

#include "vtkPenumbraSceneCasters.h"

#include "vtkType.h"

#include <string>
#include <vector>

class vtkMapper;
class vtkPolyData;

namespace penumbra_scene
{
class AlphaGrid;

/// How a prop draws its polydata (from its property, mapper, texture and the pixel size).
struct DrawStyle
{
  int Representation = 2; // VTK_SURFACE
  bool EdgeVisibility = false;
  bool VertexVisibility = false;
  double LineWidth = 0.0;             // world diameter of a drawn line; 0: lines cast nothing
  double PointSize = 0.0;             // world diameter of a drawn point; 0: points cast nothing
  double EdgeWidth = 0.0;             // world width of the edges of a surface drawn with edges
  Planes Clip;                        // kept half-spaces, world coordinates
  const AlphaGrid* Texture = nullptr; // an actor texture with cut-outs, or null
  bool TextureTransform = false;
  double TextureMatrix[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  vtkMapper* ColourMapper = nullptr; // whose scalar colours may have alpha 0, or null
  unsigned char SurfaceRole = ROLE_BOTH;
};

/// The G-buffer numbering of one polydata (see vtkPenumbraSceneGeometry::MapPrimitiveId).
struct PrimitiveCounts
{
  vtkIdType VertPrimitives = 0;   // verts: one point primitive per point id
  vtkIdType LinePrimitives = 0;   // lines: one segment per consecutive point pair
  vtkIdType PolyTriangles = 0;    // our fan triangles of polygons (all of them)
  vtkIdType PolyConservative = 0; // connectivity - 2 * cells: VTK's map-less estimate
  vtkIdType StripTriangles = 0;
  std::vector<vtkIdType> DrawnPolyToLocal; // only when VTK skips some fan triangles
  vtkIdType DrawnPolyTriangles = 0;
};

/// What one extraction met besides triangles.
struct Outcome
{
  vtkIdType BadPoints = 0;      // distinct points with NaN/inf world coordinates that are drawn
  vtkIdType BadTCoords = 0;     // cut triangles with NaN/inf texture coordinates
  bool UsesWidth = false;       // lines, points or edges drawn: the result depends on widths
  bool PointsOrLines = false;   // some fragments are drawn by point or line primitives
  long long Budget = 1ll << 22; // texture cells the cut-outs may still examine
  vtkIdType TooFine = 0;        // textured triangles cast whole because the budget ran out
};

/**
 * Appends what `poly` draws, transformed by the 4x4 row-major world matrix `m`: its drawn
 * triangles to `drawn` (cell ids offset by `cellBase`; a triangle that casts only in part
 * loses ROLE_CASTS) and its caster-only triangles to `casters` (owners are indices in
 * `drawn`). Fills `counts` when given (surface representation).
 */
void AppendDrawnPolyData(vtkPolyData* poly, const double m[16], vtkIdType cellBase,
  const DrawStyle& style, TriangleList& drawn, TriangleList& casters, PrimitiveCounts* counts,
  Outcome& outcome);

/// x' = m x for a row-major 4x4 matrix, with the homogeneous division.
void TransformPoint(const double m[16], const double p[3], double out[3]);
}

#endif
