// vtkPenumbraLinkedListShadows (linked-list shadow maps, Ferko 2014: the irregular z-buffer of
// Johnson et al. 2005 with per-texel lists of view samples, alone and as the hybrid LLSM behind
// a conservative shadow map) against the exact reference on the same view samples: zero
// mismatches outside reference ties for directional, spot and point lights on a plane with a
// thin occluder, a wire thinner than a list texel, the default city scene and the hard-light
// torture scenes; still exact with a one-texel grid and with a node pool far smaller than the
// samples; the degenerate frames (no geometry, no casters, every sample facing away) give the
// reference's answer; the statistics add up; caster culling changes no answer (recomputed
// with it off) and culls casters on the default scene for every light type; the GPU list path
// (compute shader, atomic counter and head exchange) lists the same samples per texel as the
// CPU path and gives the same visibility, also when a small node pool overflows.
#include "vtkActor.h"
#include "vtkActorCollection.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraLinkedListShadows.h"
#include "vtkPenumbraMetrics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include <algorithm>
#include <cstdio>
#include <string>

namespace
{
using namespace penumbra_technique_tests;

// Passes tested in the sparse form (few listed samples per caster), over every comparison:
// the hybrid's plane scenes must use it, so its exactness is checked above too.
int SparsePasses = 0;

// The shadowed samples outside ties, summed over a comparison's lights.
struct Shadows
{
  vtkIdType Technique = 0;
  vtkIdType Reference = 0;
};

// Renders `renderer` (128 x 96, in a new `window`) with `name` ("llsm" or "llsm-hybrid") and
// `options`; the pass's technique, or null when any of it failed.
vtkPenumbraLinkedListShadows* RenderWith(vtkRenderer* renderer, const std::string& name,
  const std::string& options, vtkSmartPointer<vtkRenderWindow>& window)
{
  window = TestWindow(renderer, 128, 96);
  vtkNew<vtkPenumbraTechniques> techniques;
  if (!techniques->Apply(renderer, name.c_str(), options.c_str()))
  {
    return nullptr;
  }
  window->Render();
  vtkPenumbraShadowPass* pass = ShadowPass(renderer);
  if (!pass || pass->GetNumberOfLights() < 1)
  {
    return nullptr;
  }
  auto* llsm = vtkPenumbraLinkedListShadows::SafeDownCast(pass->GetTechnique());
  return llsm && llsm->GetHybrid() == (name == "llsm-hybrid") ? llsm : nullptr;
}

// Renders `renderer` (128 x 96) with `name` ("llsm" or "llsm-hybrid") and `options`, then
// compares each light's visibility, from the pass and recomputed directly (the statistics
// belong to that call), with the reference's. Fails on any mismatch outside ties.
int Compare(const std::string& label, vtkRenderer* renderer, const std::string& name,
  const std::string& options, Shadows* shadows = nullptr, int minPasses = 1,
  vtkIdType* culls = nullptr)
{
  vtkSmartPointer<vtkRenderWindow> window;
  vtkPenumbraLinkedListShadows* llsm = RenderWith(renderer, name, options, window);
  CHECK(llsm != nullptr);
  vtkPenumbraShadowPass* pass = ShadowPass(renderer);
  vtkPenumbraViewSamples* samples = pass->GetViewSamples();
  CHECK(samples->GetNumberOfValidSamples() > 0);

  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(pass->GetGeometry());
  vtkNew<vtkPenumbraMetrics> metrics;
  for (int i = 0; i < pass->GetNumberOfLights(); ++i)
  {
    vtkNew<vtkFloatArray> direct, ref;
    CHECK(
      llsm->ComputeVisibility(renderer, pass->GetGeometry(), samples, pass->GetLight(i), direct));
    CHECK(reference->ComputeVisibility(samples, pass->GetLight(i), ref));
    vtkUnsignedCharArray* ties = reference->GetTies();
    vtkIdType mismatches[2] = { 0, 0 };
    vtkFloatArray* answers[2] = { pass->GetVisibility(i), direct };
    // A light no caster can reach gets no shadow work from the pass (nothing to compare).
    const bool skipped = !pass->GetLightTechnique(i);
    for (int k = skipped ? 1 : 0; k < 2; ++k)
    {
      CHECK(answers[k] != nullptr && metrics->CompareHard(answers[k], ref, ties));
      mismatches[k] = metrics->GetFalseLit() + metrics->GetFalseShadow();
    }
    for (vtkIdType s = 0; shadows && s < ref->GetNumberOfTuples(); ++s)
    {
      shadows->Reference += ref->GetValue(s) == 0.0f && !ties->GetValue(s);
      shadows->Technique += direct->GetValue(s) == 0.0f && !ties->GetValue(s);
    }
    const vtkIdType valid = llsm->GetNumberOfValidSamples();
    const vtkIdType culled = llsm->GetNumberOfCulledCasters();
    const vtkIdType rasterized = llsm->GetNumberOfRasterizedCasters();
    if (culls)
    {
      *culls += culled;
    }
    // Caster culling only skips work: without it the answer is the same, every caster of
    // every view and pass is rasterized, and the culled ones were among them.
    CHECK(llsm->GetCullCasters());
    llsm->CullCastersOff();
    vtkNew<vtkFloatArray> unculled;
    CHECK(
      llsm->ComputeVisibility(renderer, pass->GetGeometry(), samples, pass->GetLight(i), unculled));
    llsm->CullCastersOn();
    CHECK(llsm->GetNumberOfCulledCasters() == 0);
    CHECK(llsm->GetNumberOfRasterizedCasters() == culled + rasterized);
    CHECK(unculled->GetNumberOfTuples() == direct->GetNumberOfTuples());
    for (vtkIdType s = 0; s < direct->GetNumberOfTuples(); ++s)
    {
      CHECK(unculled->GetValue(s) == direct->GetValue(s));
    }
    CHECK(
      llsm->ComputeVisibility(renderer, pass->GetGeometry(), samples, pass->GetLight(i), direct));
    SparsePasses += llsm->GetNumberOfSparsePasses();
    CHECK(llsm->GetNumberOfSparsePasses() <= llsm->GetNumberOfPasses());
    std::printf("%-40s light %d: valid %lld, listed %lld (%.1f%%, sent %.1f%%), lists max %lld "
                "mean %.2f, tests %lld, traced %lld, passes %d (sparse %d), views %d, ties %lld, "
                "mismatches %lld (direct %lld), casters culled %lld rasterized %lld; classify "
                "%.1f, lists %.1f, raster %.1f, "
                "trace %.1f ms\n",
      (name + " " + label).c_str(), i, static_cast<long long>(valid),
      static_cast<long long>(llsm->GetNumberOfListedSamples()), 100.0 * llsm->GetListedFraction(),
      100.0 * llsm->GetUncertainFraction(), static_cast<long long>(llsm->GetMaxListLength()),
      llsm->GetMeanListLength(), static_cast<long long>(llsm->GetNumberOfTests()),
      static_cast<long long>(llsm->GetNumberOfTracedSamples()), llsm->GetNumberOfPasses(),
      llsm->GetNumberOfSparsePasses(), llsm->GetNumberOfViews(),
      static_cast<long long>(reference->GetNumberOfTies()), static_cast<long long>(mismatches[0]),
      static_cast<long long>(mismatches[1]), static_cast<long long>(culled),
      static_cast<long long>(rasterized), llsm->GetClassifyTimeMs(), llsm->GetListTimeMs(),
      llsm->GetRasterTimeMs(), llsm->GetTraceTimeMs());
    CHECK(mismatches[0] == 0 && mismatches[1] == 0);
    CHECK(valid == samples->GetNumberOfValidSamples());
    CHECK(llsm->GetNumberOfListedSamples() <= valid);
    CHECK(llsm->GetNumberOfTracedSamples() <= valid);
    CHECK(llsm->GetReference()->GetNumberOfRays() <= llsm->GetNumberOfTracedSamples());
    CHECK(llsm->GetMaxListLength() >= (llsm->GetNumberOfListedSamples() > 0 ? 1 : 0));
    CHECK(llsm->GetNumberOfPasses() >= (llsm->GetNumberOfListedSamples() > 0 ? minPasses : 0));
    if (llsm->GetHybrid())
    {
      // The hybrid lists exactly the classifier's uncertain samples.
      CHECK(
        llsm->GetNumberOfListedSamples() <= llsm->GetClassifier()->GetNumberOfUncertainSamples());
      CHECK(llsm->GetUncertainFraction() == llsm->GetListedFraction());
      // The list it takes them from: the uncertain samples, ascending.
      vtkPenumbraConservativeShadows* classifier = llsm->GetClassifier();
      const std::vector<vtkIdType>& uncertain = classifier->GetUncertainSamples();
      CHECK(static_cast<vtkIdType>(uncertain.size()) == classifier->GetNumberOfUncertainSamples());
      CHECK(std::is_sorted(uncertain.begin(), uncertain.end()));
      // Classified with two map layers instead of three: the same answer, and the third
      // layer only ever decides samples two leave uncertain.
      const vtkIdType uncertainWithThree = classifier->GetNumberOfUncertainSamples();
      CHECK(classifier->GetLayers() == 3);
      classifier->SetLayers(2);
      vtkNew<vtkFloatArray> twoLayers;
      CHECK(llsm->ComputeVisibility(
        renderer, pass->GetGeometry(), samples, pass->GetLight(i), twoLayers));
      classifier->SetLayers(3);
      CHECK(classifier->GetNumberOfUncertainSamples() >= uncertainWithThree);
      CHECK(twoLayers->GetNumberOfTuples() == direct->GetNumberOfTuples());
      for (vtkIdType s = 0; s < direct->GetNumberOfTuples(); ++s)
      {
        CHECK(twoLayers->GetValue(s) == direct->GetValue(s));
      }
    }
  }
  renderer->GetRenderWindow()->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// Both techniques with the same options.
int CompareBoth(const std::string& label, vtkRenderer* renderer, const std::string& options,
  Shadows* shadows = nullptr, int minPasses = 1, vtkIdType* culls = nullptr)
{
  for (const char* name : { "llsm", "llsm-hybrid" })
  {
    RUN(Compare(label, renderer, name, options, shadows, minPasses, culls));
  }
  return EXIT_SUCCESS;
}

const LightType HardLights[] = { LightType::Directional, LightType::Spot, LightType::Point };

int CheckPlane()
{
  SparsePasses = 0;
  for (LightType type : HardLights)
  {
    RUN(CompareBoth(std::string("plane+box ") + Name(type), PlaneScene(type, 0.02, 0.5),
      "{\"resolution\": 256}"));
  }
  CHECK(SparsePasses > 0);
  return EXIT_SUCCESS;
}

// A 1 mm wire seen through an 8 cm window, under a 256^2 grid spanning metres: far thinner
// than a texel, it must still reach every sample its shadow falls on.
int CheckThinWire()
{
  for (LightType type : HardLights)
  {
    Shadows shadows;
    RUN(CompareBoth(std::string("sub-texel wire ") + Name(type),
      PlaneScene(type, 0.001, 0.0005, 0.08), "{\"resolution\": 256}", &shadows));
    std::printf("  wire shadow: technique %lld, reference %lld samples\n",
      static_cast<long long>(shadows.Technique), static_cast<long long>(shadows.Reference));
    CHECK(shadows.Reference > 0 && shadows.Technique == shadows.Reference);
  }
  return EXIT_SUCCESS;
}

// A one-texel grid (every caster meets every sample) and a node pool of 97 samples (many
// passes) give the same exact answer.
int CheckDegenerateLists()
{
  for (LightType type : HardLights)
  {
    const std::string light = Name(type);
    RUN(CompareBoth(
      "plane+box one texel " + light, PlaneScene(type, 0.02, 0.5), "{\"resolution\": 1}"));
    RUN(Compare("plane+box capacity 97 " + light, PlaneScene(type, 0.02, 0.5), "llsm",
      "{\"resolution\": 64, \"capacity\": 97}", nullptr, 10));
  }
  return EXIT_SUCCESS;
}

// The GPU and CPU list paths on the same frame: the same (view, texel, sample) sets, the same
// visibility bit for bit. With a pool of `capacity` nodes the GPU path must overflow (and
// still list every sample once, in further passes).
int CompareListPaths(const std::string& label, vtkRenderer* renderer, const std::string& name,
  const std::string& options, vtkIdType capacity)
{
  vtkSmartPointer<vtkRenderWindow> window;
  vtkPenumbraLinkedListShadows* llsm = RenderWith(renderer, name, options, window);
  CHECK(llsm != nullptr);
  vtkPenumbraShadowPass* pass = ShadowPass(renderer);
  llsm->RecordListsOn();
  for (int i = 0; i < pass->GetNumberOfLights(); ++i)
  {
    vtkNew<vtkFloatArray> answer[2];
    vtkNew<vtkIdTypeArray> lists[2];
    for (int path :
      { vtkPenumbraLinkedListShadows::LISTS_CPU, vtkPenumbraLinkedListShadows::LISTS_GPU })
    {
      llsm->SetListBuilder(path);
      llsm->SetListCapacity(path == vtkPenumbraLinkedListShadows::LISTS_GPU ? capacity : 0);
      CHECK(llsm->ComputeVisibility(
        renderer, pass->GetGeometry(), pass->GetViewSamples(), pass->GetLight(i), answer[path]));
      CHECK(llsm->GetLastListBuilder() == path);
      lists[path]->DeepCopy(llsm->GetRecordedLists());
    }
    const vtkIdType listed = llsm->GetNumberOfListedSamples();
    std::printf("%-40s light %d: %lld listed, GPU passes %d, overflows %d\n",
      (name + " " + label).c_str(), i, static_cast<long long>(listed), llsm->GetNumberOfPasses(),
      llsm->GetNumberOfOverflows());
    CHECK(lists[0]->GetNumberOfTuples() == listed && lists[1]->GetNumberOfTuples() == listed);
    for (vtkIdType k = 0; k < 3 * listed; ++k)
    {
      CHECK(lists[0]->GetValue(k) == lists[1]->GetValue(k));
    }
    // Some view holds more samples than the pool: its pool must have overflowed.
    if (capacity > 0 && listed > capacity * llsm->GetNumberOfViews())
    {
      CHECK(llsm->GetNumberOfOverflows() > 0 && llsm->GetNumberOfPasses() > 1);
    }
    CHECK(capacity > 0 || llsm->GetNumberOfOverflows() == 0);
    CHECK(llsm->GetNumberOfOverflows() < std::max(llsm->GetNumberOfPasses(), 1));
    CHECK(answer[0]->GetNumberOfTuples() == answer[1]->GetNumberOfTuples());
    for (vtkIdType s = 0; s < answer[0]->GetNumberOfTuples(); ++s)
    {
      CHECK(answer[0]->GetValue(s) == answer[1]->GetValue(s));
    }
  }
  renderer->GetRenderWindow()->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// GPU lists against CPU lists (identical sets and visibility), and against the reference
// through the registry option (0 mismatches), with and without a forced small pool.
int CheckListPaths()
{
  for (LightType type : HardLights)
  {
    const std::string light = Name(type);
    for (const char* name : { "llsm", "llsm-hybrid" })
    {
      RUN(CompareListPaths(
        "plane+box lists " + light, PlaneScene(type, 0.02, 0.5), name, "{\"resolution\": 256}", 0));
      RUN(CompareListPaths("plane+box pool 97 " + light, PlaneScene(type, 0.02, 0.5), name,
        "{\"resolution\": 256}", 97));
      RUN(CompareListPaths("sub-texel wire pool 50 " + light, PlaneScene(type, 0.001, 0.0005, 0.08),
        name, "{\"resolution\": 256}", 50));
    }
    RUN(CompareBoth("plane+box gpu lists " + light, PlaneScene(type, 0.02, 0.5),
      "{\"resolution\": 256, \"lists\": \"gpu\"}"));
    RUN(Compare("plane+box gpu pool 97 " + light, PlaneScene(type, 0.02, 0.5), "llsm",
      "{\"resolution\": 64, \"capacity\": 97, \"lists\": \"gpu\"}", nullptr, 10));
  }
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> city = DefaultSceneWith(LightType::AsInScene, reader, 35.0);
  CHECK(city != nullptr);
  RUN(CompareListPaths("default.json pool 1000", city, "llsm", "{}", 1000));
  return EXIT_SUCCESS;
}

int CheckDefaultScene()
{
  for (LightType type : { LightType::AsInScene, LightType::Spot, LightType::Point })
  {
    vtkNew<vtkPenumbraSceneReader> reader;
    vtkSmartPointer<vtkRenderer> renderer = DefaultSceneWith(type, reader, 35.0);
    CHECK(renderer != nullptr);
    // The city's casters mostly cover no listed sample or lie behind them: culling must skip
    // some for every light type (and the answers above stay exact).
    vtkIdType culls = 0;
    RUN(CompareBoth(std::string("default.json ") + Name(type), renderer, "{}", nullptr, 1, &culls));
    CHECK(culls > 0);
  }
  return EXIT_SUCCESS;
}

int CheckTortureScenes()
{
  const char* scenes[] = { "thin_occluders.json", "grazing_light.json", "zenith_light.json",
    "coplanar_contact.json", "bad_triangles.json", "georef_1e7.json", "depth_range.json",
    "point_light_in_room.json", "point_light_on_surface.json", "wall_gaps.json" };
  for (const char* scene : scenes)
  {
    vtkNew<vtkPenumbraSceneReader> reader;
    vtkSmartPointer<vtkRenderer> renderer = ReadScene(std::string("torture/") + scene, reader);
    CHECK(renderer != nullptr);
    RUN(CompareBoth(std::string("torture/") + scene, renderer, "{\"resolution\": 512}"));
  }
  return EXIT_SUCCESS;
}

// Frames without work: no geometry in the light's way (no casters), every sample facing
// away from the light, and a scene without any prop. The answers are the reference's, and
// nothing is listed.
int CheckEmptyFrames()
{
  for (const char* name : { "llsm", "llsm-hybrid" })
  {
    auto noCasters = PlaneScene(LightType::Point, 0.02, 0.5);
    vtkActorCollection* actors = noCasters->GetActors();
    actors->InitTraversal();
    while (vtkActor* actor = actors->GetNextActor())
    {
      vtkPenumbraShadowKeys::SetCastsShadows(actor, false);
    }
    // Nothing casts: the pass gives the frame no shadow work at all.
    vtkSmartPointer<vtkRenderWindow> noCastersWindow;
    auto* llsm = RenderWith(noCasters, name, "{}", noCastersWindow);
    CHECK(llsm != nullptr && ShadowPass(noCasters)->GetVisibility(0) == nullptr);
    CHECK(ShadowPass(noCasters)->GetExplanation().find("nothing casts shadows") !=
      std::string::npos);
    CHECK(llsm->GetNumberOfListedSamples() == 0 && llsm->GetNumberOfTracedSamples() == 0);

    auto backFacing = PlaneScene(LightType::Directional, 0.02, 0.5);
    const double below[3] = { 0.3, 0.2, -3.0 };
    const double target[3] = { 0, 0, 0 };
    SetLight(backFacing, LightType::Directional, below, target, 35.0);
    RUN(Compare("every sample facing away", backFacing, name, "{}"));
    llsm = vtkPenumbraLinkedListShadows::SafeDownCast(ShadowPass(backFacing)->GetTechnique());
    CHECK(llsm->GetNumberOfListedSamples() == 0 && llsm->GetNumberOfTracedSamples() == 0);
    CHECK(llsm->GetNumberOfViews() == 0);

    // No props at all: every sample is background and keeps -1.
    vtkNew<vtkRenderer> empty;
    SetLight(empty, LightType::Spot, below, target, 35.0);
    vtkSmartPointer<vtkRenderWindow> window = TestWindow(empty, 64, 48);
    vtkNew<vtkPenumbraTechniques> techniques;
    CHECK(techniques->Apply(empty, name, "{}"));
    window->Render();
    vtkPenumbraShadowPass* pass = ShadowPass(empty);
    CHECK(pass != nullptr);
    vtkNew<vtkFloatArray> out;
    llsm = vtkPenumbraLinkedListShadows::SafeDownCast(pass->GetTechnique());
    if (pass->GetNumberOfLights() > 0)
    {
      CHECK(llsm->ComputeVisibility(
        empty, pass->GetGeometry(), pass->GetViewSamples(), pass->GetLight(0), out));
      for (vtkIdType s = 0; s < out->GetNumberOfTuples(); ++s)
      {
        CHECK(out->GetValue(s) == -1.0f);
      }
      CHECK(llsm->GetNumberOfValidSamples() == 0 && llsm->GetNumberOfListedSamples() == 0);
    }
    empty->GetRenderWindow()->RemoveRenderer(empty);
    window->Finalize();
  }
  return EXIT_SUCCESS;
}

int CheckBadInput()
{
  vtkNew<vtkPenumbraLinkedListShadows> technique;
  CHECK(RefusesNullInputs(technique));
  vtkNew<vtkPenumbraTechniques> techniques;
  vtkNew<vtkRenderer> renderer;
  CHECK(techniques->Apply(renderer, "llsm", "{\"resolution\": 0}") == 0);
  CHECK(techniques->Apply(renderer, "llsm", "{\"capacity\": -1}") == 0);
  CHECK(techniques->Apply(renderer, "llsm", "{\"classify_resolution\": 512}") == 0);
  CHECK(techniques->Apply(renderer, "llsm-hybrid", "{\"classify_resolution\": 512}") == 1);
  CHECK(techniques->Apply(renderer, "llsm", "{\"resolution\": 1, \"capacity\": 5}") == 1);
  CHECK(techniques->Apply(renderer, "llsm", "{\"lists\": \"gpu\"}") == 1);
  CHECK(techniques->Apply(renderer, "llsm-hybrid", "{\"lists\": \"gpu\"}") == 1);
  CHECK(techniques->Apply(renderer, "llsm", "{\"lists\": \"opencl\"}") == 0);
  return EXIT_SUCCESS;
}
}

int TestLinkedListShadows(int, char*[])
{
  RUN(CheckBadInput());
  RUN(CheckPlane());
  RUN(CheckThinWire());
  RUN(CheckDegenerateLists());
  RUN(CheckListPaths());
  RUN(CheckEmptyFrames());
  RUN(CheckDefaultScene());
  RUN(CheckTortureScenes());
  return EXIT_SUCCESS;
}
