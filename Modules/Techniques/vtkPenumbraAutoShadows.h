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
 *   It is the fastest exact hard-shadow technique on the bench scenes and in the scale sweep
 *   (docs/results.md; docs/benchmarks-scale-sweep.md). Every quality picks it: the inexact
 *   candidate, `shadowmap` (Brabec, "Shadow Techniques for Interactive and Real-Time
 *   Applications", PhD thesis, 2003, ch. 4-6), saves little or no time over it there, which
 *   does not pay for its mismatch. A shadow map reads nothing back to the CPU, which may pay
 *   off where the rasterizer is a GPU rather than the CPU cores the ray tracer also needs;
 *   this rule has not been measured on such a machine.
 * - area and linear lights with k >= 8 light samples per axis: `gears`
 *   (vtkPenumbraGearsShadows; Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient
 *   Algorithm for Rendering Shadows", Computer Graphics Forum 33(6), 2014) at the light's
 *   own k: exact, bit for bit the visibility of `raytraced` at the same k, and on the city
 *   faster than it from k = 8 on, the more so the larger k (docs/gears.md). With k <= 4,
 *   `raytraced`, as fast as gears or faster at so few light samples (docs/gears.md).
 *   Either way the answer is exact; on scenes where the other one is faster (dense meshes
 *   at k = 8, docs/benchmarks.md) the choice only costs time: a cost model calibrated per
 *   scene is what would decide those.
 *   QUALITY_FAST uses k = 4 (unless SamplesPerAxis says otherwise): fewer light samples is
 *   the one trade of error for time among exact techniques (a coarser estimate of the same
 *   penumbra, at a fraction of the cost; docs/results.md has both at samples=4 and 8).
 *
 * A time budget (`budget_ms`) is not offered: the rule above is fixed, not a cost model
 * calibrated on the machine at hand, so a budget could not be honoured.
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
    QUALITY_BALANCED = 1, ///< exact techniques, the faster per light (default; as EXACT)
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
