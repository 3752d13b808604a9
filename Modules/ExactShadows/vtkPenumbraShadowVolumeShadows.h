/**
 * @class   vtkPenumbraShadowVolumeShadows
 * @brief   Exact hard shadows with stencil shadow volumes (Brabec, "Shadow Techniques for
 *          Interactive and Real-Time Applications", PhD thesis, 2003, ch. 3, 8, 9; the
 *          hierarchical shadow-volume culling of the doctoral thesis behind Ferko 2013 and
 *          2014, done as Lloyd et al.'s CC shadow volumes, 2004): silhouette volumes from OpenMesh
 *          connectivity (the light-facing faces of closed meshes, both face sets of open ones), one
 *          closed volume per triangle for the faces OpenMesh refuses (non-manifold, flipped against
 *          their neighbours).
 *
 * Per light and frame:
 * 1. Connectivity (rebuilt only when the geometry, its flags or its origin change): the
 *    caster triangles (IsOccluder, zero-area ones skipped like the reference does) are welded
 *    by exactly equal vertex coordinates and added to an OpenMesh triangle mesh. OpenMesh
 *    refuses faces that would make an edge complex (non-manifold: a third face on an edge,
 *    a duplicate face, a face oriented against its neighbours); those are counted
 *    (GetNumberOfComplexFaces()) and get per-triangle volumes: the triangle turned toward
 *    the light, its extrusion and its three sides (always correct, for any input). The
 *    accepted faces form consistently oriented components, closed (no boundary edge) or
 *    open.
 * 2. Volumes (rebuilt only when the light, the connectivity or, with culling, the box of
 *    the lit-candidate samples changes). The stencil count of a set of per-triangle volumes
 *    is the number of its triangles the segment to the light crosses; sides shared by two
 *    triangles of the set cancel, so a set needs only its caps and the side quads on its
 *    border edges. A closed component whose bounding box does not contain a positional
 *    light uses its light-facing triangles (light cap, extruded and reversed as dark cap,
 *    one quad per silhouette edge; each face classified once in double, ties back-facing,
 *    so caps and sides always agree): the segment crosses the mesh exactly when it crosses one of
 *    them. Components with inward orientation (negative volume) swap front and back. Open
 *    components, and closed ones that may hold the light, use both sets (the back-facing
 *    triangles turned toward the light too), which counts every crossing like per-triangle
 *    volumes but with sides only on silhouette and boundary edges. Every volume is closed
 *    and bounded: directional lights extrude by a finite length beyond every caster (a
 *    prism), positional lights to L + (v - L) / w, a homogeneous vertex with a small w
 *    chosen so that the far cap lies beyond every sample (four times the farthest geometry
 *    distance over the nearest caster distance). Points at infinity (w = 0) would do under a
 *    perspective camera, but under a parallel camera they all project with clip w = 0 and
 *    the dark caps vanish.
 * 3. Counting in an own framebuffer (window size, 32-bit float depth + 8-bit stencil): the
 *    depth buffer receives, per pixel, the depth of the point where the pixel-centre ray
 *    meets the sample's own triangle (double precision on the CPU, once per frame for all
 *    lights), so the depth test sees exactly the sampled surfaces. The volumes are then
 *    drawn with two-sided stencil operations, depth writes off, GL_DEPTH_CLAMP on and a
 *    reversed float depth (glClipControl zero-to-one): z-fail by default (back faces
 *    increment and front faces decrement where the depth test fails, Carmack's reverse with
 *    caps, Brabec 2003, §3.2.5), or z-pass when the camera is provably outside every volume
 *    (Method AUTO) or when asked (ZPASS). Light caps are pushed back by CapOffset so that a
 *    sample on a caster's lit surface is outside that caster's volume, which is the
 *    reference's "own triangle never blocks" rule and its tnear epsilon.
 *    Samples are placed on pixels by projecting them with the camera (the renderer's aspect),
 *    not by their index: an array may hold several surfaces per pixel (vtkPenumbraShadowPass
 *    stacks the nearest translucent surface's rows under the opaque ones). Samples that meet
 *    an occupied pixel form the next layer, counted in its own pass (up to 4 layers); samples
 *    off every pixel centre or beyond the fourth layer are traced.
 * 4. Read back: a non-zero stencil count (modulo 256, wrap operations) is shadow.
 * 5. Edge resolve (Resolve, default on): the rasterizer decides coverage on a snapped
 *    sub-pixel grid, not exactly; the samples next to a change of the result, and those
 *    whose pixel centre lies within 1/32 pixel of the volumes' outline from the camera, are
 *    traced with vtkPenumbraReference (see SetResolve()). Everything else is the stencil's
 *    answer.
 *
 * Culling (Cull, default on; CC shadow volumes, Lloyd et al. 2004): a triangle's volume is
 * dropped when a separating plane (the sample box faces, the triangle's plane, its three
 * side planes) puts it apart from the box of the light-facing samples; in a component the
 * triangle then simply leaves its set, and the remaining sum stays a valid count.
 *
 * Facing-away samples, spot cones, lights that are off and background samples follow the
 * reference's rules (shared code with the other map-based techniques). Area lights are
 * rejected. Requirements checked at run time with a clear error (the pass then renders the
 * light unshadowed): glClipControl (GL 4.5 / ARB_clip_control), depth clamp, a complete
 * DEPTH32F_STENCIL8 framebuffer.
 *
 * GPU silhouettes (GPUSilhouettes): closed components go through a geometry shader with
 * triangle adjacency instead of the CPU silhouette loop (Brabec 2003, ch. 9).
 *
 * Several lights (Brabec 2003, ch. 8): ComputeVisibilities() (what vtkPenumbraShadowPass calls
 * once per frame) takes the lights in groups of LightsPerMask (default 4). The sample depths
 * are computed and uploaded once per frame and camera; each light of a group then clears the
 * stencil, draws its (cached, already uploaded) volumes and copies "count != 0" as 0 into its
 * own channel of one RGBA8 mask (a full-screen triangle under the stencil test, the thesis's
 * stencil-to-colour copy); the group's mask is read back once (the red channel alone for a
 * single light). ceil(N / 4) masks serve N lights; GetNumberOfMasks() counts them.
 * Goniometric lights (vtkPenumbraGoniometricLight, Brabec 2003, §8.3.1) are shadowed as point
 * lights; vtkPenumbraShadowPass scales the light by the diagram (in float, after the mask is
 * read back, so the diagram keeps its full range), for every technique alike.
 *
 * Limits: a sample inside a multiple of 256 volumes reads as lit (8-bit wrap).
 */

