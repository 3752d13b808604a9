// Different techniques for different lights of one frame (vtkPenumbraShadowPass with
// vtkPenumbraFrame::SetActiveLights): a hard-shadow technique given an area light shadows it
// with the pass's soft fallback and says so once, instead of failing every frame.
#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include "vtkActor.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraStatistics.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

using namespace penumbra_technique_tests;

namespace
{
constexpr int Width = 128, Height = 96;

// Light numbers of mixed_lights.json: a sun, a point light, an area light.
constexpr int Sun = 0, Point = 1, Area = 2;

using Counter = WarningCounter;

// Every light's visibility of the last frame, copied.
std::vector<vtkSmartPointer<vtkFloatArray>> Visibilities(vtkPenumbraShadowPass* pass)
{
  std::vector<vtkSmartPointer<vtkFloatArray>> out;
  for (int i = 0; i < pass->GetNumberOfLights(); ++i)
  {
    auto copy = vtkSmartPointer<vtkFloatArray>::New();
    if (vtkFloatArray* v = pass->GetVisibility(i))
    {
      copy->DeepCopy(v);
    }
    out.push_back(copy);
  }
  return out;
}

vtkIdType Differences(vtkFloatArray* a, vtkFloatArray* b)
{
  if (a->GetNumberOfTuples() != b->GetNumberOfTuples())
  {
    return -1;
  }
  vtkIdType n = 0;
  for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
  {
    n += a->GetValue(i) != b->GetValue(i);
  }
  return n;
}

bool HasSoftValues(vtkFloatArray* v)
{
  for (vtkIdType i = 0; i < v->GetNumberOfTuples(); ++i)
  {
    if (v->GetValue(i) > 0.0f && v->GetValue(i) < 1.0f)
    {
      return true;
    }
  }
  return false;
}

// What `technique` gives each light of the mixed scene, rendered twice; `warnings` counts the
// pass's warnings over both frames.
int RenderWith(const char* technique, const char* options,
  std::vector<vtkSmartPointer<vtkFloatArray>>& vis, std::vector<std::string>& names,
  Counter& warnings)
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> ren = ReadScene("mixed_lights.json", reader);
  CHECK(ren);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(ren, technique, options));
  vtkPenumbraShadowPass* pass = ShadowPass(ren);
  CHECK(pass);
  vtkNew<vtkCallbackCommand> observer;
  observer->SetCallback(&Counter::OnWarning);
  observer->SetClientData(&warnings);
  pass->AddObserver(vtkCommand::WarningEvent, observer);
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(ren, Width, Height);
  window->Render();
  window->Render();
  CHECK(pass->GetNumberOfLights() == 3);
  vis = Visibilities(pass);
  names.clear();
  for (int i = 0; i < 3; ++i)
  {
    names.emplace_back(pass->GetLightTechniqueName(i));
  }
  return EXIT_SUCCESS;
}

// A hard-shadow technique with an area light: the area light gets GEARS, exact at the
// light's k, so its visibility equals the ray tracer's; one warning names the light and the
// technique, once, not every frame.
int TestFallbackForAreaLights()
{
  std::vector<vtkSmartPointer<vtkFloatArray>> hard, traced;
  std::vector<std::string> hardNames, tracedNames;
  Counter hardWarnings, tracedWarnings;
  RUN(RenderWith("conservative", "", hard, hardNames, hardWarnings));
  RUN(RenderWith("raytraced", "", traced, tracedNames, tracedWarnings));
  CHECK(hardNames[Sun] == "conservative" && hardNames[Point] == "conservative");
  CHECK(hardNames[Area] == "gears");
  CHECK(tracedNames[Sun] == "raytraced" && tracedNames[Area] == "raytraced");
  CHECK(hardWarnings.Warnings == 1);
  CHECK(hardWarnings.Last.find("Light 2 (area light") != std::string::npos);
  CHECK(hardWarnings.Last.find("shadowed by gears") != std::string::npos);
  CHECK(tracedWarnings.Warnings == 0);
  CHECK(HasSoftValues(hard[Area]));
  CHECK(Differences(hard[Area], traced[Area]) == 0);
  // The conservative technique is exact for the hard lights up to near-ties.
  for (int light : { Sun, Point })
  {
    const vtkIdType differ = Differences(hard[light], traced[light]);
    CHECK(differ >= 0 && differ <= Width * Height / 1000);
  }
  return EXIT_SUCCESS;
}

