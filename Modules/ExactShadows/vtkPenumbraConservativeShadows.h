/**
 * @class   vtkPenumbraConservativeShadows
 * @brief   Exact hard shadows the hybrid way of Hertel, Hormann, Westermann, "A Hybrid GPU
 *          Rendering Pipeline for Alias-Free Hard Shadows", Eurographics 2009 Areas Papers:
 *          a conservative shadow map classifies view samples as lit, shadowed or uncertain,
 *          and only uncertain ones are ray traced.
 *
 * Per light and frame:
 * 1. Conservative shadow map (CSM, Hertel et al. 2009, §4.1; rebuilt only when what it
 *    depends on changes, see Memory below): per texel, the Layers nearest caster triangles
 *    whose projection touches the texel, each with a *conservative* (never too large)
 *    linear light depth over the texel. Two builders, see SetMapBuilder():
 *    - CPU (default): exact conservative rasterization in double precision
 *      (vtkPenumbraConservativeMapCPU.h): separating-axis texel/triangle overlap on binned
 *      tiles with vtkSMPTools, all layers in one pass, no read back.
 *    - GPU: a vertex + geometry + fragment program draws the casters (uploaded once per
 *      geometry/flags change, see GetNumberOfUploads()) into an R32UI id buffer and a float
 *      depth buffer; the geometry stage enlarges each triangle by the texel diagonal
 *      (§4.1), the fragment stage keeps texels by true point-to-segment distance (which
 *      corrects the paper's distance test) and writes max(plane minimum over the texel,
 *      vertex minimum) - epsilon; further depth-peeled draws store the next nearest *other*
 *      triangles (an exact replacement for the paper's "own id -> lit" rule of §4.2, see
 *      SetLayers()).
 *    Light cameras: directional lights get an orthographic view along the light fitted to
 *    the casters and the valid samples; spot lights with a cone of at most 60 degrees one
 *    perspective view covering the cone; wider spots and point lights six 90-degree cube
 *    faces. Triangles that come closer to a perspective view's apex than 0.2 % of its depth
 *    range (a light on or very near geometry): the GPU builder covers the whole face with
 *    them at depth 0; the CPU builder tests each exactly against every sample's ray instead
 *    (up to 64 of them; beyond, the face's samples are traced).
 * 2. Classification on the CPU (vtkSMPTools, double precision) of the layers; see the rule
 *    list in the implementation. Every decision is provable; anything else is "uncertain".
 * 3. Uncertain samples are ray traced by vtkPenumbraReference on the CPU (Embree), which also
 *    defines the answer the technique must match exactly.
 *
 * Area lights are rejected (error, the pass renders that light unshadowed).
 *
 * Cost on the CPU-only llvmpipe target: the CPU builder is much faster than the
 * geometry-shader one (docs/benchmarks.md), but Embree traces a coherent shadow ray per view
 * sample in about the time the classifier needs for a map lookup per sample, so the hybrid
 * does not beat vtkPenumbraRayTracedShadows here; its split pays where a hardware rasterizer
 * builds the map and rays are expensive.
 *
 * Memory: Layers x 8 bytes per texel, i.e. 16 MiB at the default 1024^2 and 2 layers, per
 * view (96 MiB for a point light's six faces). The maps are kept per light and reused while
 * the view, the light, the casters and the settings stay the same (GetNumberOfMapBuilds());
 * the least recently used lights' maps are dropped beyond 512 MiB in all.
 */

#ifndef vtkPenumbraConservativeShadows_h
#define vtkPenumbraConservativeShadows_h

#include "vtkPenumbraExactShadowsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr
#include <vector> // For GetUncertainSamples

class vtkPenumbraReference;
class vtkUnsignedCharArray;
class vtkPenumbraStatistics;