#ifndef vtkPenumbraShadowVolumeShadows_h
#define vtkPenumbraShadowVolumeShadows_h

#include "vtkPenumbraExactShadowsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr

class vtkPenumbraReference;
class vtkPenumbraStatistics;

class VTKPENUMBRAEXACTSHADOWS_EXPORT vtkPenumbraShadowVolumeShadows
  : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraShadowVolumeShadows* New();
  vtkTypeMacro(vtkPenumbraShadowVolumeShadows, vtkPenumbraShadowTechnique);

  const char* GetTechniqueName() override { return "volumes"; }
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  /**
   * Several lights at once, LightsPerMask per RGBA mask (see the class description). The
   * statistics then sum over the lights of the call.
   */
  int ComputeVisibilities(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLightCollection* lights,
    vtkCollection* visibilities) override;

  void ReleaseGraphicsResources(vtkWindow* window) override;

  ///@{
  /**
   * Lights counted into one RGBA mask before it is read back (Brabec 2003, ch. 8): 4 (default)
   * uses every channel; 1 reads each light's result back on its own (the per-light baseline
   * the thesis improves on). Clamped to [1, 4]. Only speed depends on it.
   */
  vtkSetClampMacro(LightsPerMask, int, 1, 4);
  vtkGetMacro(LightsPerMask, int);
  ///@}

  /**
   * Masks read back by the last call: ceil(lights that needed counting / LightsPerMask).
   */
  vtkGetMacro(NumberOfMasks, int);

  enum CountingMethod
  {
    METHOD_AUTO = 0, // z-pass when the camera is provably outside every volume, else z-fail
    METHOD_ZFAIL = 1,
    METHOD_ZPASS = 2 // always z-pass: wrong where the camera is inside a volume (for studies)
  };

  ///@{
  /**
   * Stencil counting method, see CountingMethod. Default METHOD_AUTO.
   */
  vtkSetClampMacro(Method, int, METHOD_AUTO, METHOD_ZPASS);
  vtkGetMacro(Method, int);
  ///@}

  ///@{
  /**
   * Skip volumes that cannot reach the box of the light-facing samples. Default on.
   */
  vtkSetMacro(Cull, bool);
  vtkGetMacro(Cull, bool);
  vtkBooleanMacro(Cull, bool);
  ///@}

  ///@{
  /**
   * Use silhouette volumes for closed components (on) or per-triangle volumes for every
   * caster (off, the brute-force baseline of Brabec 2003, §3.2.5). Default on.
   */
  vtkSetMacro(Silhouettes, bool);
  vtkGetMacro(Silhouettes, bool);
  vtkBooleanMacro(Silhouettes, bool);
  ///@}

  ///@{
  /**
   * Trace exactly with vtkPenumbraReference the samples whose stencil count may be wrong.
   * The rasterizer snaps vertices to a sub-pixel grid (1/256 pixel on llvmpipe), so a sample
   * whose pixel centre lies closer than that to a projected volume edge may be counted on
   * the wrong side of it. Only the volumes' outline from the camera matters: edges where a
   * camera-facing and a camera-averted volume face meet (cap edges included), faces seen
   * edge-on and edges of faces whose facing the GPU silhouette stage may decide otherwise;
   * where two faces of the same facing share an edge, the rasterizer covers each pixel centre
   * with exactly one of them. So the samples traced are those within 1/32 pixel of that
   * outline (per light and frame, on the CPU from the cached volume edges; this catches a
   * shadow narrower than a pixel, all of whose pixels lie on the outline), those next to a
   * change of the stencil result or to background and facing-away samples, and those the
   * light grazes (cosine below 1e-3: their answer hangs on the float rounding of the sample
   * position). Default on; off gives the pure stencil answer.
   */
  vtkSetMacro(Resolve, bool);
  vtkGetMacro(Resolve, bool);
  vtkBooleanMacro(Resolve, bool);
  ///@}

  /**
   * Share of the last call's counted (light-facing, lit-candidate) samples that the edge
   * resolve traced, in [0, 1].
   */
  double GetUncertainFraction() override;

  ///@{
  /**
   * Measure the fill: draw the volumes a second time with the depth test off and count the
   * fragments (GL_SAMPLES_PASSED), reported by GetNumberOfFillFragments(). Costs a second
   * draw, so it is for benchmarks only. Default off.
   */
  vtkSetMacro(MeasureFill, bool);
  vtkGetMacro(MeasureFill, bool);
  vtkBooleanMacro(MeasureFill, bool);
  ///@}

  /**
   * Volume fragments rasterized by the last call (stencil fill), -1 unless MeasureFill.
   */
  vtkGetMacro(NumberOfFillFragments, vtkIdType);

  /**
   * Samples traced by the edge resolve in the last call, and its time in milliseconds.
   */
  vtkGetMacro(NumberOfResolvedSamples, vtkIdType);
  vtkGetMacro(ResolveTimeMs, double);

  /**
   * The ray tracer of the edge resolve (exposed for its statistics and epsilons). Above its
   * CompactAbove casters, after a call it holds only the casters that can block the samples
   * the call traced (vtkPenumbraReference::SetOccluderSubset): trace other rays with a
   * vtkPenumbraReference of your own. Raising its CompactAbove keeps every caster.
   */
  vtkPenumbraReference* GetReference() { return this->Reference; }

  ///@{
  /**
   * Find silhouettes on the GPU (Brabec 2003, ch. 9): closed components are drawn as
   * GL_TRIANGLES_ADJACENCY (indices from the OpenMesh connectivity) and a geometry shader
   * decides facing per face (in float, one canonical evaluation per face shared by both
   * sides of every edge), emitting caps and side quads. Per-triangle volumes, components
   * around a positional light and culling stay on the CPU; closed components are not culled
   * on this path, and GetNumberOfSilhouetteEdges() is -1 (not counted). Default off.
   */
  vtkSetMacro(GPUSilhouettes, bool);
  vtkGetMacro(GPUSilhouettes, bool);
  vtkBooleanMacro(GPUSilhouettes, bool);
  ///@}

  ///@{
  /**
   * How far light caps are pushed back, relative to their eye depth (no unit). Default
   * 2^-17 (about 7.6e-6, 64 float32 steps), clamped to [0, 1e-3]. It must exceed the float
   * rounding between the CPU sample depth and the rasterized cap, and stay below the
   * reference's tie band (16 x 1e-5 of the scene scale).
   */
  vtkSetClampMacro(CapOffset, double, 0.0, 1e-3);
  vtkGetMacro(CapOffset, double);
  ///@}

  ///@{
  /**
   * Statistics of the connectivity (valid after a call): caster triangles, faces OpenMesh
   * refused (complex/non-manifold or inconsistently oriented), boundary edges, closed and
   * open components (silhouette volumes of one or both face sets) and triangles that use
   * per-triangle volumes (the refused faces; every caster without Silhouettes).
   */
  vtkGetMacro(NumberOfCasterTriangles, vtkIdType);
  vtkGetMacro(NumberOfComplexFaces, vtkIdType);
  vtkGetMacro(NumberOfBoundaryEdges, vtkIdType);
  vtkGetMacro(NumberOfClosedComponents, vtkIdType);
  vtkGetMacro(NumberOfOpenComponents, vtkIdType);
  vtkGetMacro(NumberOfPerTriangleVolumes, vtkIdType);
  ///@}

  ///@{
  /**
   * Statistics of the last call, summed over its lights: silhouette edges extruded (-1 when
   * GPU silhouettes made some), volume triangles drawn, volumes culled (per-triangle volumes
   * and closed components), fragments that passed the depth test while counting
   * (GL_SAMPLES_PASSED), whether z-pass was used (for any light).
   */
  vtkGetMacro(NumberOfSilhouetteEdges, vtkIdType);
  vtkGetMacro(NumberOfVolumeTriangles, vtkIdType);
  vtkGetMacro(NumberOfCulledVolumes, vtkIdType);
  vtkGetMacro(NumberOfPassedFragments, vtkIdType);
  vtkGetMacro(UsedZPass, bool);
  ///@}

  ///@{
  /**
   * How many times the connectivity, the volumes (one cached set per light, up to 8) and
   * the per-pixel sample depths (once per frame and camera, shared by all lights) were
   * built since construction.
   */
  vtkGetMacro(NumberOfConnectivityBuilds, int);
  vtkGetMacro(NumberOfVolumeBuilds, int);
  vtkGetMacro(NumberOfDepthComputations, int);
  ///@}

  ///@{
  /**
   * Phase times of the last call in milliseconds: connectivity (0 when cached), volume
   * generation (0 when cached), stencil counting (sample depths, upload, drawing, read
   * back), and the sample-depth part of it alone (CPU, double precision).
   */
  vtkGetMacro(ConnectivityTimeMs, double);
  vtkGetMacro(VolumeTimeMs, double);
  vtkGetMacro(StencilTimeMs, double);
  vtkGetMacro(SampleDepthTimeMs, double);
  ///@}