// `auto` on a sun, a point light and an area light: every light is shadowed, the area light
// softly, each by the technique auto chose for it, and each light's visibility is that
// technique's (the same frame rendered with the chosen technique alone).
int TestAuto()
{
  std::vector<vtkSmartPointer<vtkFloatArray>> automatic, traced, gears;
  std::vector<std::string> names, tracedNames, gearsNames;
  Counter warnings, none;
  RUN(RenderWith("auto", "", automatic, names, warnings));
  RUN(RenderWith("raytraced", "", traced, tracedNames, none));
  RUN(RenderWith("gears", "", gears, gearsNames, none));
  CHECK(warnings.Warnings == 0);
  CHECK(names[Sun] == "raytraced" && names[Point] == "raytraced" && names[Area] == "gears");
  for (int light : { Sun, Point, Area })
  {
    CHECK(automatic[light]->GetNumberOfTuples() == Width * Height);
    CHECK(Differences(automatic[light], traced[light]) == 0);
  }
  CHECK(Differences(automatic[Area], gears[Area]) == 0);
  CHECK(HasSoftValues(automatic[Area]));
  CHECK(!HasSoftValues(automatic[Sun]) && !HasSoftValues(automatic[Point]));
  // Every light casts a shadow somewhere in the view.
  for (int light : { Sun, Point, Area })
  {
    bool shadowed = false;
    for (vtkIdType i = 0; i < automatic[light]->GetNumberOfTuples() && !shadowed; ++i)
    {
      shadowed = automatic[light]->GetValue(i) == 0.0f;
    }
    CHECK(shadowed);
  }

  // quality=exact and quality=fast choose the same techniques (hard lights get raytraced at
  // every quality, see vtkPenumbraAutoShadows); fast gives soft lights k = 4, `samples` any k.
  std::vector<vtkSmartPointer<vtkFloatArray>> exact, fast, fine, gears8;
  std::vector<std::string> exactNames, fastNames, fineNames, gears8Names;
  RUN(RenderWith("auto", R"({"quality": "exact"})", exact, exactNames, none));
  CHECK(exactNames == names);
  RUN(RenderWith("auto", R"({"quality": "fast", "samples": 16})", fine, fineNames, none));
  RUN(RenderWith("gears", R"({"samples": 16})", gears8, gears8Names, none));
  CHECK(fineNames == names);
  CHECK(Differences(fine[Area], gears8[Area]) == 0);
  CHECK(Differences(fine[Area], gears[Area]) > 0); // k = 16, not the light's 8
  // quality=fast: k = 4, where the ray tracer is as fast as GEARS (docs/gears.md).
  std::vector<vtkSmartPointer<vtkFloatArray>> traced4;
  std::vector<std::string> traced4Names;
  RUN(RenderWith("auto", R"({"quality": "fast"})", fast, fastNames, none));
  RUN(RenderWith("raytraced", R"({"samples": 4})", traced4, traced4Names, none));
  CHECK(fastNames[Sun] == "raytraced" && fastNames[Area] == "raytraced");
  CHECK(Differences(fast[Area], traced4[Area]) == 0);
  CHECK(Differences(fast[Area], gears[Area]) > 0);
  CHECK(HasSoftValues(fast[Area]));
  CHECK(Differences(fast[Sun], traced[Sun]) == 0);

  vtkNew<vtkPenumbraTechniques> techniques;
  vtkNew<vtkRenderer> ren;
  CHECK(!techniques->Apply(ren, "auto", R"({"quality": "best"})"));
  CHECK(std::string(techniques->GetErrorMessage()).find("quality: expected one of") == 0);
  return EXIT_SUCCESS;
}

