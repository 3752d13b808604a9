// penumbra-bench: measuring the scene benchmark, the reference of each scene and every
// technique's timed frames and error against it (see penumbra-bench.cxx for the method).

#include "PenumbraBenchScenes.h"
#include "PenumbraCLI.h"

#include "vtkActor.h"
#include "vtkActorCollection.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraImageIO.h"
#include "vtkPenumbraLineReference.h"
#include "vtkPenumbraMetrics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraResolutionMatchedShadows.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraStatistics.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkPointData.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"
#include "vtksys/SystemTools.hxx"

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

namespace
{
using namespace penumbra_bench;

// The light sampling of a setting ("samples=16;path=gpu" -> "samples=16"): GEARS points are
// compared with the ray tracer at the same k whatever their other options.
std::string SamplesKey(const std::string& setting)
{
  std::istringstream in(setting);
  std::string item;
  while (std::getline(in, item, ';'))
  {
    if (item.rfind("samples=", 0) == 0)
    {
      return item;
    }
  }
  return "default";
}

// Every light that is on and actually emits, with its number in VTK's shader order (the
// lights that are on): the lights whose shadows are measured.
std::vector<std::pair<vtkLight*, int>> MeasuredLights(vtkRenderer* ren)
{
  std::vector<std::pair<vtkLight*, int>> measured;
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  int shaderIndex = 0;
  while (vtkLight* l = lights->GetNextLight(it))
  {
    if (!l->GetSwitch())
    {
      continue;
    }
    if (penumbra_rules::LightEmits(l))
    {
      measured.emplace_back(l, shaderIndex);
    }
    ++shaderIndex;
  }
  return measured;
}

std::string KindOf(vtkLight* light)
{
  if (auto* area = vtkPenumbraAreaLight::SafeDownCast(light))
  {
    const int shape = area->GetShape();
    return shape == vtkPenumbraAreaLight::Line
      ? "linear"
      : (shape == vtkPenumbraAreaLight::Disc ? "disc" : "area");
  }
  if (!light->GetPositional())
  {
    return "directional";
  }
  return light->GetConeAngle() < 90.0 ? "spot" : "point";
}

// Visibility of `light` recovered from images: white diffuse-only render lit by that light
// alone, with the technique's pass, divided by the same without shadows. `measurable` marks
// the samples where the unshadowed render is bright enough for the ratio to mean anything;
// the others (grazing or unlit) are left out of the comparison rather than guessed.
// Median of `frames` renders in which nothing changes, with the shadow pass allowed to reuse
// its last visibility (its default): what a re-render for a widget or a screenshot costs.
double TimeStillFrames(vtkRenderer* ren, vtkRenderWindow* win, int frames)
{
  if (vtkPenumbraShadowPass* pass = ShadowPassOf(ren))
  {
    pass->ReuseUnchangedFramesOn();
  }
  const FrameTimes times =
    TimeFrames(win, 1, frames, std::numeric_limits<double>::infinity(), [](int) {});
  return times.Median();
}

vtkSmartPointer<vtkFloatArray> RecoverVisibility(vtkRenderer* ren, vtkRenderWindow* win,
  vtkLight* light, vtkPenumbraViewSamples* samples, vtkUnsignedCharArray* measurable)
{
  struct Saved
  {
    vtkActor* Actor;
    double Color[3], Ambient, Diffuse, Specular;
    int Interpolation;
  };
  std::vector<Saved> saved;
  vtkActorCollection* actors = ren->GetActors();
  vtkCollectionSimpleIterator ait;
  actors->InitTraversal(ait);
  while (vtkActor* a = actors->GetNextActor(ait))
  {
    vtkProperty* p = a->GetProperty();
    Saved s{ a, { 0, 0, 0 }, p->GetAmbient(), p->GetDiffuse(), p->GetSpecular(),
      p->GetInterpolation() };
    p->GetColor(s.Color);
    saved.push_back(s);
    p->SetColor(1, 1, 1);
    p->SetAmbient(0.0);
    p->SetDiffuse(1.0);
    p->SetSpecular(0.0);
    if (p->GetInterpolation() == VTK_PBR)
    {
      p->SetInterpolationToPhong();
    }
  }
  std::vector<std::pair<vtkLight*, int>> switches;
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator lit;
  lights->InitTraversal(lit);
  while (vtkLight* l = lights->GetNextLight(lit))
  {
    switches.emplace_back(l, l->GetSwitch());
    l->SetSwitch(l == light ? 1 : 0);
  }

  vtkSmartPointer<vtkRenderPass> pass = ren->GetPass();
  win->Render();
  vtkSmartPointer<vtkImageData> shadowed = penumbra_cli::GrabLuminance(win);
  ren->SetPass(nullptr);
  win->Render();
  vtkSmartPointer<vtkImageData> unshadowed = penumbra_cli::GrabLuminance(win);
  ren->SetPass(pass);

  for (auto& s : saved)
  {
    vtkProperty* p = s.Actor->GetProperty();
    p->SetColor(s.Color);
    p->SetAmbient(s.Ambient);
    p->SetDiffuse(s.Diffuse);
    p->SetSpecular(s.Specular);
    p->SetInterpolation(s.Interpolation);
  }
  for (auto& sw : switches)
  {
    sw.first->SetSwitch(sw.second);
  }

  auto* a = vtkFloatArray::SafeDownCast(shadowed->GetPointData()->GetScalars());
  auto* b = vtkFloatArray::SafeDownCast(unshadowed->GetPointData()->GetScalars());
  auto vis = vtkSmartPointer<vtkFloatArray>::New();
  vis->SetNumberOfTuples(samples->GetNumberOfSamples());
  measurable->SetNumberOfTuples(samples->GetNumberOfSamples());
  for (vtkIdType i = 0; i < vis->GetNumberOfTuples(); ++i)
  {
    const float lit = b->GetValue(i);
    const bool ok = samples->IsValid(i) && lit > 8.0f / 255.0f;
    measurable->SetValue(i, ok ? 1 : 0);
    vis->SetValue(
      i, ok ? std::min(1.0f, a->GetValue(i) / lit) : (samples->IsValid(i) ? 0.0f : -1.0f));
  }
  return vis;
}

std::string FileSafe(std::string s)
{
  for (char& c : s)
  {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_')
    {
      c = '_';
    }
  }
  return s;
}

// What every point of one scene is measured against.
struct SceneContext
{
  std::string Label;
  vtkRenderer* Renderer = nullptr;
  vtkRenderWindow* Window = nullptr;
  penumbra_cli::ErrorLog* Errors = nullptr;
  vtkPenumbraTechniques* Registry = nullptr;
  vtkNew<vtkPenumbraViewSamples> Samples;
  // One per light that is on and emits, each scored on its own.
  struct Measured
  {
    vtkLight* Light = nullptr;                  // as shadowed: a sphere light's disc
    vtkLight* Source = nullptr;                 // the renderer's light
    vtkSmartPointer<vtkPenumbraAreaLight> Disc; // a sphere light's disc, as the pass makes it
    int LightIndex = -1;                        // in VTK's shader numbering
    vtkPenumbraAreaLight* Area = nullptr;       // Light, if it is an area or linear light
    vtkNew<vtkFloatArray> Reference;
    vtkNew<vtkUnsignedCharArray> Ties; // hard lights: near-ties, excluded from the comparison
    // The ray tracer's visibility per setting ("samples=16"), so a GEARS point at the same k
    // can be checked for exactness on the full-size frame.
    std::map<std::string, vtkSmartPointer<vtkFloatArray>> TracedAtK;
    std::string ReferenceNote; // which reference, for results.md
  };
  std::vector<std::unique_ptr<Measured>> Lights;
};
using Measured = SceneContext::Measured;

// View samples and exact visibility of every measured light, from the ray tracer on the very
// same camera and window size. Returns why there is no reference, or "".
std::string ComputeReference(SceneContext& ctx)
{
  ctx.Registry->Apply(ctx.Renderer, "raytraced", "{}");
  ctx.Window->Render();
  vtkPenumbraShadowPass* refPass = ShadowPassOf(ctx.Renderer);
  const auto lights = MeasuredLights(ctx.Renderer);
  if (!refPass || lights.empty() || ctx.Errors->Raised())
  {
    return ctx.Errors->Raised() ? ctx.Errors->FirstError() : "no light to measure";
  }
  ctx.Samples->DeepCopy(refPass->GetViewSamples());
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(refPass->GetGeometry());
  ctx.Lights.clear();
  for (const auto& l : lights)
  {
    auto m = std::make_unique<Measured>();
    m->Light = m->Source = l.first;
    m->LightIndex = l.second;
    m->Area = vtkPenumbraAreaLight::SafeDownCast(l.first);
    // A sphere light is measured as the disc the pass shadows (the same function decides).
    auto disc = vtkSmartPointer<vtkPenumbraAreaLight>::New();
    if (!m->Area &&
      disc->SetFromLightRadius(l.first, vtkPenumbraShadowKeys::GetLightRadius(l.first)))
    {
      m->Disc = disc;
      m->Light = m->Area = m->Disc;
    }
    if (m->Area && m->Area->GetShape() == vtkPenumbraAreaLight::Line)
    {
      // A linear light has an exact answer: no sampling error left in the yardstick.
      vtkNew<vtkPenumbraLineReference> exact;
      exact->SetGeometry(refPass->GetGeometry());
      if (!exact->ComputeVisibility(ctx.Samples, m->Area, m->Reference))
      {
        return exact->GetErrorMessage();
      }
      m->Ties->DeepCopy(exact->GetTies());
      m->ReferenceNote = "exact linear-light interval union (vtkPenumbraLineReference), " +
        std::to_string(exact->GetNumberOfTies()) + " near-tie samples excluded, " +
        Fixed(exact->GetLastTimeMs(), 0) + " ms";
    }
    else if (m->Area)
    {
      reference->ComputeConvergedVisibility(ctx.Samples, m->Area, 64, m->Reference);
      m->ReferenceNote = "converged area-light estimate, 64 x 64 light samples";
    }
    else
    {
      // Traced again light by light: the ties are the last traced light's.
      reference->ComputeVisibility(ctx.Samples, m->Light, m->Reference);
      m->Ties->DeepCopy(reference->GetTies());
      m->ReferenceNote = "exact hard-shadow rays, near-ties excluded";
    }
    ctx.Lights.push_back(std::move(m));
  }
  return "";
}

// How many samples of light `m` the pass's visibility gives differently from the ray tracer
// at the same number of light samples in this run (soft techniques that sample the light as
// the reference does, GEARS: Wang et al. 2014, Tables 5-6 analogues), or -1 when the ray
// tracer did not run at that setting.
vtkIdType DifferencesFromTraced(
  vtkPenumbraShadowPass* pass, const Measured& m, const TechniqueSpec& spec)
{
  auto traced = m.TracedAtK.find(SamplesKey(spec.Setting));
  vtkFloatArray* mine = pass->GetVisibility(m.LightIndex);
  if (traced == m.TracedAtK.end() || !mine ||
    mine->GetNumberOfTuples() != traced->second->GetNumberOfTuples())
  {
    return -1;
  }
  vtkIdType differ = 0;
  for (vtkIdType i = 0; i < mine->GetNumberOfTuples(); ++i)
  {
    differ += mine->GetValue(i) != traced->second->GetValue(i);
  }
  return differ;
}

// The map size a shadow-map technique reports, "W×H (need w×h)", or "".
std::string MapSizeOf(vtkPenumbraStatistics* stats)
{
  if (!stats->Has("map_width"))
  {
    return "";
  }
  std::string size = std::to_string(std::lround(stats->Get("map_width"))) + "×" +
    std::to_string(std::lround(stats->Get("map_height")));
  if (stats->Has("needed_width"))
  {
    size += " (need " + std::to_string(std::lround(stats->Get("needed_width"))) + "×" +
      std::to_string(std::lround(stats->Get("needed_height"))) + ")";
  }
  return size;
}

// The pass's phases and the technique's statistics of the last frame into `row` (read from
// the statistics table, whatever the technique); returns a copy of its visibility of light
// `m`, or nullptr for passes that expose none.
vtkSmartPointer<vtkFloatArray> ReadPass(
  SceneContext& ctx, Measured& m, const TechniqueSpec& spec, Row& row)
{
  vtkPenumbraShadowPass* pass = ShadowPassOf(ctx.Renderer);
  if (!pass)
  {
    return nullptr;
  }
  row.ExtractionMs = pass->GetExtractionTimeMs();
  row.SamplesMs = pass->GetSamplesTimeMs();
  row.TechniqueMs = pass->GetTechniqueTimeMs();
  row.ShadingMs = pass->GetShadingTimeMs();
  row.LightTechnique = pass->GetLightTechniqueName(m.LightIndex);
  vtkNew<vtkPenumbraStatistics> stats;
  if (pass->GetLightTechnique(m.LightIndex) && pass->GetLightStatistics(m.LightIndex, stats))
  {
    // The share of the last light the technique handled in the last frame (the measured
    // light in single-light scenes).
    if (stats->Has("uncertain_share"))
    {
      row.UncertainShare = stats->Get("uncertain_share");
    }
    if (stats->Has("fill_fragments"))
    {
      row.FillFragments = std::llround(stats->Get("fill_fragments"));
    }
    row.MapSize = MapSizeOf(stats);
    if (m.Area)
    {
      const vtkIdType differ = DifferencesFromTraced(pass, m, spec);
      if (differ >= 0)
      {
        stats->Set("differs_from_raytraced", static_cast<double>(differ));
      }
    }
    row.Statistics = stats->Format();
    std::cerr << "\n"
              << ctx.Label << " " << spec.Label() << " light " << m.LightIndex << ": "
              << row.Statistics << "\n";
  }
  auto estimate = vtkSmartPointer<vtkFloatArray>::New();
  if (vtkFloatArray* v = pass->GetVisibility(m.LightIndex))
  {
    estimate->DeepCopy(v);
  }
  if (spec.Name == "raytraced")
  {
    m.TracedAtK[SamplesKey(spec.Setting)] = estimate;
  }
  return estimate;
}

// --mismatch-lists: the samples of light `m` that `estimate` gets wrong, into `path`, and a
// summary on stderr (with rmsm's per-sample levels).
void ListMismatches(SceneContext& ctx, Measured& m, const TechniqueSpec& spec,
  vtkFloatArray* estimate, const std::string& path)
{
  vtkNew<vtkIntArray> levels;
  vtkPenumbraShadowPass* pass = ShadowPassOf(ctx.Renderer);
  auto* rmsm = vtkPenumbraResolutionMatchedShadows::SafeDownCast(
    pass ? pass->GetLightTechnique(m.LightIndex) : nullptr);
  const bool haveLevels = rmsm && rmsm->GetSampleLevels(m.Light, levels);
  std::cerr << "\n"
            << ctx.Label << " " << spec.Label() << " light " << m.LightIndex << ": "
            << WriteMismatchList(path, ctx.Samples, estimate, m.Reference, m.Ties, m.Light,
                 haveLevels ? levels.Get() : nullptr)
            << "\n";
}

// Error of `estimate` against the reference into `row`, and the point's images.
void ScorePoint(SceneContext& ctx, Measured& m, const TechniqueSpec& spec, const Options& o,
  vtkSmartPointer<vtkFloatArray> estimate, Row& row)
{
  vtkSmartPointer<vtkUnsignedCharArray> measurable; // null: every valid sample counts
  if (!estimate || estimate->GetNumberOfTuples() != ctx.Samples->GetNumberOfSamples())
  {
    measurable = vtkSmartPointer<vtkUnsignedCharArray>::New();
    estimate = RecoverVisibility(ctx.Renderer, ctx.Window, m.Source, ctx.Samples, measurable);
  }
  const std::string stem =
    o.OutDir + "/" + FileSafe(ctx.Label + "__" + spec.Name + "_" + spec.Setting);
  // Error images per light; the first light keeps the name single-light scenes always had.
  const std::string errorStem = stem +
    (m.LightIndex == ctx.Lights.front()->LightIndex ? "" : "_light" + std::to_string(m.LightIndex));
  vtkNew<vtkPenumbraMetrics> metrics;
  if (!m.Area)
  {
    metrics->CompareHard(estimate, m.Reference, m.Ties, measurable);
    row.MismatchRate = metrics->GetMismatchRate();
    row.FalseLit = metrics->GetFalseLit();
    row.FalseShadow = metrics->GetFalseShadow();
    row.Candidates = metrics->GetCandidates();
    row.Ties = metrics->GetTies();
    if (o.Images)
    {
      metrics->WriteErrorImage(o.Width, o.Height, (errorStem + "_error.png").c_str());
    }
    if (o.MismatchLists)
    {
      ListMismatches(ctx, m, spec, estimate, errorStem + "_mismatch.csv");
    }
  }
  const bool exactSoft = m.Area && m.Area->GetShape() == vtkPenumbraAreaLight::Line;
  metrics->CompareSoft(
    estimate, m.Reference, measurable, !m.Area || exactSoft ? m.Ties.Get() : nullptr);
  row.MAE = metrics->GetMAE();
  row.RMSE = metrics->GetRMSE();
  row.MaxError = metrics->GetMaxError();
  row.P95 = metrics->GetP95Error();
  if (m.Area && o.Images)
  {
    metrics->WriteErrorImage(o.Width, o.Height, (errorStem + "_error.png").c_str());
  }
  if (o.Images && errorStem == stem)
  {
    ctx.Window->Render();
    vtkNew<vtkPenumbraImageIO> io;
    io->Write(penumbra_cli::GrabRGB(ctx.Window), (stem + ".png").c_str());
  }
}

// Whether `spec` has anything to say about light `m`: a light-sample count means nothing
// for a hard light, and a hard-shadow technique nothing for an area light (the pass hands
// that light to its soft fallback, whose work it is not).
bool Scores(const SceneContext& ctx, const Measured& m, const TechniqueSpec& spec)
{
  if (!m.Area && spec.Options.contains("samples"))
  {
    return false;
  }
  vtkPenumbraShadowPass* pass = ShadowPassOf(ctx.Renderer);
  return !(m.Area && pass && pass->GetTechnique() && !pass->GetTechnique()->CanShadow(m.Light));
}

// One technique on one scene: timed frames, phases, and per light its error against the
// reference. Appends a row per light it scores, or a failure, or nothing where the technique
// has nothing to say about any light.
void MeasurePoint(SceneContext& ctx, const TechniqueSpec& spec, const Options& o, BenchRun& run)
{
  const std::string what = ctx.Label + ": " + spec.Name + " " + spec.Setting;
  if (spec.Options.contains("samples") &&
    std::none_of(ctx.Lights.begin(), ctx.Lights.end(), [](const auto& m) { return m->Area; }))
  {
    return; // a light-sample count means nothing for hard lights
  }
  Progress(run.Done, run.Total, what);
  if (!ctx.Registry->Apply(ctx.Renderer, spec.Name.c_str(), spec.Options.dump().c_str()))
  {
    run.Fail(what, ctx.Registry->GetErrorMessage()); // options were checked before the run
    return;
  }
  if (std::none_of(
        ctx.Lights.begin(), ctx.Lights.end(), [&](const auto& m) { return Scores(ctx, *m, spec); }))
  {
    return;
  }
  vtkPenumbraShadowPass* applied = ShadowPassOf(ctx.Renderer);
  // Timed frames redo the shadow work (the pass would otherwise reuse a still frame's
  // visibility); --still-frames times that reuse separately.
  if (applied)
  {
    applied->ReuseUnchangedFramesOff();
  }
  // --moving-light, --moving-camera: a new light or camera position for every frame, by a
  // negligible amount, restored afterwards.
  vtkLight* moving = ctx.Lights.front()->Source;
  vtkCamera* camera = ctx.Renderer->GetActiveCamera();
  double home[3], eye[3];
  moving->GetPosition(home);
  camera->GetPosition(eye);
  auto nudge = [](const double p[3], int f)
  { return (f + 1) * 1e-9 * (1.0 + std::fabs(p[0]) + std::fabs(p[1]) + std::fabs(p[2])); };
  const FrameTimes times =
    TimeFrames(ctx.Window, o.Warmup, o.Frames, std::numeric_limits<double>::infinity(),
      [&](int f)
      {
        if (o.MovingLight)
        {
          moving->SetPosition(home[0] + nudge(home, f), home[1], home[2]);
        }
        if (o.MovingCamera)
        {
          camera->SetPosition(eye[0] + nudge(eye, f), eye[1], eye[2]);
        }
      });
  if (o.MovingLight || o.MovingCamera)
  {
    moving->SetPosition(home);
    camera->SetPosition(eye);
    ctx.Window->Render();
    ctx.Window->WaitForCompletion();
  }
  if (ctx.Errors->Raised())
  {
    run.Fail(what, "rendering failed: " + ctx.Errors->FirstError());
    ctx.Errors->Clear();
    return;
  }
  double stillMs = -1.0;
  const size_t first = run.Rows.size();
  for (auto& m : ctx.Lights)
  {
    if (!Scores(ctx, *m, spec))
    {
      continue;
    }
    Row row;
    row.Scene = ctx.Label;
    row.Technique = spec.Name;
    row.Setting = spec.Setting;
    row.Light = m->LightIndex;
    row.SceneLights = static_cast<int>(ctx.Lights.size());
    row.LightKind = KindOf(m->Light);
    row.Width = o.Width;
    row.Height = o.Height;
    row.MedianMs = times.Median();
    row.MinMs = times.Ms.front();
    row.ErrorKind = m->Area ? "soft" : "hard";
    ScorePoint(ctx, *m, spec, o, ReadPass(ctx, *m, spec, row), row);
    run.Rows.push_back(row);
  }
  if (o.StillFrames && run.Rows.size() > first)
  {
    stillMs = TimeStillFrames(ctx.Renderer, ctx.Window, o.Frames); // after the phases were read
    for (size_t r = first; r < run.Rows.size(); ++r)
    {
      run.Rows[r].StillMs = stillMs;
    }
  }
}
}

