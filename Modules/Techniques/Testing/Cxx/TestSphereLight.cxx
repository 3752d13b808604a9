// A sphere light: a point light with a radius (vtkPenumbraShadowKeys::LIGHT_RADIUS, the key
// ParaView's light Radius sets) is shadowed by the pass as the disc of that radius facing its
// focal point (vtkPenumbraAreaLight::SetFromLightRadius):
// - the exact soft techniques (raytraced, gears, auto) give the reference's visibility for
//   that disc bit for bit, the approximate ones (soft-shadowmap, pcss, single-sample-soft,
//   adaptive-soft) stay within their stated mean error of the converged disc, and every one
//   draws a penumbra (the converged reference has one, and a point light's shadow differs);
// - a hard technique hands the light to the pass's soft fallback and says so once;
// - the disc is kept while the light is unchanged and follows a new radius; radius 0 makes it
//   a point light again;
// - a negative radius and a directional light's radius are refused with a warning, once, and
//   the light casts hard shadows.
#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace penumbra_technique_tests;

namespace
{
constexpr int Width = 160, Height = 120;

// The scene's point light (radius 0.75 in sphere_light.json).
vtkLight* SceneLight(vtkRenderer* renderer)
{
  renderer->GetLights()->InitTraversal();
  return renderer->GetLights()->GetNextItem();
}

// Mean |a - b| over the samples valid in both, and how many differ at all.
double MeanError(vtkFloatArray* a, vtkFloatArray* b, vtkIdType& differ)
{
  double sum = 0.0;
  vtkIdType n = 0;
  differ = 0;
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
  {
    if (a->GetValue(i) < 0.0f || b->GetValue(i) < 0.0f)
    {
      continue;
    }
    sum += std::fabs(a->GetValue(i) - b->GetValue(i));
    differ += a->GetValue(i) != b->GetValue(i);
    ++n;
  }
  return n ? sum / n : 1.0;
}

int CheckTechniques()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> renderer = ReadScene("sphere_light.json", reader);
  CHECK(renderer != nullptr);
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(renderer, Width, Height);
  vtkNew<vtkPenumbraTechniques> registry;
  // A point light's hard shadow first: the penumbra must change it.
  vtkLight* light = SceneLight(renderer);
  CHECK(vtkPenumbraShadowKeys::GetLightRadius(light) == 0.75);
  vtkPenumbraShadowKeys::SetLightRadius(light, 0.0);
  CHECK(registry->Apply(renderer, "raytraced", "{}"));
  window->Render();
  vtkNew<vtkFloatArray> hard;
  hard->DeepCopy(ShadowPass(renderer)->GetVisibility(0));
  vtkPenumbraShadowKeys::SetLightRadius(light, 0.75);

  // Twice the mean error measured on Mesa llvmpipe (160 x 120), rounded up.
  const struct
  {
    const char* Name;
    double Bound; // < 0: exact, equal to the reference at the light's k
  } techniques[] = { { "raytraced", -1 }, { "gears", -1 }, { "auto", -1 },
    { "soft-shadowmap", 0.014 }, { "pcss", 0.018 }, { "single-sample-soft", 0.014 },
    { "adaptive-soft", 0.008 } };
  for (const auto& t : techniques)
  {
    CHECK(registry->Apply(renderer, t.Name, "{}"));
    window->Render();
    vtkPenumbraShadowPass* pass = ShadowPass(renderer);
    auto* disc = vtkPenumbraAreaLight::SafeDownCast(pass->GetLight(0));
    CHECK(disc && disc->GetShape() == vtkPenumbraAreaLight::Disc);
    CHECK(disc->GetWidth() == 1.5 && disc->GetNumberOfSamples() == 52);
    CHECK(
      pass->GetExplanation().find("disc light of diameter 1.5, 52 samples") != std::string::npos);
    vtkFloatArray* vis = pass->GetVisibility(0);
    CHECK(vis != nullptr);
    vtkNew<vtkPenumbraReference> reference;
    reference->SetGeometry(pass->GetGeometry());
    vtkNew<vtkFloatArray> atK, converged;
    vtkPenumbraViewSamples* samples = pass->GetViewSamples();
    CHECK(reference->ComputeVisibility(samples, disc, atK));
    CHECK(reference->ComputeConvergedVisibility(samples, disc, 64, converged));
    vtkIdType differ = 0, penumbra = 0, hardDiffer = 0;
    const double maeK = MeanError(vis, atK, differ);
    const vtkIdType exactDiffer = differ;
    const double mae = MeanError(vis, converged, differ);
    MeanError(vis, hard, hardDiffer);
    for (vtkIdType i = 0; i < vis->GetNumberOfTuples(); ++i)
    {
      penumbra += vis->GetValue(i) > 0.02f && vis->GetValue(i) < 0.98f;
    }
    std::printf("%-18s sphere light r = 0.75: MAE %.4f against the converged disc (bound %s), "
                "%lld samples differ from the reference at k = 8 (MAE %.4f), penumbra %lld "
                "samples, %lld differ from the point light's\n",
      t.Name, mae, t.Bound < 0 ? "exact" : std::to_string(t.Bound).c_str(),
      static_cast<long long>(exactDiffer), maeK, static_cast<long long>(penumbra),
      static_cast<long long>(hardDiffer));
    CHECK(t.Bound < 0 ? exactDiffer == 0 : mae <= t.Bound);
    CHECK(penumbra > 200 && hardDiffer > penumbra / 2);
  }
  return EXIT_SUCCESS;
}

