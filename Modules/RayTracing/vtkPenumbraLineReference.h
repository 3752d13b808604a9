/**
 * @class   vtkPenumbraLineReference
 * @brief   Exact visibility of a linear light (vtkPenumbraAreaLight with Shape Line): the
 *          unblocked fraction of the light segment, computed in double precision without
 *          sampling the light.
 *
 * For a view sample p and the light segment x(t) = A + t (B - A), t in [0, 1], the light
 * points a triangle T hides are those x(t) whose segment p -> x(t) crosses T: the
 * intersection of the cone from p over T with the half-space beyond T's plane. That set is
 * convex, so on the segment it is one interval of t, and every bound is a linear inequality
 * in t: one per edge (the plane through p and the edge) and one for T's plane. Clipping
 * [0, 1] against them (Cyrus-Beck) gives the interval in closed form; the visible fraction
 * is 1 - |union of the intervals|, merged in double (Brabec 2003, ch. 10 motivates the
 * linear light; the interval argument is the exact counterpart of its sampled
 * references).
 *
 * Candidate triangles: the union of the segments p -> x(t) is the triangle (p, A, B), so
 * only triangles meeting it can block. A bounding volume hierarchy over the caster
 * triangles (built here, in double, rebuilt only when the geometry changes) is walked with
 * an exact triangle/box overlap test (Akenine-Moller's separating axes), so a sample looks
 * at the few triangles near its light wedge, not at the whole scene.
 *
 * Rules: those of vtkPenumbraReference (the sampled reference), so that the two agree as
 * the sample count grows:
 * - triangles rounded to float32 as the tracer's copy is (penumbra_rules::MakeExactTriangle),
 *   casters only; the sample's own triangle (and the caster pieces it owns) never blocks;
 * - tangent plane: light points with N.(x - p) <= 0 count as blocked (the light side of
 *   the receiver only); the light emits to both sides of its own line, as in the tracer;
 * - the ray ends at distance * (1 - RelativeEpsilon), so an emitter's own surface never
 *   blocks (a linear bound in t, part of the plane clip);
 * - self-intersection and ties: where the tracer ignores hits closer than its tie limit
 *   (TieFactor * RelativeEpsilon * max(|p|, D)), this class ignores a blocking triangle
 *   whose plane is closer to p than that limit (every hit on it could be that close) and
 *   flags the sample in GetTies(), so comparisons can exclude it as they exclude the
 *   tracer's ties;
 * - a light that is off or has zero intensity gives 1; invalid (background) samples -1.
 *
 * Frames: like vtkPenumbraReference, all differences are taken in double in the geometry's
 * rebased frame. Samples are processed in parallel with vtkSMPTools; the result does not
 * depend on the number of threads.
 */

#ifndef vtkPenumbraLineReference_h
#define vtkPenumbraLineReference_h

#include "vtkObject.h"
#include "vtkPenumbraRayTracingModule.h" // For export macro

#include <memory> // For std::unique_ptr
#include <string> // For std::string

class vtkFloatArray;
class vtkPenumbraAreaLight;
class vtkPenumbraSceneGeometry;
class vtkPenumbraViewSamples;
class vtkUnsignedCharArray;

class VTKPENUMBRARAYTRACING_EXPORT vtkPenumbraLineReference : public vtkObject
{
public:
  static vtkPenumbraLineReference* New();
  vtkTypeMacro(vtkPenumbraLineReference, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The scene triangles; the hierarchy is built by the next Compute call and reused while
   * the geometry object and its GetCastersTime() (which its triangles, flags and Origin move)
   * do not change. Default null.
   */
  virtual void SetGeometry(vtkPenumbraSceneGeometry* geometry);
  vtkGetObjectMacro(Geometry, vtkPenumbraSceneGeometry);
  ///@}

  ///@{
  /**
   * Scale-relative epsilon, as vtkPenumbraReference's (no unit). Default 1e-5, clamped to
   * [0, 0.01].
   */
  vtkSetClampMacro(RelativeEpsilon, double, 0.0, 0.01);
  vtkGetMacro(RelativeEpsilon, double);
  ///@}

  ///@{
  /**
   * Tie band as a multiple of the epsilon distance, as vtkPenumbraReference's. Default 16,
   * clamped to [1, 1e6].
   */
  vtkSetClampMacro(TieFactor, double, 1.0, 1e6);
  vtkGetMacro(TieFactor, double);
  ///@}

  /**
   * Exact visible fraction of the linear light `light` (Shape must be Line) for each view
   * sample: one component, one tuple per sample, in [0, 1]; -1 for invalid samples.
   * Returns 1 on success, 0 on bad input (message in GetErrorMessage(); outputs untouched).
   */
  int ComputeVisibility(
    vtkPenumbraViewSamples* samples, vtkPenumbraAreaLight* light, vtkFloatArray* visibility);

  /**
   * Per sample of the last successful call: 1 when a blocker closer than the tie limit was
   * ignored (see the class description).
   */
  vtkUnsignedCharArray* GetTies();

  /**
   * Number of tie samples of the last successful call.
   */
  vtkGetMacro(NumberOfTies, vtkIdType);

  /**
   * Triangles whose interval was computed by the last successful call (the candidates the
   * hierarchy returned), summed over samples.
   */
  vtkGetMacro(NumberOfCandidates, vtkIdType);

  /**
   * Wall-clock time of the last successful call in milliseconds, hierarchy build included.
   */
  vtkGetMacro(LastTimeMs, double);

  /**
   * How many times the hierarchy was built since construction.
   */
  vtkGetMacro(NumberOfBuilds, int);

  /**
   * Why the last call failed; empty after a success.
   */
  const char* GetErrorMessage();

protected:
  vtkPenumbraLineReference();
  ~vtkPenumbraLineReference() override;

  vtkPenumbraSceneGeometry* Geometry;
  double RelativeEpsilon;
  double TieFactor;
  vtkIdType NumberOfTies;
  vtkIdType NumberOfCandidates;
  double LastTimeMs;
  int NumberOfBuilds;

private:
  vtkPenumbraLineReference(const vtkPenumbraLineReference&) = delete;
  void operator=(const vtkPenumbraLineReference&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;

  int Fail(const std::string& text);
  int EnsureHierarchy();
};

#endif
