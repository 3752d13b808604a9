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
 *   docs/benchmarks-scale-sweep.md, up to 1e7 triangles). `shadowmap` was no faster there
 *   and is not exact, so QUALITY_BALANCED also picks `raytraced`.
 *   QUALITY_FAST picks `shadowmap` (vtkPenumbraShadowMapShadows, Brabec, "Shadow Techniques
 *   for Interactive and Real-Time Applications", PhD thesis, 2003, ch. 4-6): the only
 *   technique that reads nothing back to the CPU, which pays off where the rasterizer is a
 *   GPU rather than the CPU cores the ray tracer also needs; mismatch about 2.5e-4 at 2048²
 *   in the same measurements.
 * - area and linear lights: `gears` (vtkPenumbraGearsShadows; Wang, Wang, Shi, Popescu,
 *   "GEARS: A General and Efficient Algorithm for Rendering Shadows", Computer Graphics
 *   Forum 33(6), 2014) at the light's own k: exact, bit for bit the visibility of `raytraced`
 *   at the same k, and 2.5x (k = 8) to 25x (k = 32) faster on the city (docs/gears.md).
 *   QUALITY_FAST uses k = 4 (SamplesPerAxis), the cheapest measured point: MAE 0.0044
 *   against the converged estimate where k = 8 gives 0.0016 (docs/benchmarks.md, GEARS).
 *
 * A time budget (`budget_ms`) is not offered: the measurements above are from one machine
 * and no cost model calibrated from them is stored yet, so a budget could not be honoured.
 */

#ifndef vtkPenumbraAutoShadows_h
#define vtkPenumbraAutoShadows_h

#include "vtkPenumbraRenderingModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr

class VTKPENUMBRARENDERING_EXPORT vtkPenumbraAutoShadows : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraAutoShadows* New();
  vtkTypeMacro(vtkPenumbraAutoShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Qualities
  {
    QUALITY_EXACT = 0,    ///< exact techniques only
    QUALITY_BALANCED = 1, ///< the best measured error for the time (default)
    QUALITY_FAST = 2      ///< the fastest measured settings, not exact
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
