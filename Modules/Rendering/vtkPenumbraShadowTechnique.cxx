#include "vtkPenumbraShadowTechnique.h"

#include "vtkCollection.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"

int vtkPenumbraShadowTechnique::ComputeVisibilities(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLightCollection* lights,
  vtkCollection* visibilities)
{
  if (!lights || !visibilities ||
    lights->GetNumberOfItems() != visibilities->GetNumberOfItems())
  {
    vtkErrorMacro("ComputeVisibilities needs one visibility array per light");
    return 0;
  }
  int done = 0;
  for (int i = 0; i < lights->GetNumberOfItems(); ++i)
  {
    auto* light = vtkLight::SafeDownCast(lights->GetItemAsObject(i));
    auto* vis = vtkFloatArray::SafeDownCast(visibilities->GetItemAsObject(i));
    if (!light || !vis)
    {
      vtkErrorMacro("ComputeVisibilities: item " << i << " is not a light and a float array");
      continue;
    }
    if (this->ComputeVisibility(renderer, geometry, samples, light, vis))
    {
      ++done;
    }
    else
    {
      vis->SetNumberOfTuples(0);
    }
  }
  return done;
}

void vtkPenumbraShadowTechnique::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "LastTimeMs: " << this->LastTimeMs << "\n";
}
