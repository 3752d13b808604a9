#include "vtkPenumbraAutoShadows.h"

#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkSmartPointer.h"

// The members are made on first use: a scene without area lights never builds GEARS.
struct vtkPenumbraAutoShadows::Internals
{
  vtkSmartPointer<vtkPenumbraRayTracedShadows> Traced;
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
      : this->Quality == QUALITY_FAST      ? 4
                                           : 0;
    const int used = k > 0 ? k : area->GetSamplesPerAxis();
    const std::string fast = this->Quality == QUALITY_FAST && this->SamplesPerAxis == 0
      ? "; quality=fast: k = 4, fewer light samples for less time"
      : "";
    // Both are exact and give the same visibility at the same k; only the time differs.
    if (used <= 4)
    {
      if (!impl.Traced)
      {
        impl.Traced = vtkSmartPointer<vtkPenumbraRayTracedShadows>::New();
      }
      impl.Traced->SetSamplesPerAxis(k);
      why = "soft light at k = " + std::to_string(used) +
        ": exact; at k <= 4 the ray tracer is as fast as gears or faster (docs/gears.md)" + fast;
      return impl.Traced;
    }
    if (!impl.Gears)
    {
      impl.Gears = vtkSmartPointer<vtkPenumbraGearsShadows>::New();
    }
    impl.Gears->SetSamplesPerAxis(k);
    why = "soft light at k = " + std::to_string(used) +
      ": exact, the same visibility as raytraced at that k and faster on the city for "
      "k >= 8 (docs/gears.md)" +
      fast;
    return impl.Gears;
  }
  if (!impl.Traced)
  {
    impl.Traced = vtkSmartPointer<vtkPenumbraRayTracedShadows>::New();
  }
  static const char* const names[] = { "exact", "balanced", "fast" };
  why = std::string("hard light, quality=") + names[this->Quality] +
    ": exact, and the fastest exact hard-shadow technique on the bench scenes "
    "(docs/results.md)";
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
  for (vtkPenumbraShadowTechnique* t : { static_cast<vtkPenumbraShadowTechnique*>(impl.Traced),
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