class VTKPENUMBRAEXACTSHADOWS_EXPORT vtkPenumbraConservativeShadows
  : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraConservativeShadows* New();
  vtkTypeMacro(vtkPenumbraConservativeShadows, vtkPenumbraShadowTechnique);

  const char* GetTechniqueName() override { return "conservative"; }
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  void ReleaseGraphicsResources(vtkWindow* window) override;

  /**
   * Steps 1 and 2 without step 3: fills `visibility` like ComputeVisibility for every sample
   * the map decides, and sets `uncertainMask[s]` (resized to one value per sample) to 1 for
   * the uncertain ones, whose visibility is left at 1, else 0. For techniques that resolve the
   * uncertain samples another way (the hybrid linked-list shadow maps,
   * vtkPenumbraLinkedListShadows). The counters describe this classification; NumberOfRays is 0.
   * Returns 1 on success, 0 on failure (with an error reported).
   */
  int Classify(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility,
    vtkUnsignedCharArray* uncertainMask);

  ///@{
  /**
   * CSM texels per side (per cube face for point lights). Default 1024, clamped to
   * [64, 8192]. Higher resolutions classify more samples and trace fewer rays.
   */
  vtkSetClampMacro(Resolution, int, 64, 8192);
  vtkGetMacro(Resolution, int);
  ///@}

  /**
   * Who builds the conservative map.
   * - MAP_CPU (default): exact conservative rasterization in double precision on the CPU
   *   (vtkSMPTools over binned tiles, separating-axis texel tests; see
   *   vtkPenumbraConservativeMapCPU.h). All layers in one pass, no read back; triangles in
   *   a point light's apex region are tested exactly per sample instead of filling the map.
   * - MAP_GPU: the geometry-shader program described above (one draw per layer, read back).
   * Both give maps the same classification rules use, so both are exact; they differ in
   * cost: on llvmpipe the geometry shader runs on the CPU cores too, and MAP_CPU is the
   * faster (see the class description).
   */
  enum MapBuilders
  {
    MAP_CPU = 0,
    MAP_GPU = 1
  };
  vtkSetClampMacro(MapBuilder, int, MAP_CPU, MAP_GPU);
  vtkGetMacro(MapBuilder, int);

  /**
   * CPU builder: texel/triangle pairs written into the map by the last call (all views).
   */
  vtkGetMacro(NumberOfTexelWrites, vtkIdType);

  ///@{
  /**
   * Depth-peeled CSM layers. Layer k stores the nearest triangle no earlier layer stores at
   * that texel, so a sample can look past its own triangle and past neighbours that provably
   * miss its shadow ray (coplanar neighbours at shared edges). Two layers replace the
   * inexact "own id -> lit" rule of Hertel et al. 2009, §4.2. Clamped to [2, 4]. Default 2:
   * a third layer cuts the uncertain share several-fold, but when rays are traced on the
   * same CPU cores that rasterize the map (llvmpipe), the rays it saves cost about what the
   * layer costs; where rays are dearer than map texels, use 3 or 4.
   */
  vtkSetClampMacro(Layers, int, 2, 4);
  vtkGetMacro(Layers, int);
  ///@}

  ///@{
  /**
   * Classification of the last ComputeVisibility call. Every valid sample is counted once:
   * lit (incl. lights that are off), shadowed (incl. facing away from the light and outside
   * a spot cone) or uncertain. Lit + shadowed + uncertain = valid samples.
   */
  vtkGetMacro(NumberOfLitSamples, vtkIdType);
  vtkGetMacro(NumberOfShadowedSamples, vtkIdType);
  vtkGetMacro(NumberOfUncertainSamples, vtkIdType);
  ///@}

#ifndef __VTK_WRAP__
  /**
   * The uncertain samples of the last call (mask value 1), ascending; valid until the next
   * call. A caller that resolves them (llsm-hybrid) reads them here instead of scanning
   * every sample's mask.
   */
  const std::vector<vtkIdType>& GetUncertainSamples();
#endif

  /**
   * Uncertain / (lit + shadowed + uncertain) of the last call; 0 without valid samples.
   */
  double GetUncertainFraction() override;

  /**
   * Shadow rays of the last call: one per uncertain sample.
   */
  vtkGetMacro(NumberOfRays, vtkIdType);

  ///@{
  /**
   * Phase times of the last call in milliseconds: building the maps (upload, render,
   * read back; glFinish included by the read back), classifying, tracing.
   */
  vtkGetMacro(MapTimeMs, double);
  vtkGetMacro(ClassifyTimeMs, double);
  vtkGetMacro(TraceTimeMs, double);
  ///@}

  /**
   * How many times the caster vertices were uploaded to the GPU since construction.
   */
  vtkGetMacro(NumberOfUploads, int);

  /**
   * Number of shadow map views the last call used (1, or 6 for point lights).
   */
  vtkGetMacro(NumberOfViews, int);

  /**
   * Number of those views whose maps the last call built. The others were reused: each
   * light's maps are kept (up to 512 MB in all, least recently used lights dropped first)
   * and rebuilt only when the view (it covers the pending samples, so a camera move that
   * changes their extent changes it), the light, the casters or the settings change.
   */
  vtkGetMacro(NumberOfMapBuilds, int);

  /**
   * The ray tracer for the uncertain samples (exposed for its statistics and epsilons).
   */
  vtkPenumbraReference* GetReference()
  {
    return this->Reference;
  }

protected:
  vtkPenumbraConservativeShadows();
  ~vtkPenumbraConservativeShadows() override;

  int Resolution = 1024;
  int Layers = 2;
  int MapBuilder = MAP_CPU;
  vtkIdType NumberOfTexelWrites = 0;
  vtkIdType NumberOfLitSamples = 0;
  vtkIdType NumberOfShadowedSamples = 0;
  vtkIdType NumberOfUncertainSamples = 0;
  vtkIdType NumberOfRays = 0;
  double MapTimeMs = 0.0;
  double ClassifyTimeMs = 0.0;
  double TraceTimeMs = 0.0;
  int NumberOfUploads = 0;
  int NumberOfViews = 0;
  int NumberOfMapBuilds = 0;
  vtkPenumbraReference* Reference;

private:
  vtkPenumbraConservativeShadows(const vtkPenumbraConservativeShadows&) = delete;
  void operator=(const vtkPenumbraConservativeShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
