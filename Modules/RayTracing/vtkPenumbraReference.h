/**
 * @class   vtkPenumbraReference
 * @brief   Exact ray-traced shadow visibility for view samples, the yardstick of every
 *          technique (Embree 3, CPU, independent of any rendering code).
 *
 * Given the scene triangles (vtkPenumbraSceneGeometry) and the view samples a technique
 * shaded (vtkPenumbraViewSamples), computes per sample and per light the visibility a
 * technique should have produced: 1 lit, 0 shadowed for hard lights, the unoccluded fraction
 * of the light's fixed sample positions for a vtkPenumbraAreaLight, and -1 for invalid
 * (background) samples. Only triangles flagged CASTS_SHADOWS block light; receivers that do
 * not cast are not in the ray-tracing scene.
 *
 * Frames and precision. Embree works in float32, so the scene is built in the geometry's
 * rebased frame (vertices relative to its Origin, small numbers even for city coordinates).
 * Sample positions are moved into that frame in double precision
 * (p + samplesOrigin - geometryOrigin) before rounding, and light positions likewise
 * (world - geometryOrigin), so georeferenced scenes give the same answers as at the origin.
 *
 * Rules (they decide what "exact" means, and a technique must follow the same ones):
 * - Facing: a sample whose normal faces away from the light (N.L <= 0, N as stored in the
 *   samples, L toward the light) is shadowed (0) without a ray, like the back-facing rule
 *   of Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for Alias-Free Hard
 *   Shadows", Eurographics 2009 Areas Papers, §5. For an area light each light sample x_j counts
 *   only when N.(x_j - p) > 0; light samples on or below the tangent plane count as occluded, so a
 *   sample facing away from the whole light gets 0.
 * - Spot lights (positional, cone angle < 90 degrees): a sample outside the cone (angle to
 *   the axis > cone angle) receives no light and gets 0; on the cone boundary it is inside.
 *   A positional light with a cone angle >= 90 is an omnidirectional point light.
 * - Lights that are switched off or have zero intensity: no ray work; every valid sample
 *   gets 1 (the shading multiplies a zero light anyway, so no shadow is the cheap and
 *   harmless answer), and for masks all bits are set.
 * - Self-intersection: the sample's own triangle (its triangle id), and the caster pieces it
 *   owns (vtkPenumbraSceneGeometry::GetTriangleOwner(), penumbra_rules::IsOwnCaster), never
 *   block, and hits closer than tnear = RelativeEpsilon * max(|p|, D) are ignored, where |p| is the
 *   sample's distance to the geometry origin and D the diagonal of the geometry's bounds
 *   (scale-relative, no absolute length). Rays to a point/spot/area light sample end at
 *   distance * (1 - RelativeEpsilon) so the emitter's own surface never blocks.
 * - Ties: a blocker hit at distance t in [tnear, TieFactor * tnear) is a near-contact whose
 *   decision depends on the epsilon. Such a hit is not counted as blocking; if no other
 *   blocker exists the sample (or, for area lights, any of its light-sample rays) is flagged
 *   in GetTies() and its visibility is the answer ignoring the tie band. Comparisons must
 *   exclude tie samples (vtkPenumbraMetrics does). A blocker farther away decides the ray
 *   and clears the tie. Rays that graze a blocker's silhouette edge are decided by Embree's
 *   robust (watertight) test and are not flagged.
 * - No geometry triangles that cast: every valid, light-facing sample is lit.
 *
 * Area lights: visibility = float(count) / float(n) where count is the number of the
 * light's n = GetNumberOfSamples() fixed positions (vtkPenumbraAreaLight::GetSamplePosition)
 * that are above the tangent plane and unoccluded. ComputeAreaMasks() gives the per-sample
 * bit masks (bit j = light sample j counts as lit), ComputeConvergedVisibility() the same
 * rule on a denser grid of cell centres as the converged (k -> infinity) estimate.
 *
 * Caching: the Embree scene is rebuilt only when the geometry object or its
 * GetCastersTime() (which its triangles, flags and Origin move) changed since the last build
 * (see GetNumberOfBuilds()).
 * The geometry must be Update()d by the caller; this class never touches the renderer.
 *
 * Bad input (no samples, no light, inconsistent array sizes, an invalid area light, no
 * geometry) makes a Compute call return 0 with vtkErrorMacro and GetErrorMessage(); outputs
 * are then left untouched.
 *
 * Loops over samples run in parallel with vtkSMPTools; each sample is independent, so the
 * result does not depend on the number of threads.
 */