vtkSmartPointer<vtkLight> AddLight(vtkRenderer* ren, const double from[3], const double to[3],
  bool positional, double cone, double intensity, bool on)
{
  auto light = vtkSmartPointer<vtkLight>::New();
  light->SetLightTypeToSceneLight();
  light->SetPosition(from[0], from[1], from[2]);
  light->SetFocalPoint(to[0], to[1], to[2]);
  light->SetPositional(positional);
  light->SetConeAngle(cone);
  light->SetIntensity(intensity);
  light->SetSwitch(on);
  ren->AddLight(light);
  return light;
}

// Lights no visible sample can receive get no shadow work, and the explanation counts them:
// a spot light aimed at the sky (every sample outside its cone), a black light; a
// switched-off light is counted apart. (Facing away: TestLightBelowPlane.)
int TestSkippedLights()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> ren = ReadScene("mixed_lights.json", reader);
  CHECK(ren);
  const double high[3] = { 0, 0, 200 }, sky[3] = { 0, 0, 400 }, origin[3] = { 0, 0, 0 };
  AddLight(ren, high, sky, true, 20.0, 1.0, true);      // 3: spot at the sky
  AddLight(ren, high, origin, true, 180.0, 0.0, true);  // 4: black
  AddLight(ren, high, origin, true, 180.0, 1.0, false); // off
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(ren, "auto", ""));
  vtkPenumbraShadowPass* pass = ShadowPass(ren);
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(ren, Width, Height);
  window->Render();
  const std::string text = pass->GetExplanation();
  std::cout << text;
  CHECK(pass->GetNumberOfLights() == 5);
  CHECK(pass->GetNumberOfSkippedLights() == 2);
  CHECK(pass->GetNumberOfLightsOff() == 1);
  for (int light : { 3, 4 })
  {
    CHECK(!pass->GetLightTechnique(light) && !pass->GetVisibility(light));
  }
  for (int light : { Sun, Point, Area })
  {
    CHECK(pass->GetLightTechnique(light) && pass->GetVisibility(light));
  }
  for (const char* line :
    { "light 0 (directional light): raytraced - hard light, quality=balanced",
      "light 2 (area light, 8x8 samples): gears - soft light at k = 8",
      "light 3 (spot light): skipped, no shadow work - every visible sample lies outside its cone",
      "light 4 (point light): skipped, no shadow work - it casts no light",
      "skipped lights: 2; lights off: 1" })
  {
    CHECK(text.find(line) != std::string::npos);
  }

  // Statistics as data: each light's technique reports its figures by name, whatever its
  // class, under the pass's phase times; the explanation prints them.
  vtkNew<vtkPenumbraStatistics> stats;
  CHECK(pass->GetLightStatistics(Sun, stats));
  CHECK(stats->Has("technique_ms") && stats->Get("time_ms") >= 0.0);
  CHECK(stats->Get("rays") > 0.0); // raytraced: one shadow ray per lit-facing sample
  CHECK(pass->GetLightStatistics(Area, stats));
  CHECK(stats->Get("cells") > 0.0 && stats->Get("grid_ms") >= 0.0); // GEARS' grid
  CHECK(!stats->Has("rays") && std::isnan(stats->Get("rays")));
  CHECK(!pass->GetLightStatistics(3, stats) || !stats->Has("time_ms")); // skipped: no figures
  CHECK(!pass->GetLightStatistics(99, stats) && stats->GetNumberOfEntries() == 0);
  CHECK(text.find("  figures: time_ms ") != std::string::npos);

  // A technique that works on the GPU reads no samples back, so with the area light off (its
  // fallback, GEARS, would read them) only the black light is skipped; the spot light is
  // shadowed (and comes out unlit, as the rules say).
  vtkLight* area = vtkLight::SafeDownCast(ren->GetLights()->GetItemAsObject(Area));
  area->SetSwitch(0);
  CHECK(techniques->Apply(ren, "shadowmap", ""));
  pass = ShadowPass(ren);
  window->Render();
  CHECK(pass->GetNumberOfLightsOff() == 2);
  CHECK(pass->GetNumberOfSkippedLights() == 1);
  CHECK(pass->GetLightTechnique(2) && !pass->GetLightTechnique(3)); // spot, black
  return EXIT_SUCCESS;
}

