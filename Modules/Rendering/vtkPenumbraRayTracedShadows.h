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
 */

#ifndef vtkPenumbraRayTracedShadows_h
#define vtkPenumbraRayTracedShadows_h

#include "vtkPenumbraRenderingModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

class vtkPenumbraReference;

class VTKPENUMBRARENDERING_EXPORT vtkPenumbraRayTracedShadows : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraRayTracedShadows* New();
  vtkTypeMacro(vtkPenumbraRayTracedShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

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

  /**
   * The ray tracer (exposed for its statistics and epsilon settings).
   */
  vtkPenumbraReference* GetReference() { return this->Reference; }

protected:
  vtkPenumbraRayTracedShadows();
  ~vtkPenumbraRayTracedShadows() override;

  vtkPenumbraReference* Reference;
  int SamplesPerAxis = 0;

private:
  vtkPenumbraRayTracedShadows(const vtkPenumbraRayTracedShadows&) = delete;
  void operator=(const vtkPenumbraRayTracedShadows&) = delete;
};

#endif