#ifndef vtkPenumbraReference_h
#define vtkPenumbraReference_h

#include "vtkObject.h"
#include "vtkPenumbraRayTracingModule.h" // For export macro

#include <memory> // For std::unique_ptr
#include <string> // For std::string

class vtkFloatArray;
class vtkLight;
class vtkPenumbraAreaLight;
class vtkPenumbraSceneGeometry;
class vtkPenumbraViewSamples;
class vtkIdTypeArray;
class vtkTypeUInt32Array;
class vtkUnsignedCharArray;

class VTKPENUMBRARAYTRACING_EXPORT vtkPenumbraReference : public vtkObject
{
public:
  static vtkPenumbraReference* New();
  vtkTypeMacro(vtkPenumbraReference, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The scene triangles. The Embree scene is built lazily by the next Compute call and
   * reused while the geometry does not change (see the class description). Default null;
   * Compute calls fail without geometry.
   */
  virtual void SetGeometry(vtkPenumbraSceneGeometry* geometry);
  vtkGetObjectMacro(Geometry, vtkPenumbraSceneGeometry);
  ///@}

  ///@{
  /**
   * Self-intersection epsilon relative to the scene scale max(|p|, bounds diagonal); no
   * unit. Default 1e-5, clamped to [0, 0.01]. Also shortens rays to positional lights by
   * this fraction of their length.
   */
  vtkSetClampMacro(RelativeEpsilon, double, 0.0, 0.01);
  vtkGetMacro(RelativeEpsilon, double);
  ///@}

  ///@{
  /**
   * Width of the tie band as a multiple of tnear: blocker hits in [tnear, TieFactor * tnear)
   * are ties. No unit. Default 16, clamped to [1, 1e6]; 1 disables tie detection.
   */
  vtkSetClampMacro(TieFactor, double, 1.0, 1e6);
  vtkGetMacro(TieFactor, double);
  ///@}

  ///@{
  /**
   * Occluders above which the Embree scene indexes the scene geometry's own float32 points
   * (RTC_SCENE_FLAG_COMPACT: about 36 bytes a triangle) instead of copying the corners into
   * its leaves (about 68 bytes a triangle and 100 while it builds, with spatial splits; its
   * rays are traced about 30 % faster). Both answer every ray the same: the same robust
   * ray/triangle test on the same float32 corners. Default 2^20 (1,048,576); 0: always
   * compact. A change takes effect at the next query (the scene is built again).
   * GetCompact(): whether the current scene is.
   */
  vtkSetClampMacro(CompactAbove, vtkIdType, 0, VTK_ID_MAX);
  vtkGetMacro(CompactAbove, vtkIdType);
  bool GetCompact();
  ///@}

  /**
   * Restricts the Embree scene to the occluders among `triangles` (global triangle indices
   * of the geometry, ascending), for a caller that has proved that no other triangle can
   * block the rays it is about to trace; the answers for those rays are then the same as
   * with every occluder. Null (the default) keeps every occluder. The ids are copied; a
   * subset with other ids rebuilds the Embree scene at the next query, the same ids reuse it.
   * Ids out of order, repeated or negative are refused: every query then fails (message in
   * GetErrorMessage()) until the next call.
   * GetNumberOfCasterTriangles() counts the occluders the current scene holds.
   */
  void SetOccluderSubset(vtkIdTypeArray* triangles);

  /**
   * Visibility of each view sample from `light`, written to `visibility` (one component,
   * one tuple per sample): 1 lit, 0 shadowed, -1 invalid sample; for a vtkPenumbraAreaLight
   * the unoccluded fraction of its fixed light samples in [0, 1]. Directional lights
   * (positional off) shine from TransformedPosition - TransformedFocalPoint; positional
   * lights from TransformedPosition; area lights from their GetSamplePosition() points.
   * Returns 1 on success, 0 on bad input (message in GetErrorMessage()).
   */
  int ComputeVisibility(
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility);

  /**
   * The same rules as ComputeVisibility() for the samples whose `mask` value is nonzero
   * only; every other sample keeps the value `visibility` already holds (and is no tie).
   * For hybrid techniques that classify most samples themselves and trace the rest.
   * `visibility` must already have one component and one tuple per sample, `mask` one
   * tuple per sample. GetNumberOfRays() counts the rays of the masked samples only.
   * Returns 1 on success, 0 on bad input (outputs untouched).
   */
  int ComputeVisibility(vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility,
    vtkUnsignedCharArray* mask);

  /**
   * Per-sample light-sample bit masks for an area light: ceil(n / 32) 32-bit words per sample
   * (the components of `masks`), bit j % 32 of word j / 32 set when light sample j is above
   * the tangent plane and unoccluded. Invalid samples get all-zero masks. Ties and
   * statistics as for ComputeVisibility(). Returns 1 on success, 0 on bad input.
   */
  int ComputeAreaMasks(
    vtkPenumbraViewSamples* samples, vtkPenumbraAreaLight* light, vtkTypeUInt32Array* masks);

  /**
   * Single area-light rays with exactly the rules of ComputeAreaMasks(): for each of the
   * `count` pairs, visible[i] = 1 when light sample lightSamples[i] of `light` counts as lit
   * for view sample sampleIds[i] (above its tangent plane and unoccluded), else 0; an
   * invalid view sample gives 0, a light that is off 1. Lets a technique hand over only the
   * light samples it could not decide. Ties are not reported. Returns 1 on success, 0 on bad
   * input (an index out of range included; outputs untouched).
   */
  int TraceAreaRays(vtkPenumbraViewSamples* samples, vtkPenumbraAreaLight* light, vtkIdType count,
    const vtkIdType* sampleIds, const int* lightSamples, unsigned char* visible);

  /**
   * Converged soft visibility: the same rule as ComputeVisibility() with the light sampled
   * on a samplesPerAxis x samplesPerAxis grid of cell centres (samplesPerAxis points for a
   * Line), following vtkPenumbraAreaLight's cell-centre formula; with samplesPerAxis equal
   * to the light's SamplesPerAxis the result is identical to ComputeVisibility(). The
   * sampling error is below 1 / samplesPerAxis for a straight occluder edge. samplesPerAxis
   * must be in [1, 256]; 64 (4096 rays per sample) is a good converged value. Returns 1 on
   * success, 0 on bad input.
   */
  int ComputeConvergedVisibility(vtkPenumbraViewSamples* samples, vtkPenumbraAreaLight* light,
    int samplesPerAxis, vtkFloatArray* visibility);

  /**
   * Per sample of the last successful Compute call: 1 when its answer depended on a hit in
   * the tie band (see the class description), else 0.
   */
  vtkUnsignedCharArray* GetTies();

  /**
   * Number of tie samples of the last successful Compute call.
   */
  vtkGetMacro(NumberOfTies, vtkIdType);

  /**
   * Number of rays traced by the last successful Compute call (facing rejects and lights
   * that are off trace none).
   */
  vtkGetMacro(NumberOfRays, vtkIdType);

  /**
   * Wall-clock time of the last successful Compute call in milliseconds, scene build
   * included.
   */
  vtkGetMacro(LastTimeMs, double);

  /**
   * Wall-clock time of the last Embree scene build in milliseconds.
   */
  vtkGetMacro(LastBuildTimeMs, double);

  /**
   * How many times an Embree scene was built since construction.
   */
  vtkGetMacro(NumberOfBuilds, int);

  /**
   * Number of caster triangles in the current Embree scene (zero-area triangles skipped).
   */
  vtkIdType GetNumberOfCasterTriangles();

  /**
   * Why the last Compute call failed; empty after a success.
   */
  const char* GetErrorMessage();

protected:
  vtkPenumbraReference();
  ~vtkPenumbraReference() override;

  vtkPenumbraSceneGeometry* Geometry;
  vtkIdType CompactAbove = vtkIdType(1) << 20;
  double RelativeEpsilon;
  double TieFactor;
  vtkIdType NumberOfTies;
  vtkIdType NumberOfRays;
  double LastTimeMs;
  double LastBuildTimeMs;
  int NumberOfBuilds;

private:
  vtkPenumbraReference(const vtkPenumbraReference&) = delete;
  void operator=(const vtkPenumbraReference&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;

  struct LightRays;
  int Fail(const std::string& text);
  int EnsureScene();
  int Run(vtkPenumbraViewSamples* samples, const LightRays& light, vtkFloatArray* visibility,
    vtkTypeUInt32Array* masks, const unsigned char* subset = nullptr);
  int ComputeHardVisibility(vtkPenumbraViewSamples* samples, vtkLight* light,
    vtkFloatArray* visibility, vtkUnsignedCharArray* mask);
};

#endif
