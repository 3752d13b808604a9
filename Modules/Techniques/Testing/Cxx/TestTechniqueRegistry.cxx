// The technique registry: names are unique, options are validated, a failed Apply leaves the
// renderer as it was.
#include "vtkNew.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowVolumeShadows.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderPass.h"
#include "vtkRenderer.h"

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <set>
#include <string>

#include "PenumbraTestMacros.h"

namespace
{
// The technique `name` installs on `renderer` with the table's defaults.
template <class T>
T* Installed(vtkPenumbraTechniques* t, vtkRenderer* renderer, const char* name)
{
  if (!t->Apply(renderer, name, "{}"))
  {
    return nullptr;
  }
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(renderer);
  return pass ? T::SafeDownCast(pass->GetTechnique()) : nullptr;
}

// The option tables' defaults are the classes' own defaults, so a technique used directly
// (vtkNew<...>, SetTechnique()) behaves as the registry's.
int DefaultsMatchTheClasses()
{
  vtkNew<vtkPenumbraTechniques> t;
  vtkNew<vtkRenderer> ren;

  vtkNew<vtkPenumbraShadowMapShadows> sm;
  auto* smDefault = Installed<vtkPenumbraShadowMapShadows>(t, ren, "shadowmap");
  CHECK(smDefault != nullptr);
  CHECK(smDefault->GetResolution() == sm->GetResolution() &&
    smDefault->GetFilter() == sm->GetFilter() && smDefault->GetPCFKernel() == sm->GetPCFKernel() &&
    smDefault->GetBias() == sm->GetBias() && smDefault->GetSlopeBias() == sm->GetSlopeBias() &&
    smDefault->GetDepthMode() == sm->GetDepthMode() &&
    smDefault->GetPointMode() == sm->GetPointMode() && smDefault->GetLookup() == sm->GetLookup());

  vtkNew<vtkPenumbraConservativeShadows> csm;
  auto* csmDefault = Installed<vtkPenumbraConservativeShadows>(t, ren, "conservative");
  CHECK(csmDefault != nullptr);
  CHECK(csmDefault->GetResolution() == csm->GetResolution() &&
    csmDefault->GetLayers() == csm->GetLayers() &&
    csmDefault->GetMapBuilder() == csm->GetMapBuilder());

  vtkNew<vtkPenumbraShadowVolumeShadows> sv;
  auto* svDefault = Installed<vtkPenumbraShadowVolumeShadows>(t, ren, "volumes");
  CHECK(svDefault != nullptr);
  CHECK(svDefault->GetSilhouettes() == sv->GetSilhouettes() &&
    svDefault->GetGPUSilhouettes() == sv->GetGPUSilhouettes() &&
    svDefault->GetMethod() == sv->GetMethod() && svDefault->GetCull() == sv->GetCull() &&
    svDefault->GetCapOffset() == sv->GetCapOffset() &&
    svDefault->GetResolve() == sv->GetResolve() &&
    svDefault->GetMeasureFill() == sv->GetMeasureFill() &&
    svDefault->GetLightsPerMask() == sv->GetLightsPerMask());

  vtkNew<vtkPenumbraGearsShadows> gears;
  auto* gearsDefault = Installed<vtkPenumbraGearsShadows>(t, ren, "gears");
  CHECK(gearsDefault != nullptr);
  CHECK(gearsDefault->GetSamplesPerAxis() == gears->GetSamplesPerAxis() &&
    gearsDefault->GetGridResolution() == gears->GetGridResolution() &&
    gearsDefault->GetCameraDistanceFactor() == gears->GetCameraDistanceFactor() &&
    gearsDefault->GetTraceThreshold() == gears->GetTraceThreshold() &&
    gearsDefault->GetDenseCells() == gears->GetDenseCells() &&
    gearsDefault->GetPath() == gears->GetPath());

  vtkNew<vtkPenumbraRayTracedShadows> rt;
  auto* rtDefault = Installed<vtkPenumbraRayTracedShadows>(t, ren, "raytraced");
  CHECK(rtDefault != nullptr && rtDefault->GetSamplesPerAxis() == rt->GetSamplesPerAxis());
  return EXIT_SUCCESS;
}
}

