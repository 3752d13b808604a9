// Different techniques for different lights of one frame (vtkPenumbraShadowPass with
// vtkPenumbraFrame::SetActiveLights): a hard-shadow technique given an area light shadows it
// with the pass's soft fallback and says so once, instead of failing every frame.
#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"

#include <cstdlib>
#include <string>
#include <vector>

using namespace penumbra_technique_tests;

namespace
{
constexpr int Width = 128, Height = 96;

// Light numbers of mixed_lights.json: a sun, a point light, an area light.
constexpr int Sun = 0, Point = 1, Area = 2;

struct Counter
{
  int Warnings = 0;
  std::string Last;
  static void OnWarning(vtkObject*, unsigned long, void* client, void* data)
  {
    auto* self = static_cast<Counter*>(client);
    ++self->Warnings;
    self->Last = data ? static_cast<const char*>(data) : "";
  }
};

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
  std::vector<vtkSmartPointer<vtkFloatArray>>& vis, std::vector<std::string>& names, Counter& warnings)
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

  // quality=exact chooses the same; quality=fast gives hard lights shadow maps (the same
  // visibility as `shadowmap` alone) and soft lights k = 4.
  std::vector<vtkSmartPointer<vtkFloatArray>> exact, fast, maps;
  std::vector<std::string> exactNames, fastNames, mapNames;
  RUN(RenderWith("auto", R"({"quality": "exact"})", exact, exactNames, none));
  CHECK(exactNames == names);
  RUN(RenderWith("auto", R"({"quality": "fast"})", fast, fastNames, none));
  RUN(RenderWith("shadowmap", "", maps, mapNames, none));
  CHECK(fastNames[Sun] == "shadowmap" && fastNames[Point] == "shadowmap");
  CHECK(fastNames[Area] == "gears");
  CHECK(Differences(fast[Sun], maps[Sun]) == 0 && Differences(fast[Point], maps[Point]) == 0);
  CHECK(Differences(fast[Area], gears[Area]) == 0); // the scene's area light has k = 4

  vtkNew<vtkPenumbraTechniques> techniques;
  vtkNew<vtkRenderer> ren;
  CHECK(!techniques->Apply(ren, "auto", R"({"quality": "best"})"));
  CHECK(std::string(techniques->GetErrorMessage()).find("quality: expected one of") == 0);
  return EXIT_SUCCESS;
}
}

int TestPerLightTechniques(int, char*[])
{
  RUN(TestFallbackForAreaLights());
  RUN(TestAuto());
  return EXIT_SUCCESS;
}