// A plane seen from above and a sun below it: every sample faces away (N.L = -1), so the
// light is skipped and the frame is the unshadowed one. The sun starts above the plane: the
// sample that showed it needed shadow work then (the pass tests it first) does not keep it
// from being skipped once it moves below.
int TestLightBelowPlane()
{
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-1, -1, 0);
  plane->SetPoint1(1, -1, 0);
  plane->SetPoint2(-1, 1, 0);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(plane->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  vtkNew<vtkRenderer> ren;
  ren->AddActor(actor);
  const double above[3] = { 0.3, 0.2, 1 }, below[3] = { 0.3, 0.2, -1 }, origin[3] = { 0, 0, 0 };
  vtkSmartPointer<vtkLight> sun = AddLight(ren, above, origin, false, 30.0, 1.0, true);
  ren->GetActiveCamera()->SetPosition(0, 0, 5);
  ren->GetActiveCamera()->SetFocalPoint(0, 0, 0);
  ren->ResetCamera();
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(ren, "auto", ""));
  vtkPenumbraShadowPass* pass = ShadowPass(ren);
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(ren, 64, 64);
  window->Render();
  CHECK(pass->GetNumberOfSkippedLights() == 0 && pass->GetLightTechnique(0));
  sun->SetPosition(below[0], below[1], below[2]);
  window->Render();
  CHECK(pass->GetNumberOfSkippedLights() == 1);
  CHECK(!pass->GetLightTechnique(0) && !pass->GetVisibility(0));
  CHECK(pass->GetExplanation().find(
          "light 0 (directional light): skipped, no shadow work - every visible sample faces "
          "away from it") != std::string::npos);
  return EXIT_SUCCESS;
}

// A sun whose only caster stands outside the view on the side away from it
// (unreachable_light.json): no visible sample's ray can meet the caster's box, so the light
// gets no shadow work. Turned to come from behind the tower, low, its shadow reaches the view:
// the light is shadowed again and some samples are in shadow.
int TestUnreachableCaster()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> ren = ReadScene("unreachable_light.json", reader);
  CHECK(ren);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(ren, "auto", ""));
  vtkPenumbraShadowPass* pass = ShadowPass(ren);
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(ren, 128, 96);
  window->Render();
  CHECK(pass->GetNumberOfSkippedLights() == 1);
  CHECK(!pass->GetLightTechnique(0) && !pass->GetVisibility(0));
  CHECK(pass->GetExplanation().find(
          "light 0 (directional light): skipped, no shadow work - no "
          "caster lies between it and any visible surface") != std::string::npos);
  vtkLight* sun = vtkLight::SafeDownCast(ren->GetLights()->GetItemAsObject(0));
  sun->SetPosition(1.0, 0.0, 0.2); // towards the light, seen from the focal point
  sun->SetFocalPoint(0.0, 0.0, 0.0);
  window->Render();
  CHECK(pass->GetNumberOfSkippedLights() == 0);
  vtkFloatArray* visibility = pass->GetVisibility(0);
  CHECK(visibility);
  vtkIdType shadowed = 0;
  for (vtkIdType i = 0; i < visibility->GetNumberOfTuples(); ++i)
  {
    shadowed += visibility->GetValue(i) == 0.0f;
  }
  CHECK(shadowed > 100);
  return EXIT_SUCCESS;
}
}

int TestPerLightTechniques(int, char*[])
{
  RUN(TestUnreachableCaster());
  RUN(TestSkippedLights());
  RUN(TestLightBelowPlane());
  RUN(TestFallbackForAreaLights());
  RUN(TestAuto());
  return EXIT_SUCCESS;
}
