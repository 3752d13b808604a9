/**
 * @file   vtkPenumbraVisibilityRules.h
 * @brief  The exact visibility rules, in one place: which lights emit, the scene scale the
 *         self-intersection epsilon and the tie band are relative to, and the double-precision
 *         ray/triangle decision the hybrid techniques make before asking the tracer.
 *
 * vtkPenumbraReference (the Embree tracer) defines what "exact" means; the techniques that
 * decide some rays themselves (vtkPenumbraConservativeShadows, vtkPenumbraGearsShadows)
 * call these functions so that they cannot drift from it, the way pbrt-v4's one
 * `Unoccluded()` query handles self-intersection once for every integrator.
 */

#ifndef vtkPenumbraVisibilityRules_h
#define vtkPenumbraVisibilityRules_h

#include "vtkPenumbraRayTracingModule.h" // For export macro
#include "vtkType.h"                     // For vtkIdType

class vtkLight;
class vtkPenumbraSceneGeometry;
namespace penumbra
{
class SceneTriangles;
}

namespace penumbra_rules
{
/**
 * The tracer's default ray band (vtkPenumbraReference and vtkPenumbraLineReference): hits
 * closer than RelativeEpsilon * max(|p|, scene diagonal) are self-intersections, hits within
 * TieFactor times that distance are ties.
 */
constexpr double DefaultRelativeEpsilon = 1e-5;
constexpr double DefaultTieFactor = 16.0;

/**
 * A light that is switched off, has no positive intensity or is black (diffuse and specular
 * colour zero) casts nothing: no shadow work, every valid sample is lit (the shading
 * multiplies a zero light anyway). The one rule for the tracer, the techniques, the pass
 * and the bench.
 */
VTKPENUMBRARAYTRACING_EXPORT bool LightEmits(vtkLight* light);

/**
 * The length D the epsilons are relative to: the diagonal of the geometry's bounds, or 1 for
 * empty or degenerate bounds.
 */
VTKPENUMBRARAYTRACING_EXPORT double SceneDiagonal(vtkPenumbraSceneGeometry* geometry);

/**
 * One view sample's ray band, in the geometry's rebased frame: hits closer than TNear =
 * epsilon * max(|p|, D) are ignored (self-intersection), hits in [TNear, TieLimit) with
 * TieLimit = tieFactor * TNear are ties, Scale = max(|p|, D).
 */
struct RayBand
{
  double Scale;
  double TNear;
  double TieLimit;
};
VTKPENUMBRARAYTRACING_EXPORT RayBand SampleBand(
  const double p[3], double diagonal, double epsilon, double tieFactor);

/**
 * A triangle rounded to float32 the way the tracer's copy is, with what the exact test needs
 * precomputed.
 */
struct ExactTriangle
{
  double V[3][3];
  double N[3];    // unit normal
  double M[3][3]; // unit in-plane normals of the edges (k, k+1), pointing inside
  double MD[3];   // M[k] . V[k]
  vtkIdType Id;   // the drawn triangle that owns it (own-triangle exclusion, see IsOwnCaster)
};

/**
 * The one own-triangle rule: a caster never blocks the view samples of the drawn triangle
 * that owns it, `casterOwner` = vtkPenumbraSceneGeometry::GetTriangleOwner() (the triangle itself,
 * or the drawn triangle a caster piece was cut from). A sample whose triangle is unknown
 * (`sampleTriangle` -1) and casters that belong to no drawn triangle (owner -1: tubes, point
 * solids, splats) exclude nothing.
 */
inline bool IsOwnCaster(vtkIdType casterOwner, vtkIdType sampleTriangle)
{
  return sampleTriangle >= 0 && casterOwner == sampleTriangle;
}

/**
 * Fills `triangle` from nine coordinates, `id` its owner (IsOwnCaster); false when it has no
 * area after rounding (the tracer cannot hit it either).
 */
VTKPENUMBRARAYTRACING_EXPORT bool MakeExactTriangle(
  const double* v9, vtkIdType id, ExactTriangle& triangle);

/**
 * Triangle `t` of the scene as an occluder: false when it casts nothing or has no area
 * (IsOccluder), else MakeExactTriangle of its rebased corners with its owner.
 */
VTKPENUMBRARAYTRACING_EXPORT bool MakeOccluder(
  const penumbra::SceneTriangles& triangles, vtkIdType t, ExactTriangle& triangle);

enum class Hit
{
  Clear,  // the tracer's ray provably hits beyond the tie band and before its end
  Miss,   // provably no hit the tracer would count
  OnEdge, // clear in t and inside two edges, within the tolerance of the third only
  Unknown // otherwise too close to call (grazing, near the tie band or the ray end)
};

/**
 * The tracer's decision for the ray o + t d (d unit) and one triangle, in double. The tracer
 * counts a blocker for t in [tieLimit, tmax] and computes visibility as if hits below tieLimit
 * (below tnear, or ties) were not there, so anything provably below tieLimit is a miss. Every
 * decision keeps `errPos` of margin (a length; grown by 1/|cos| where a shifted ray slides
 * along the plane). `edge` receives the edge of an OnEdge answer.
 */
VTKPENUMBRARAYTRACING_EXPORT Hit SegmentTest(const double o[3], const double d[3], double tieLimit,
  double tmax, const ExactTriangle& triangle, double errPos, int& edge);
}

#endif
