/**
 * @class   vtkPenumbraShadowMapPass
 * @brief   Drop-in replacement for VTK's vtkShadowMapPass: vtkPenumbraShadowPass with the
 *          practical shadow-map technique (Brabec, "Shadow Techniques for Interactive and
 *          Real-Time Applications", PhD thesis, 2003, ch. 4-6) already installed.
 *
 * Existing code keeps its composition, only the class name changes:
 * @code
 * vtkNew<vtkPenumbraShadowMapPass> shadows;           // was vtkShadowMapPass
 * passes->AddItem(shadows->GetShadowMapBakerPass());  // a no-op stand-in
 * passes->AddItem(shadows);
 * sequence->SetPasses(passes);
 * cameraPass->SetDelegatePass(sequence);
 * @endcode
 * Occluders and receivers are marked with vtkPenumbraShadowKeys. Unlike VTK's pass it
 * shadows point lights (cube or dual-paraboloid maps), translucent props and PBR receivers,
 * does not leak light (plain depth compare, optional PCF instead of an exponential map) and
 * fits its maps to the visible receivers; see vtkPenumbraShadowMapShadows for the settings
 * (GetShadowMaps()).
 */

#ifndef vtkPenumbraShadowMapPass_h
#define vtkPenumbraShadowMapPass_h

#include "vtkPenumbraShadowMapsModule.h" // For export macro
#include "vtkPenumbraShadowPass.h"

class vtkPenumbraShadowMapShadows;

class VTKPENUMBRASHADOWMAPS_EXPORT vtkPenumbraShadowMapPass : public vtkPenumbraShadowPass
{
public:
  static vtkPenumbraShadowMapPass* New();
  vtkTypeMacro(vtkPenumbraShadowMapPass, vtkPenumbraShadowPass);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The technique's settings (resolution, filter, bias, point-light maps); nullptr if
   * another technique was installed with SetTechnique().
   */
  vtkPenumbraShadowMapShadows* GetShadowMaps();

protected:
  vtkPenumbraShadowMapPass();
  ~vtkPenumbraShadowMapPass() override = default;

private:
  vtkPenumbraShadowMapPass(const vtkPenumbraShadowMapPass&) = delete;
  void operator=(const vtkPenumbraShadowMapPass&) = delete;
};

#endif
