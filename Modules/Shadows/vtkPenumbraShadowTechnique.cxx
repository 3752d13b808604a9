#include "vtkPenumbraShadowTechnique.h"

#include "vtkCollection.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraStatistics.h"
#include "vtkPenumbraViewSamples.h"

bool vtkPenumbraShadowTechnique::CanShadow(vtkLight* light)
{
  return light && (this->HandlesAreaLights() || !vtkPenumbraAreaLight::SafeDownCast(light));
}

vtkPenumbraShadowTechnique* vtkPenumbraShadowTechnique::SelectTechnique(
  vtkLight* light, std::string& why)
{
  if (!this->CanShadow(light))
  {
    why = std::string(this->GetTechniqueName()) + " cannot shadow this light";
    return nullptr;
  }
  why = "the pass's technique";
  return this;
}

int vtkPenumbraShadowTechnique::ComputeFrameLights(
  vtkPenumbraFrame* frame, const char* what, const std::function<bool(int, std::string&)>& light)
{
  int done = 0;
  for (int k = 0; frame && k < frame->GetNumberOfShadowedLights(); ++k)
  {
    std::string error;
    if (light(k, error))
    {
      frame->MarkOnGPU(k);
      ++done;
    }
    else
    {
      vtkErrorMacro(<< what << ": " << error);
    }
  }
  return done;
}

void vtkPenumbraShadowTechnique::GetStatistics(vtkLight*, vtkPenumbraStatistics* stats)
{
  stats->Set("time_ms", this->LastTimeMs);
  const double uncertain = this->GetUncertainFraction();
  if (uncertain >= 0.0)
  {
    stats->Set("uncertain_share", uncertain);
  }
}

const char* vtkPenumbraShadowTechnique::GetTechniqueNameFor(vtkLight*)
{
  return this->GetTechniqueName();
}

const char* vtkPenumbraShadowTechnique::GetTechniqueName()
{
  return this->GetClassName();
}

int vtkPenumbraShadowTechnique::ComputeFrame(vtkPenumbraFrame* frame)
{
  const int lights = frame->GetNumberOfShadowedLights();
  vtkPenumbraViewSamples* samples = lights > 0 ? frame->GetSamples() : nullptr;
  if (!samples)
  {
    return 0;
  }
  vtkNew<vtkLightCollection> casting;
  vtkNew<vtkCollection> results;
  for (int k = 0; k < lights; ++k)
  {
    if (this->FrameResults.size() <= static_cast<size_t>(k))
    {
      this->FrameResults.push_back(vtkSmartPointer<vtkFloatArray>::New());
    }
    casting->AddItem(frame->GetShadowedLight(k));
    results->AddItem(this->FrameResults[static_cast<size_t>(k)]);
  }
  this->ComputeVisibilities(frame->GetRenderer(), frame->GetGeometry(), samples, casting, results);
  int done = 0;
  for (int k = 0; k < lights; ++k)
  {
    vtkFloatArray* vis = this->FrameResults[static_cast<size_t>(k)];
    if (vis->GetNumberOfTuples() == samples->GetNumberOfSamples())
    {
      frame->SetVisibility(k, vis);
      ++done;
    }
  }
  return done;
}

int vtkPenumbraShadowTechnique::ComputeVisibilities(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLightCollection* lights,
  vtkCollection* visibilities)
{
  if (!lights || !visibilities || lights->GetNumberOfItems() != visibilities->GetNumberOfItems())
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
