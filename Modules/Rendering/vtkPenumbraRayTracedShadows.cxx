#include "vtkPenumbraRayTracedShadows.h"

#include "vtkObjectFactory.h"
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

int vtkPenumbraRayTracedShadows::ComputeVisibility(vtkRenderer*,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const double start = vtkTimerLog::GetUniversalTime();
  // SetGeometry rebuilds the acceleration structure only when the geometry changed.
  this->Reference->SetGeometry(geometry);
  const int ok = this->Reference->ComputeVisibility(samples, light, visibility);
  this->LastTimeMs = 1000.0 * (vtkTimerLog::GetUniversalTime() - start);
  return ok;
}

void vtkPenumbraRayTracedShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