int TestTechniqueRegistry(int, char*[])
{
  if (DefaultsMatchTheClasses() != EXIT_SUCCESS)
  {
    return EXIT_FAILURE;
  }
  std::set<std::string> names;
  for (int i = 0; i < vtkPenumbraTechniques::GetNumberOfTechniques(); ++i)
  {
    CHECK(names.insert(vtkPenumbraTechniques::GetTechniqueName(i)).second);
    CHECK(std::strlen(vtkPenumbraTechniques::GetTechniqueDescription(i)) > 0);
  }
  CHECK(names.count("none") && names.count("vtk-shadowmap"));
  CHECK(vtkPenumbraTechniques::GetTechniqueName(-1) == nullptr);
  CHECK(
    !vtkPenumbraTechniques::HasTechnique("nope") && !vtkPenumbraTechniques::HasTechnique(nullptr));

  vtkNew<vtkPenumbraTechniques> t;
  vtkNew<vtkRenderer> ren;
  CHECK(t->Apply(ren, "vtk-shadowmap", R"({"resolution": 512})"));
  vtkRenderPass* installed = ren->GetPass();
  CHECK(installed != nullptr);

  const char* bad[] = { R"({"resolution": 8})", R"({"resolution": 1.5})", R"({"bias": 1})",
    "[1, 2]", "{not json" };
  for (const char* options : bad)
  {
    CHECK(!t->Apply(ren, "vtk-shadowmap", options));
    CHECK(std::strlen(t->GetErrorMessage()) > 0);
    CHECK(ren->GetPass() == installed); // unchanged
  }
  CHECK(!t->Apply(ren, "none", R"({"resolution": 512})"));
  CHECK(std::string(t->GetErrorMessage()).find("has none") != std::string::npos);
  CHECK(t->Apply(ren, "none", ""));
  CHECK(ren->GetPass() == nullptr);
  CHECK(!t->Apply(nullptr, "none", ""));

  // A pass wrapped by the application (ParaView: under IceT's compositing pass) is found
  // once recorded; without the record the camera pass's delegate is.
  CHECK(t->Apply(ren, "raytraced", ""));
  vtkPenumbraShadowPass* own = vtkPenumbraShadowPass::GetInstalled(ren);
  CHECK(own != nullptr);
  vtkNew<vtkPenumbraShadowPass> wrapped;
  vtkPenumbraShadowPass::SetInstalled(ren, wrapped);
  CHECK(vtkPenumbraShadowPass::GetInstalled(ren) == wrapped.GetPointer());
  vtkPenumbraShadowPass::SetInstalled(ren, nullptr);
  CHECK(vtkPenumbraShadowPass::GetInstalled(ren) == own);
  vtkPenumbraShadowPass::SetInstalled(nullptr, wrapped); // ignored

  // Structured ranges and choices (the ParaView plugin's widgets) agree with the tables.
  for (int o = 0; o < vtkPenumbraTechniques::GetNumberOfOptions("shadowmap"); ++o)
  {
    const std::string option = vtkPenumbraTechniques::GetOptionName("shadowmap", o);
    double bounds[2] = { 0, 0 };
    const bool ranged = vtkPenumbraTechniques::GetOptionBounds("shadowmap", o, bounds);
    const auto choices = vtkPenumbraTechniques::GetOptionChoices("shadowmap", o);
    if (option == "resolution")
    {
      CHECK(ranged && bounds[0] == 64 && bounds[1] == 8192 && choices.empty());
    }
    if (option == "filter")
    {
      CHECK(!ranged && choices.size() == 3 && choices[1] == "\"pcf\"");
    }
  }
  const auto samples = vtkPenumbraTechniques::GetOptionChoices("auto", 1);
  CHECK(samples.size() == 5 && samples[2] == "8");
  double unused[2];
  CHECK(!vtkPenumbraTechniques::GetOptionBounds("auto", 1, unused));
  CHECK(!vtkPenumbraTechniques::GetOptionBounds("nope", 0, unused));

  // Every table row is documented, and its default passes its own validation.
  for (int i = 0; i < vtkPenumbraTechniques::GetNumberOfTechniques(); ++i)
  {
    const char* name = vtkPenumbraTechniques::GetTechniqueName(i);
    std::string defaults;
    for (int o = 0; o < vtkPenumbraTechniques::GetNumberOfOptions(name); ++o)
    {
      CHECK(std::strlen(vtkPenumbraTechniques::GetOptionDoc(name, o)) > 0);
      CHECK(!vtkPenumbraTechniques::GetOptionRange(name, o).empty());
      defaults += (defaults.empty() ? "{" : ", ") + std::string("\"") +
        vtkPenumbraTechniques::GetOptionName(name, o) +
        "\": " + vtkPenumbraTechniques::GetOptionDefault(name, o);
    }
    defaults += defaults.empty() ? "{}" : "}";
    vtkNew<vtkRenderer> fresh;
    CHECK(t->Apply(fresh, name, defaults.c_str()));
  }
  CHECK(vtkPenumbraTechniques::GetOptionName("shadowmap", 99) == nullptr);
  CHECK(vtkPenumbraTechniques::GetNumberOfOptions("nope") == 0);
  // Allowed-value lists and ranges from the tables.
  CHECK(!t->Apply(ren, "raytraced", R"({"samples": 5})"));
  CHECK(std::string(t->GetErrorMessage()) == "samples: expected one of 0, 4, 8, 16, 32, got 5");
  CHECK(!t->Apply(ren, "shadowmap", R"({"pcf_kernel": 4})"));
  CHECK(!t->Apply(ren, "gears", R"({"path": "fpga"})"));
  CHECK(std::string(t->GetErrorMessage()) ==
    R"(path: expected one of "auto", "cpu", "gpu", got "fpga")");
  return EXIT_SUCCESS;
}