namespace penumbra_bench
{
// Every technique on one scene. Returns -1 to go on, or the exit status (no window).
int MeasureScene(const std::string& sceneName, const Options& o, BenchRun& run)
{
  const int points =
    static_cast<int>(o.Techniques.size()) + 1; // the reference, then each technique
  const std::string path = ResolveScene(sceneName);
  const std::string label = vtksys::SystemTools::GetFilenameWithoutLastExtension(path);
  Progress(run.Done, run.Total, label + ": loading");
  vtkNew<vtkPenumbraSceneReader> reader;
  reader->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
  reader->SetFileName(path.c_str());
  if (!reader->Read())
  {
    run.Fail(label, reader->GetErrorMessage());
    run.Done += points;
    return -1;
  }
  SceneContext ctx;
  ctx.Label = label;
  ctx.Renderer = reader->GetRenderer();
  penumbra_cli::ErrorLog errors;
  ctx.Errors = &errors;
  std::string windowError;
  vtkSmartPointer<vtkRenderWindow> win =
    penumbra_cli::MakeWindow(o.Width, o.Height, ctx.Renderer, errors, windowError);
  if (!win)
  {
    std::cerr << "\npenumbra-bench: " << windowError << "\n";
    return 3;
  }
  ctx.Window = win;
  Progress(run.Done, run.Total, label + ": reference");
  vtkNew<vtkPenumbraTechniques> registry;
  ctx.Registry = registry;
  const std::string why = ComputeReference(ctx);
  if (!why.empty())
  {
    run.Fail(label, why);
    errors.Clear();
    run.Done += points;
  }
  else
  {
    for (const auto& m : ctx.Lights)
    {
      run.References.push_back(
        label + ", light " + std::to_string(m->LightIndex) + ": " + m->ReferenceNote);
    }
    ++run.Done;
    for (const auto& spec : o.Techniques)
    {
      MeasurePoint(ctx, spec, o, run);
      ++run.Done;
    }
  }
  double noShadowMs = 0.0;
  for (const Row& r : run.Rows)
  {
    noShadowMs = r.Scene == label && r.Technique == "none" ? r.MedianMs : noShadowMs;
  }
  for (Row& r : run.Rows)
  {
    if (r.Scene == label)
    {
      r.RatioToNoShadow = noShadowMs > 0 ? r.MedianMs / noShadowMs : 0.0;
      r.StillRatio = r.StillMs >= 0 && noShadowMs > 0 ? r.StillMs / noShadowMs : -1.0;
    }
  }
  registry->Apply(ctx.Renderer, "none", "");
  win->Finalize();
  return -1;
}
}
