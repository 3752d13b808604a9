/**
 * @file   vtkPenumbraShadowReach.h
 * @brief  Which casters can shadow a region: the space every shadow ray from a box of
 *         receivers to a light passes through, and the triangles that may lie in it.
 *
 * A shadow ray starts at a view sample on a receiving triangle and ends on the light: at a
 * point light's position, at one of an area light's samples (all inside its rectangle or
 * disc, or on its segment) or, for a directional light, at infinity along its direction. So
 * every shadow ray of the samples in an axis-aligned box B lies in
 * - hull(B, B + L d) for a directional light of unit direction d (towards the light), where
 *   L is the diagonal of the bounds of B and the casters: a caster is inside those bounds and
 *   no farther than L from any point of B, so a longer sweep adds no caster;
 * - hull(B, Q) for a positional or area light, Q being the points whose convex hull holds
 *   every point the techniques sample on the light (the position; the rectangle's, disc's
 *   bounding square's or segment's corners; the cube around a sphere light).
 * A triangle outside that region blocks none of those rays. Region::MayBlock() tells, for a
 * triangle's (or a block of triangles') bounds, whether it may lie inside: it looks for a
 * separating axis between the two convex sets (the coordinate axes and the cross products of
 * the coordinate axes with the region's edge directions), so it only ever answers "no" when
 * the two are disjoint. It is the exact distributed shadows' test of need
 * (vtkPVPenumbraShadowView): a rank sends a peer the casters that may block a ray of the
 * peer's receivers, and the peer's answers equal those over all casters.
 *
 * Rounding: view samples are rebased float32 positions and the tracer holds float32
 * triangles, so both sit up to a few float ulps of the scene off their double-precision
 * triangles; the receivers' boxes are grown by Margin() of the scene, far beyond that.
 */

#ifndef vtkPenumbraShadowReach_h
#define vtkPenumbraShadowReach_h

#include "vtkPenumbraRayTracingModule.h" // For export macro
#include "vtkType.h"                     // For vtkIdType

#include <array>  // For std::array
#include <string> // For std::string
#include <vector> // For std::vector

class vtkLight;
class vtkPenumbraSceneGeometry;
class vtkRenderer;

namespace penumbra_reach
{
/**
 * Where one light's shadow rays end: along Direction (directional) or inside the convex hull
 * of Points (x, y, z, x, y, z, ...).
 */
struct LightReach
{
  bool Directional = false;
  double Direction[3] = { 0.0, 0.0, 0.0 }; // unit, towards the light
  std::vector<double> Points;

  bool operator==(const LightReach& other) const;
  bool operator!=(const LightReach& other) const { return !(*this == other); }
};

/**
 * The reach of `light` as the shadow pass shadows it (an area light's extent, a positional
 * light's radius as the cube around its sphere). False, with `error`, when its position,
 * focal point or extent is not finite or a directional light has no direction.
 */
VTKPENUMBRARAYTRACING_EXPORT bool DescribeLight(
  vtkLight* light, LightReach& reach, std::string& error);

/**
 * The reaches of the renderer's lights that get shadow work (switched on and emitting,
 * penumbra_rules::LightEmits), in the renderer's order. Lights that cannot be described are
 * left out with their message in `errors` (the pass refuses them too).
 */
VTKPENUMBRARAYTRACING_EXPORT std::vector<LightReach> DescribeLights(
  vtkRenderer* renderer, std::vector<std::string>* errors = nullptr);

/**
 * The growth of a receivers' box (a length): 1e-4 of the diagonal of `bounds`, at least
 * 1e-9 of the largest coordinate.
 */
VTKPENUMBRARAYTRACING_EXPORT double Margin(const double bounds[6]);

/**
 * The region every shadow ray from a point of `receivers` (bounds, xmin, xmax, ...) to one
 * light passes through, cut to `casters` (the bounds of every caster that may be asked about;
 * they only set the sweep of a directional light).
 */
class VTKPENUMBRARAYTRACING_EXPORT Region
{
public:
  Region(const double receivers[6], const LightReach& light, const double casters[6]);

  /**
   * False only when nothing inside `bounds` can meet the region (a separating axis exists).
   */
  bool MayBlock(const double bounds[6]) const;

private:
  struct Axis
  {
    double A[3];
    double Min, Max; // the region's extent along A
  };
  std::vector<Axis> Axes; // the coordinate axes first: they reject most boxes at once
};

/**
 * Appends to `selected`, in increasing order, the indices of the triangles of `xyz` (9
 * coordinates each, `count` of them) that may block a ray of any of `regions`: blocks of
 * consecutive triangles are tested by their bounds first, then their triangles one by one.
 */
VTKPENUMBRARAYTRACING_EXPORT void SelectTriangles(const double* xyz, vtkIdType count,
  const std::vector<Region>& regions, std::vector<vtkIdType>& selected);

/**
 * Up to `maxBoxes` bounds (6 doubles each, world coordinates) that together hold the
 * triangles of `geometry` whose flags (vtkPenumbraSceneGeometry::GetTriangleFlags()) have a
 * bit of `flags` (RECEIVES_SHADOWS: the receivers; CASTS_SHADOWS: the casters), split at the median
 * triangle of the longest side until there are `maxBoxes` or a box holds one triangle. Each
 * box is grown by Margin() of the geometry's bounds. Empty when no triangle has the flag.
 */
VTKPENUMBRARAYTRACING_EXPORT std::vector<std::array<double, 6>> TriangleBoxes(
  vtkPenumbraSceneGeometry* geometry, unsigned char flags, int maxBoxes);

/**
 * Whether the segment o + t d, t in [0, tmax] (tmax may be infinite), meets `box`.
 */
VTKPENUMBRARAYTRACING_EXPORT bool SegmentMeetsBox(
  const double o[3], const double d[3], double tmax, const double box[6]);
}

#endif
