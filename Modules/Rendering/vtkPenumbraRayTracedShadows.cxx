#include "vtkPenumbraRayTracedShadows.h"

#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraReference.h"
#include "vtkTimerLog.h"

vtkStandardNewMacro(vtkPenumbraRayTracedShadows);

vtkPenumbraRayTracedShadows::vtkPenumbraRayTracedShadows()
  : Reference(vtkPenumbraReference::New())
{
}

vtkPenumbraRayTracedShadows::~vtkPenumbraRayTracedShadows()
{
  this->Reference->Delete();
}

int vtkPenumbraRayTracedShadows::ComputeVisibility(vtkRenderer*, vtkPenumbraSceneGeometry* geometry,
  vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility)
{
  const double start = vtkTimerLog::GetUniversalTime();
  // SetGeometry rebuilds the acceleration structure only when the geometry changed.
  this->Reference->SetGeometry(geometry);
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  int ok = 0;
  if (area && this->SamplesPerAxis > 0 && this->SamplesPerAxis != area->GetSamplesPerAxis())
  {
    // A copy of the light with the requested k: the positions follow the light's own rule.
    vtkPenumbraAreaLight* copy = vtkPenumbraAreaLight::SafeDownCast(area->ShallowClone());
    copy->SetSamplesPerAxis(this->SamplesPerAxis);
    ok = this->Reference->ComputeVisibility(samples, copy, visibility);
    copy->Delete();
  }
  else
  {
    ok = this->Reference->ComputeVisibility(samples, light, visibility);
  }
  this->LastTimeMs = 1000.0 * (vtkTimerLog::GetUniversalTime() - start);
  return ok;
}

void vtkPenumbraRayTracedShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SamplesPerAxis: " << this->SamplesPerAxis << "\n";
}
