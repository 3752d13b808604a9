#include "vtkPenumbraShadowMapPass.h"

#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraShadowMapShadows.h"

vtkStandardNewMacro(vtkPenumbraShadowMapPass);

vtkPenumbraShadowMapPass::vtkPenumbraShadowMapPass()
{
  this->SetTechnique(vtkNew<vtkPenumbraShadowMapShadows>());
}

vtkPenumbraShadowMapShadows* vtkPenumbraShadowMapPass::GetShadowMaps()
{
  return vtkPenumbraShadowMapShadows::SafeDownCast(this->GetTechnique());
}

void vtkPenumbraShadowMapPass::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