int CheckLifecycle()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> renderer = ReadScene("sphere_light.json", reader);
  CHECK(renderer != nullptr);
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(renderer, 64, 48);
  vtkNew<vtkPenumbraTechniques> registry;
  CHECK(registry->Apply(renderer, "shadowmap", "{}"));
  vtkPenumbraShadowPass* pass = ShadowPass(renderer);
  WarningCounter warnings;
  vtkNew<vtkCallbackCommand> observer;
  observer->SetClientData(&warnings);
  observer->SetCallback(&WarningCounter::OnWarning);
  pass->AddObserver(vtkCommand::WarningEvent, observer);
  window->Render();
  window->Render();
  // A hard technique: the soft fallback shadows the disc, said once.
  CHECK(warnings.Warnings == 1 && warnings.Last.find("disc light") != std::string::npos);
  CHECK(pass->GetExplanation().find("shadowmap cannot shadow it; shadowed by gears") !=
    std::string::npos);
  vtkLight* light = SceneLight(renderer);
  vtkLight* disc = pass->GetLight(0);
  const vtkMTimeType built = disc->GetMTime();
  window->Render();
  CHECK(pass->GetLight(0) == disc && disc->GetMTime() == built); // kept, not rebuilt
  vtkPenumbraShadowKeys::SetLightRadius(light, 0.25);
  window->Render();
  CHECK(pass->GetLight(0) == disc);
  CHECK(vtkPenumbraAreaLight::SafeDownCast(disc)->GetWidth() == 0.5);
  // Radius 0: the point light itself, shadowed by the pass's own (hard) technique.
  vtkPenumbraShadowKeys::SetLightRadius(light, 0.0);
  window->Render();
  CHECK(pass->GetLight(0) == light);
  CHECK(std::string(pass->GetLightTechniqueName(0)) == "shadowmap");
  // A radius the pass cannot use: a warning, once, and hard shadows.
  warnings.Warnings = 0;
  vtkPenumbraShadowKeys::SetLightRadius(light, -1.0);
  window->Render();
  window->Render();
  CHECK(warnings.Warnings == 1 && warnings.Last.find("Light radius -1 not used") != std::string::npos);
  CHECK(pass->GetLight(0) == light);
  vtkNew<vtkLight> sun;
  sun->SetPositional(false);
  sun->SetPosition(1, 1, 3);
  sun->SetFocalPoint(0, 0, 0);
  vtkPenumbraShadowKeys::SetLightRadius(sun, 0.5);
  renderer->AddLight(sun);
  window->Render();
  CHECK(warnings.Warnings == 2 &&
    warnings.Last.find("directional light's angular size is not supported") != std::string::npos);
  CHECK(pass->GetLight(1) == sun.Get());
  return EXIT_SUCCESS;
}
}

int TestSphereLight(int, char*[])
{
  RUN(CheckTechniques());
  RUN(CheckLifecycle());
  return EXIT_SUCCESS;
}