protected:
  vtkPenumbraShadowVolumeShadows();
  ~vtkPenumbraShadowVolumeShadows() override;

  int Method = METHOD_AUTO;
  bool Cull = true;
  bool Silhouettes = true;
  double CapOffset = 1.0 / 131072.0;
  bool Resolve = true;
  bool GPUSilhouettes = false;
  bool MeasureFill = false;
  int LightsPerMask = 4;
  int NumberOfMasks = 0;
  vtkIdType NumberOfFillFragments = -1;
  vtkIdType NumberOfCountedSamples = 0;
  vtkIdType NumberOfResolvedSamples = 0;
  double ResolveTimeMs = 0.0;
  vtkPenumbraReference* Reference;
  vtkIdType NumberOfCasterTriangles = 0;
  vtkIdType NumberOfComplexFaces = 0;
  vtkIdType NumberOfBoundaryEdges = 0;
  vtkIdType NumberOfClosedComponents = 0;
  vtkIdType NumberOfOpenComponents = 0;
  vtkIdType NumberOfPerTriangleVolumes = 0;
  vtkIdType NumberOfSilhouetteEdges = 0;
  vtkIdType NumberOfVolumeTriangles = 0;
  vtkIdType NumberOfCulledVolumes = 0;
  vtkIdType NumberOfPassedFragments = 0;
  bool UsedZPass = false;
  int NumberOfConnectivityBuilds = 0;
  int NumberOfVolumeBuilds = 0;
  int NumberOfDepthComputations = 0;
  double ConnectivityTimeMs = 0.0;
  double VolumeTimeMs = 0.0;
  double StencilTimeMs = 0.0;
  double SampleDepthTimeMs = 0.0;

private:
  vtkPenumbraShadowVolumeShadows(const vtkPenumbraShadowVolumeShadows&) = delete;
  void operator=(const vtkPenumbraShadowVolumeShadows&) = delete;

  // Up to four lights into one mask; returns how many succeeded.
  int ComputeGroup(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* const* lights, vtkFloatArray* const* visibilities,
    int count);
  void ResetStatistics();

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
