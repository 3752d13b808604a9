/**
 * @class   vtkPenumbraAutoShadows
 * @brief   Chooses a technique per light: what the measurements say is the best one for the
 *          light's type at the requested quality (the `auto` technique of the registry).
 *
 * Users should not need the error-against-time chart to get good shadows. Per light (see
 * SelectTechnique(); vtkPenumbraShadowPass runs each chosen technique on the lights it was
 * chosen for, all in one frame):
 *
 * - point, spot and directional lights: `raytraced` (vtkPenumbraRayTracedShadows), exact.
 *   It was the fastest exact hard-shadow technique in every measurement on the project's
 *   machine (docs/benchmarks.md, "The frame on the GPU", 2026-11-25, 1280 x 720: still
 *   camera 1.4-1.9x the unshadowed frame on the city against 1.8x for `conservative` and
 *   2.9x for `volumes`, 2.5x against 3.4x and 5.6x on the isosurface; and in the scale sweep,
 *   docs/benchmarks-scale-sweep.md, up to 1e7 triangles). Every quality picks it: the
 *   inexact candidate, `shadowmap` (Brabec, "Shadow Techniques for Interactive and Real-Time
 *   Applications", PhD thesis, 2003, ch. 4-6; mismatch about 2.5e-4 at 2048²), was slower
 *   than `raytraced` in every one of those measurements (still, moving light, moving camera,
 *   1e4-1e7 triangles; within 4 % at best), so choosing it would be both slower and wrong.
 *   It reads nothing back to the CPU, which may pay off where the rasterizer is a GPU
 *   rather than the CPU cores the ray tracer also needs: that needs measurements there.
 * - area and linear lights with k >= 8 light samples per axis: `gears`
 *   (vtkPenumbraGearsShadows; Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient
 *   Algorithm for Rendering Shadows", Computer Graphics Forum 33(6), 2014) at the light's
 *   own k: exact, bit for bit the visibility of `raytraced` at the same k, and 2.5x (k = 8)
 *   to 25x (k = 32) faster on the city (docs/gears.md). With k <= 4, `raytraced`: as fast or
 *   faster there (city 79 vs 76 ms, the two-light area_light scene 226 vs 1046 ms). Where the
 *   measurements disagree with this rule (gears slower at k = 8 on the dense bunny, carotid
 *   and 1 M-triangle isosurface and on area_light, docs/benchmarks.md) the answer is the same,
 *   only slower: a cost model calibrated per scene is what would decide those.
 *   QUALITY_FAST uses k = 4 (unless SamplesPerAxis says otherwise), the cheapest measured
 *   point: MAE 0.0044 against the converged estimate where k = 8 gives 0.0016 and 50 against
 *   72 ms a frame on the city at 1280 x 720 (docs/benchmarks.md, GEARS). Fewer light
 *   samples is the one measured trade of error for time.
 *
 * A time budget (`budget_ms`) is not offered: the measurements above are from one machine
 * and no cost model calibrated from them is stored yet, so a budget could not be honoured.
 */

#ifndef vtkPenumbraAutoShadows_h
#define vtkPenumbraAutoShadows_h

#include "vtkPenumbraTechniquesModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr

class VTKPENUMBRATECHNIQUES_EXPORT vtkPenumbraAutoShadows : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraAutoShadows* New();
  vtkTypeMacro(vtkPenumbraAutoShadows, vtkPenumbraShadowTechnique);

  const char* GetTechniqueName() override { return "auto"; }
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Qualities
  {
    QUALITY_EXACT = 0,    ///< exact techniques only
    QUALITY_BALANCED = 1, ///< the best measured error for the time (default)
    QUALITY_FAST = 2      ///< fewer light samples for soft lights, not exact
  };

  ///@{
  /**
   * What the choice optimises (see the class description). Default QUALITY_BALANCED.
   */
  vtkSetClampMacro(Quality, int, QUALITY_EXACT, QUALITY_FAST);
  vtkGetMacro(Quality, int);
  void SetQualityToExact() { this->SetQuality(QUALITY_EXACT); }
  void SetQualityToBalanced() { this->SetQuality(QUALITY_BALANCED); }
  void SetQualityToFast() { this->SetQuality(QUALITY_FAST); }
  ///@}

  ///@{
  /**
   * Light samples per axis of the soft-shadow technique for area and linear lights: 0
   * (default) keeps the light's own k (QUALITY_FAST: 4), otherwise k in [1, 64].
   */
  vtkSetClampMacro(SamplesPerAxis, int, 0, 64);
  vtkGetMacro(SamplesPerAxis, int);
  ///@}

  /** Every light: area and linear lights go to a soft-shadow technique. */
  bool HandlesAreaLights() override { return true; }

  vtkPenumbraShadowTechnique* SelectTechnique(vtkLight* light, std::string& why) override;

  /** Runs the technique SelectTechnique() chooses for `light`. */
  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkPenumbraAutoShadows();
  ~vtkPenumbraAutoShadows() override;

  int Quality = QUALITY_BALANCED;
  int SamplesPerAxis = 0;

private:
  vtkPenumbraAutoShadows(const vtkPenumbraAutoShadows&) = delete;
  void operator=(const vtkPenumbraAutoShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
