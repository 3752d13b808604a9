// vtkPenumbraConservativeShadows (Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for
// Alias-Free Hard Shadows", Eurographics 2009 Areas Papers) against the exact reference on the same
// view samples: zero mismatches outside reference ties for directional, spot and point lights on
// a plane with a thin occluder, on the default city scene and on the torture scenes; a wire
// thinner than one shadow-map texel still casts its full shadow; the counters add up; rays
// are traced only for uncertain samples; unchanged geometry is not uploaded again and
// unchanged maps are not rebuilt.
#include "vtkActor.h"
#include "vtkActorCollection.h"
#include "vtkCamera.h"
#include "vtkCameraPass.h"
#include "vtkCubeSource.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraMetrics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include <cstdio>
#include <string>

namespace
{
using namespace penumbra_technique_tests;

struct Outcome
{
  vtkIdType Shadowed = 0;    // samples the technique shadows
  vtkIdType RefShadowed = 0; // samples the reference shadows
};

// The map builder under test ("cpu" or "gpu"), set by TestConservativeShadows.
std::string Map = "cpu";

// Renders `renderer` with the conservative technique and compares every light's visibility
// with the reference on the same samples. Fails on any non-tie mismatch or bad counters.
int CompareWithReference(const std::string& label, vtkRenderer* renderer, int resolution,
  Outcome* outcome = nullptr, int layers = 2)
{
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(renderer, 128, 96);
  vtkNew<vtkPenumbraTechniques> techniques;
  const std::string options = "{\"resolution\": " + std::to_string(resolution) +
    ", \"layers\": " + std::to_string(layers) + ", \"map\": \"" + Map + "\"}";
  CHECK(techniques->Apply(renderer, "conservative", options.c_str()));
  window->Render();
  vtkPenumbraShadowPass* pass = ShadowPass(renderer);
  CHECK(pass != nullptr);
  auto* technique = vtkPenumbraConservativeShadows::SafeDownCast(pass->GetTechnique());
  CHECK(technique != nullptr);
  CHECK(technique->GetResolution() == resolution);
  CHECK(technique->GetLayers() == layers);
  CHECK(technique->GetMapBuilder() ==
    (Map == "gpu" ? vtkPenumbraConservativeShadows::MAP_GPU
                  : vtkPenumbraConservativeShadows::MAP_CPU));
  CHECK(pass->GetNumberOfLights() >= 1);
  vtkPenumbraViewSamples* samples = pass->GetViewSamples();
  CHECK(samples->GetNumberOfValidSamples() > 0);

  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(pass->GetGeometry());
  vtkNew<vtkPenumbraMetrics> metrics;
  for (int i = 0; i < pass->GetNumberOfLights(); ++i)
  {
    vtkFloatArray* test = pass->GetVisibility(i);
    CHECK(test != nullptr);
    // The counters belong to the last light the technique handled; recompute that light
    // directly so they can be checked for every light.
    vtkNew<vtkFloatArray> direct;
    CHECK(technique->ComputeVisibility(
      renderer, pass->GetGeometry(), samples, pass->GetLight(i), direct));
    vtkNew<vtkFloatArray> ref;
    CHECK(reference->ComputeVisibility(samples, pass->GetLight(i), ref));
    // The masked variant traces only the masked samples and leaves the others untouched.
    {
      const vtkIdType count = samples->GetNumberOfSamples();
      vtkNew<vtkFloatArray> partial;
      partial->SetNumberOfTuples(count);
      vtkNew<vtkUnsignedCharArray> mask;
      mask->SetNumberOfTuples(count);
      for (vtkIdType s = 0; s < count; ++s)
      {
        partial->SetValue(s, 0.5f);
        mask->SetValue(s, static_cast<unsigned char>(s % 3 == 0));
      }
      vtkNew<vtkPenumbraReference> masked;
      masked->SetGeometry(pass->GetGeometry());
      CHECK(masked->ComputeVisibility(samples, pass->GetLight(i), partial, mask));
      for (vtkIdType s = 0; s < count; ++s)
      {
        CHECK(partial->GetValue(s) == (s % 3 == 0 ? ref->GetValue(s) : 0.5f));
      }
      CHECK(masked->GetNumberOfRays() <= reference->GetNumberOfRays());
    }
    CHECK(metrics->CompareHard(test, ref, reference->GetTies()));
    const vtkIdType mismatches = metrics->GetFalseLit() + metrics->GetFalseShadow();
    CHECK(metrics->CompareHard(direct, ref, reference->GetTies()));
    const vtkIdType directMismatches = metrics->GetFalseLit() + metrics->GetFalseShadow();

    const vtkIdType valid = samples->GetNumberOfValidSamples();
    const vtkIdType lit = technique->GetNumberOfLitSamples();
    const vtkIdType shadowed = technique->GetNumberOfShadowedSamples();
    const vtkIdType uncertain = technique->GetNumberOfUncertainSamples();
    vtkIdType refShadowed = 0, testShadowed = 0;
    for (vtkIdType s = 0; s < ref->GetNumberOfTuples(); ++s)
    {
      refShadowed += ref->GetValue(s) == 0.0f && !reference->GetTies()->GetValue(s);
      testShadowed += test->GetValue(s) == 0.0f && !reference->GetTies()->GetValue(s);
    }
    std::printf("%-34s light %d: valid %lld, lit %lld, shadowed %lld, uncertain %lld "
                "(%.1f%%), ties %lld, mismatches %lld (direct %lld), views %d, "
                "map %.1f ms, classify %.1f ms, trace %.1f ms\n",
      (Map + " " + label).c_str(), i, static_cast<long long>(valid), static_cast<long long>(lit),
      static_cast<long long>(shadowed), static_cast<long long>(uncertain),
      valid ? 100.0 * uncertain / valid : 0.0, static_cast<long long>(reference->GetNumberOfTies()),
      static_cast<long long>(mismatches), static_cast<long long>(directMismatches),
      technique->GetNumberOfViews(), technique->GetMapTimeMs(), technique->GetClassifyTimeMs(),
      technique->GetTraceTimeMs());
    if (mismatches)
    {
      std::printf("  false lit %lld, false shadow %lld\n",
        static_cast<long long>(metrics->GetFalseLit()),
        static_cast<long long>(metrics->GetFalseShadow()));
    }
    CHECK(mismatches == 0);
    CHECK(directMismatches == 0);
    CHECK(lit + shadowed + uncertain == valid);
    CHECK(technique->GetNumberOfRays() == uncertain);
    CHECK(technique->GetReference()->GetNumberOfRays() <= uncertain);
    if (outcome)
    {
      outcome->Shadowed += testShadowed;
      outcome->RefShadowed += refShadowed;
    }
  }

  // Nothing changed: the next frame reuses the uploaded casters and every light's maps. The
  // CPU builder uploads nothing.
  const int uploads = technique->GetNumberOfUploads();
  CHECK(Map == "gpu" ? uploads >= 1 : uploads == 0);
  window->Render();
  CHECK(technique->GetNumberOfUploads() == uploads);
  CHECK(technique->GetNumberOfMapBuilds() == 0);
  renderer->GetRenderWindow()->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// (a) Plane z = 0 with a thin square occluder at z = 1 (PlaneScene, spot lights 35 degrees).
int CheckPlane()
{
  for (LightType type : { LightType::Directional, LightType::Spot, LightType::Point })
  {
    for (int layers = 2; layers <= 4; ++layers)
    {
      auto renderer = PlaneScene(type, 0.02, 0.5);
      RUN(CompareWithReference(
        std::string("plane+occluder ") + Name(type) + " L" + std::to_string(layers), renderer, 256,
        nullptr, layers));
    }
  }
  return EXIT_SUCCESS;
}

// A 1 mm wire over a 6 m scene is far thinner than one texel of a 256^2 map: the
// conservative rasterization must still put it into every texel its shadow rays cross.
int CheckThinWire()
{
  for (LightType type : { LightType::Directional, LightType::Spot, LightType::Point })
  {
    // 1 mm x 1 m wire; 8 cm field of view (0.8 mm per sample); 256^2 map over > 8 m.
    auto renderer = PlaneScene(type, 0.001, 0.0005, 0.08);
    Outcome outcome;
    RUN(CompareWithReference(std::string("sub-texel wire ") + Name(type), renderer, 256, &outcome));
    std::printf("  wire shadow: technique %lld, reference %lld samples\n",
      static_cast<long long>(outcome.Shadowed), static_cast<long long>(outcome.RefShadowed));
    CHECK(outcome.RefShadowed > 0);
    CHECK(outcome.Shadowed == outcome.RefShadowed);
  }
  return EXIT_SUCCESS;
}

// (b) The default city scene with its sun, a spot and a point light.
int CheckDefaultScene()
{
  for (LightType type : { LightType::AsInScene, LightType::Spot, LightType::Point })
  {
    vtkNew<vtkPenumbraSceneReader> reader;
    vtkSmartPointer<vtkRenderer> renderer = DefaultSceneWith(type, reader, 35.0);
    CHECK(renderer != nullptr);
    RUN(CompareWithReference(std::string("default.json ") + Name(type), renderer, 1024));
  }
  return EXIT_SUCCESS;
}

// (c) The torture scenes with their own lights.
int CheckTortureScenes()
{
  // Every torture scene with a hard light (the area-light ones belong to soft techniques).
  const char* scenes[] = { "thin_occluders.json", "grazing_light.json", "zenith_light.json",
    "coplanar_contact.json", "bad_triangles.json", "georef_1e6.json", "georef_1e7.json",
    "depth_range.json", "point_light_in_room.json", "point_light_on_surface.json",
    "wall_gaps.json" };
  for (const char* scene : scenes)
  {
    vtkNew<vtkPenumbraSceneReader> reader;
    vtkSmartPointer<vtkRenderer> renderer = ReadScene(std::string("torture/") + scene, reader);
    CHECK(renderer != nullptr);
    RUN(CompareWithReference(std::string("torture/") + scene, renderer, 1024));
    vtkNew<vtkPenumbraSceneReader> again;
    renderer = ReadScene(std::string("torture/") + scene, again);
    CHECK(renderer != nullptr);
    RUN(CompareWithReference(std::string("torture/") + scene + " L3", renderer, 512, nullptr, 3));
  }
  return EXIT_SUCCESS;
}

// The maps are kept between frames and rebuilt exactly when what they were built from
// changes: the light, a caster, or the view. The view covers the pending samples' box grown
// by a tenth (penumbra_light_views::KeptBox), so a camera that turns a little keeps it, and one
// that zooms in (the kept box much larger than needed) or out (the samples outside it)
// refits it. Every frame stays exact.
int CheckMapReuse()
{
  auto renderer = PlaneScene(LightType::Directional, 0.1, 0.5);
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(renderer, 128, 96);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(
    renderer, "conservative", (std::string("{\"map\": \"") + Map + "\"}").c_str()));
  vtkPenumbraShadowPass* pass = ShadowPass(renderer);
  CHECK(pass != nullptr);
  // The technique's own cache is under test: the pass must not skip the technique.
  pass->ReuseUnchangedFramesOff();
  auto* technique = vtkPenumbraConservativeShadows::SafeDownCast(pass->GetTechnique());
  CHECK(technique != nullptr);
  vtkLight* light = vtkLight::SafeDownCast(renderer->GetLights()->GetItemAsObject(0));
  vtkActor* occluder = vtkActor::SafeDownCast(renderer->GetActors()->GetItemAsObject(1));
  CHECK(light != nullptr && occluder != nullptr);

  auto frame = [&](const char* what, bool rebuilt)
  {
    window->Render();
    vtkNew<vtkPenumbraReference> reference;
    reference->SetGeometry(pass->GetGeometry());
    vtkNew<vtkFloatArray> ref;
    vtkNew<vtkPenumbraMetrics> metrics;
    const bool ok = pass->GetVisibility(0) &&
      reference->ComputeVisibility(pass->GetViewSamples(), light, ref) &&
      metrics->CompareHard(pass->GetVisibility(0), ref, reference->GetTies());
    const vtkIdType mismatches = metrics->GetFalseLit() + metrics->GetFalseShadow();
    std::printf("%s map reuse, %-22s builds %d of %d views, map %.2f ms, mismatches %lld\n",
      Map.c_str(), what, technique->GetNumberOfMapBuilds(), technique->GetNumberOfViews(),
      technique->GetMapTimeMs(), static_cast<long long>(mismatches));
    return ok && mismatches == 0 && metrics->GetCandidates() > 1000 &&
      (technique->GetNumberOfMapBuilds() > 0) == rebuilt;
  };
  CHECK(frame("first frame", true));
  CHECK(frame("nothing changed", false));
  light->SetPosition(1.2, 0.9, 3.0);
  CHECK(frame("light moved", true));
  CHECK(frame("nothing changed", false));
  occluder->SetPosition(0.3, 0.0, 0.0);
  CHECK(frame("occluder moved", true));
  renderer->GetActiveCamera()->Azimuth(1.0);
  renderer->ResetCameraClippingRange();
  CHECK(frame("camera turned a little", false));
  renderer->GetActiveCamera()->Zoom(3.0);
  renderer->ResetCameraClippingRange();
  CHECK(frame("camera zoomed in", true));
  CHECK(frame("nothing changed", false));
  renderer->GetActiveCamera()->Zoom(1.0 / 3.0);
  renderer->ResetCameraClippingRange();
  CHECK(frame("camera zoomed out", true));
  renderer->GetRenderWindow()->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

int CheckBadInput()
{
  vtkNew<vtkPenumbraConservativeShadows> technique;
  CHECK(RefusesNullInputs(technique));
  vtkNew<vtkPenumbraTechniques> techniques;
  vtkNew<vtkRenderer> renderer;
  CHECK(techniques->Apply(renderer, "conservative", "{\"resolution\": 32}") == 0);
  CHECK(techniques->Apply(renderer, "conservative", "{\"resolutoin\": 512}") == 0);
  CHECK(techniques->Apply(renderer, "conservative", "{\"resolution\": 512}") == 1);
  CHECK(techniques->Apply(renderer, "conservative", "{\"map\": \"fpga\"}") == 0);
  CHECK(techniques->Apply(renderer, "conservative", "{\"map\": \"gpu\"}") == 1);
  return EXIT_SUCCESS;
}
}

int TestConservativeShadows(int, char*[])
{
  RUN(CheckBadInput());
  // Both map builders, every scene: they must agree with the reference, not just each other.
  for (const char* map : { "cpu", "gpu" })
  {
    Map = map;
    RUN(CheckPlane());
    RUN(CheckMapReuse());
    RUN(CheckThinWire());
    RUN(CheckDefaultScene());
    RUN(CheckTortureScenes());
  }
  return EXIT_SUCCESS;
}
