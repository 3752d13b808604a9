/**
 * @class   vtkPenumbraRayTracedShadows
 * @brief   Shadows ray traced on the CPU for every view sample, with the exact reference.
 *
 * Runs vtkPenumbraReference (Embree) as a technique: one shadow ray per sample for point,
 * spot and directional lights, the light's fixed k x k samples for area and linear lights.
 * It is exact by construction and is the baseline every other technique is timed against.
 *
 * SamplesPerAxis (default 0: the light's own k) overrides an area light's k with the same
 * cell-centre positions, so soft-shadow techniques can be timed against it at equal k.
 *
 * AdaptiveBlock > 1 turns it into an approximate soft-shadow technique (`adaptive-soft`):
 * for area and linear lights the exact rays are traced only at the corners and centres of
 * blocks AdaptiveBlock pixels wide; a block whose samples lie on one prop, and whose centre
 * the corners predict bilinearly within AdaptiveTolerance, is interpolated, and every other
 * block is split in four and its children treated the same way, down to 2-pixel blocks,
 * which are traced whole. This is the adaptive sampling of
 * Brabec 2003, ch. 11.3 (corners of a block computed, the inside interpolated when they
 * agree, refined where they do not), with the exact ray-traced visibility in place of the
 * chapter's depth-map search and a traced centre as the agreement test. Soft shadows vary
 * smoothly inside a penumbra, so the error stays small; a shadow detail narrower than a
 * block that touches neither its corners nor its centre is lost. Hard lights are traced at
 * every sample as before.
 */

#ifndef vtkPenumbraRayTracedShadows_h
#define vtkPenumbraRayTracedShadows_h

#include "vtkPenumbraExactShadowsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

class vtkPenumbraReference;
class vtkPenumbraStatistics;

class VTKPENUMBRAEXACTSHADOWS_EXPORT vtkPenumbraRayTracedShadows : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraRayTracedShadows* New();
  vtkTypeMacro(vtkPenumbraRayTracedShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  /// Area and linear lights are traced at their k x k samples.
  bool HandlesAreaLights() override { return true; }

  ///@{
  /**
   * Light samples per axis for area and linear lights: 0 (default) uses the light's own
   * SamplesPerAxis, otherwise k in [1, 64] replaces it (same cell-centre positions). No unit.
   */
  vtkSetClampMacro(SamplesPerAxis, int, 0, 64);
  vtkGetMacro(SamplesPerAxis, int);
  ///@}

  ///@{
  /**
   * Adaptive sampling for area and linear lights (see the class description): the block
   * size in pixels, 0 (default: every sample traced, exact) or 2 to 16.
   */
  void SetAdaptiveBlock(int block);
  vtkGetMacro(AdaptiveBlock, int);
  ///@}

  ///@{
  /**
   * The largest difference between a block centre's traced visibility and the bilinear
   * prediction from the block's corners for which the block is interpolated. Visibility
   * units (0 to 1); default 0.05.
   */
  vtkSetClampMacro(AdaptiveTolerance, double, 0.0, 1.0);
  vtkGetMacro(AdaptiveTolerance, double);
  ///@}

  /// The share of valid view samples traced in the last frame (adaptive mode; -1 otherwise).
  double GetUncertainFraction() override { return this->TracedFraction; }

  const char* GetTechniqueName() override
  {
    return this->AdaptiveBlock > 1 ? "adaptive-soft" : "raytraced";
  }
  /** `adaptive-soft` traces hard lights at every sample, as `raytraced`. */
  const char* GetTechniqueNameFor(vtkLight* light) override;

  /**
   * The ray tracer (exposed for its statistics and epsilon settings).
   */
  vtkPenumbraReference* GetReference() { return this->Reference; }

protected:
  vtkPenumbraRayTracedShadows();
  ~vtkPenumbraRayTracedShadows() override;

  int ComputeAdaptive(vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility);

  vtkPenumbraReference* Reference;
  int SamplesPerAxis = 0;
  int AdaptiveBlock = 0;
  double AdaptiveTolerance = 0.05;
  double TracedFraction = -1.0;

private:
  vtkPenumbraRayTracedShadows(const vtkPenumbraRayTracedShadows&) = delete;
  void operator=(const vtkPenumbraRayTracedShadows&) = delete;
};

#endif
