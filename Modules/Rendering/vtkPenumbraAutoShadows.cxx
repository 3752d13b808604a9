#include "vtkPenumbraAutoShadows.h"

#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkSmartPointer.h"

// The members are made on first use: a scene without area lights never builds GEARS.
struct vtkPenumbraAutoShadows::Internals
{
  vtkSmartPointer<vtkPenumbraRayTracedShadows> Traced;
  vtkSmartPointer<vtkPenumbraShadowMapShadows> Maps;
  vtkSmartPointer<vtkPenumbraGearsShadows> Gears;
};

vtkStandardNewMacro(vtkPenumbraAutoShadows);

vtkPenumbraAutoShadows::vtkPenumbraAutoShadows()
  : Impl(new Internals)
{
}

vtkPenumbraAutoShadows::~vtkPenumbraAutoShadows() = default;

vtkPenumbraShadowTechnique* vtkPenumbraAutoShadows::SelectTechnique(
  vtkLight* light, std::string& why)
{
  Internals& impl = *this->Impl;
  if (!light)
  {
    return nullptr;
  }
  if (auto* area = vtkPenumbraAreaLight::SafeDownCast(light))
  {
    const int k = this->SamplesPerAxis > 0 ? this->SamplesPerAxis
      : this->Quality == QUALITY_FAST     ? 4
                                          : 0;
    if (!impl.Gears)
    {
      impl.Gears = vtkSmartPointer<vtkPenumbraGearsShadows>::New();
    }
    impl.Gears->SetSamplesPerAxis(k);
    const int used = k > 0 ? k : area->GetSamplesPerAxis();
    why = "soft light: exact soft shadows at k = " + std::to_string(used) +
      ", the same visibility as raytraced at that k and 2.5-25x faster on the city for k >= 8 "
      "(docs/gears.md)" +
      (this->Quality == QUALITY_FAST && this->SamplesPerAxis == 0
          ? std::string("; quality=fast: k = 4, the cheapest measured setting")
          : std::string());
    return impl.Gears;
  }
  if (this->Quality == QUALITY_FAST)
  {
    if (!impl.Maps)
    {
      impl.Maps = vtkSmartPointer<vtkPenumbraShadowMapShadows>::New();
    }
    why = "hard light, quality=fast: shadow maps on the GPU, nothing read back; mismatch "
          "about 2.5e-4 at 2048^2 (docs/benchmarks.md)";
    return impl.Maps;
  }
  if (!impl.Traced)
  {
    impl.Traced = vtkSmartPointer<vtkPenumbraRayTracedShadows>::New();
  }
  why = std::string("hard light, quality=") +
    (this->Quality == QUALITY_EXACT ? "exact" : "balanced") +
    ": the fastest exact hard-shadow technique measured, 1.4-2.5x the unshadowed frame "
    "against 1.8-3.4x for conservative and 2.9-5.6x for volumes (docs/benchmarks.md)";
  return impl.Traced;
}

int vtkPenumbraAutoShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  std::string why;
  vtkPenumbraShadowTechnique* chosen = this->SelectTechnique(light, why);
  if (!chosen)
  {
    vtkErrorMacro("ComputeVisibility needs a light");
    return 0;
  }
  const int ok = chosen->ComputeVisibility(renderer, geometry, samples, light, visibility);
  this->LastTimeMs = chosen->GetLastTimeMs();
  return ok;
}

void vtkPenumbraAutoShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  Internals& impl = *this->Impl;
  for (vtkPenumbraShadowTechnique* t :
    { static_cast<vtkPenumbraShadowTechnique*>(impl.Traced), static_cast<vtkPenumbraShadowTechnique*>(impl.Maps),
      static_cast<vtkPenumbraShadowTechnique*>(impl.Gears) })
  {
    if (t)
    {
      t->ReleaseGraphicsResources(window);
    }
  }
}

void vtkPenumbraAutoShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Quality: " << this->Quality << "\n";
  os << indent << "SamplesPerAxis: " << this->SamplesPerAxis << "\n";
}
