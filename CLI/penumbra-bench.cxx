// penumbra-bench: error against run time for every shadow technique, on the same scenes and
// view samples, next to its peers (no shadows, VTK's vtkShadowMapPass, the exact reference).
//
//   penumbra-bench [--scenes A,B,...] [--techniques T[:k=v;k=v],...] [--size WxH]
//                  [--frames N] [--warmup N] [--moving-light] [--moving-camera]
//                  [--still-frames] [--no-images] [--mismatch-lists] --out DIR
//
// Writes DIR/results.csv, DIR/results.md and DIR/chart.png (and, unless --no-images, each
// point's image and error image; with --mismatch-lists, per hard light and point a CSV of the
// samples that disagree with the reference, and a summary by category on stderr). Scenes are names
// of files in Data/Scenes or paths to scene files. A progress bar goes to stderr.
//
// Method, per scene:
//  - the view samples and the exact visibility of every light of the scene that is on and
//    emits come from the ray-traced reference on the very same camera and window size (for an
//    area light: a converged 64 x 64-sample estimate; for a linear light: the exact interval
//    union of vtkPenumbraLineReference, near-ties excluded; for hard lights: one exact ray per
//    sample, near-ties reported and excluded); each point gives one row per light, with the
//    frame's times and that light's error; results.md names each light's reference;
//  - each technique renders `warmup` frames, then `frames` timed frames (glFinish before the
//    clock stops); the median is reported, with the phases of vtkPenumbraShadowPass. Nothing
//    moves by default, so techniques that cache (shadow maps) are timed on reuse; with
//    --moving-light the measured light moves by a negligible amount before every frame
//    (1e-9 of its position's scale; the scene's first measured light), which invalidates such
//    caches, and is put back for one untimed frame before the error is measured; --moving-camera
//    does the same with the camera, so the view samples are rendered every frame; the pass's reuse
//    of unchanged frames is off for timed frames, --still-frames times it separately;
//  - techniques with a `samples` option (k x k soft shadows: gears, raytraced) are scored on
//    area and linear lights only, hard-shadow techniques on the lights they can shadow (the
//    pass hands the others to its soft fallback, which is not the technique's work); GEARS
//    points also print their grid statistics and the samples that differ from raytraced at
//    the same k; the `light_technique` column names what shadowed the light (auto's choice);
//  - its visibility for each light is read from the pass, or, for passes that do not expose
//    one (VTK's vtkShadowMapPass), recovered as the ratio of a white, diffuse-only render
//    with shadows to the same render without, lit by that light alone.
//
// With --scale-sweep the bench measures run time against triangle count on a generated
// scene instead (see PenumbraBenchSweep.cxx).

#include "PenumbraBench.h"
#include "PenumbraCLI.h"

#include "vtkActor.h"
#include "vtkActorCollection.h"
#include "vtkAxis.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkCameraPass.h"
#include "vtkChartLegend.h"
#include "vtkChartMatrix.h"
#include "vtkChartXY.h"
#include "vtkCommand.h"
#include "vtkContextScene.h"
#include "vtkContextView.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraImageIO.h"
#include "vtkPenumbraLineReference.h"
#include "vtkPenumbraLinkedListShadows.h"
#include "vtkPenumbraMetrics.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraResolutionMatchedShadows.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraShadowVolumeShadows.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkPlot.h"
#include "vtkPlotPoints.h"
#include "vtkPointData.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkTable.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVector.h"
#include "vtksys/SystemTools.hxx"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#ifndef PENUMBRA_SCENES_DIR
#define PENUMBRA_SCENES_DIR "Data/Scenes"
#endif

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

struct Row
{
  std::string Scene, Technique, Setting, ErrorKind;
  // The measured light: its number among the lights that are on (VTK's shader order), what
  // it is, how many the scene measures, and the technique that shadowed it ("" for VTK's
  // pass and none).
  int Light = 0, SceneLights = 1;
  std::string LightKind, LightTechnique;
  int Width = 0, Height = 0;
  double MedianMs = 0, MinMs = 0;
  double ExtractionMs = -1, SamplesMs = -1, TechniqueMs = -1, ShadingMs = -1;
  double MismatchRate = 0, MAE = 0, RMSE = 0, MaxError = 0, P95 = 0;
  // Hybrid techniques: share of samples handed to the exact fallback; -1 = not applicable.
  double UncertainShare = -1;
  // Shadow volumes with measure_fill: rasterized volume fragments per frame; -1 = not measured.
  long long FillFragments = -1;
  // Shadow maps: texels along s x t of the last light's map (RESM chooses them).
  std::string MapSize;
  vtkIdType FalseLit = 0, FalseShadow = 0, Candidates = 0, Ties = 0;
  double RatioToNoShadow = 0;
  // --still-frames: median frame when nothing changes (the pass reuses its visibility).
  double StillMs = -1, StillRatio = -1;
  // GEARS (analogues of Wang et al. 2014, Tables 5-6): per-cell loads and the share of assigned
  // triangles that actually block; empty for other techniques.
  std::string GearsStats;
};

int Usage(const char* why)
{
  if (why)
  {
    std::cerr << "penumbra-bench: " << why << "\n";
  }
  std::cerr << "usage: penumbra-bench [--scenes A,B,...] [--techniques T[:k=v;k=v],...]"
               " [--size WxH] [--frames N] [--warmup N] [--moving-light] [--moving-camera] "
               "[--still-frames] [--no-images] [--mismatch-lists]"
               " --out DIR\n"
               "       penumbra-bench --scale-sweep [N1,N2,...] [--budget SECONDS]"
               " [--techniques ...] [--size WxH] [--frames N] [--warmup N] --out DIR\n";
  return 2;
}

std::string ResolveScene(const std::string& name)
{
  if (vtksys::SystemTools::FileExists(name, true))
  {
    return name;
  }
  return std::string(PENUMBRA_SCENES_DIR) + "/" + name + ".json";
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
    return area->GetShape() == vtkPenumbraAreaLight::Line ? "linear" : "area";
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

std::string Sci(double v)
{
  std::ostringstream s;
  s << std::scientific << std::setprecision(3) << v;
  return s.str();
}

void WriteCSV(const std::string& path, const std::vector<Row>& rows)
{
  std::ofstream out(path);
  out << "scene,technique,setting,light,light_kind,light_technique,width,height,median_ms,min_ms,"
         "extraction_ms,samples_ms,"
         "technique_ms,shading_ms,ratio_to_no_shadow,error_kind,mismatch_rate,false_lit,"
         "false_shadow,candidates,ties,mae,rmse,max_error,p95_error,uncertain_share,fill_fragments,"
         "map_size,still_ms,still_ratio_to_no_shadow\n";
  for (const Row& r : rows)
  {
    out << r.Scene << "," << r.Technique << ",\"" << r.Setting << "\"," << r.Light << ","
        << r.LightKind << "," << r.LightTechnique << "," << r.Width << "," << r.Height << ","
        << r.MedianMs << "," << r.MinMs << "," << r.ExtractionMs << "," << r.SamplesMs << ","
        << r.TechniqueMs << "," << r.ShadingMs << "," << r.RatioToNoShadow << "," << r.ErrorKind
        << "," << r.MismatchRate << "," << r.FalseLit << "," << r.FalseShadow << "," << r.Candidates
        << "," << r.Ties << "," << r.MAE << "," << r.RMSE << "," << r.MaxError << "," << r.P95
        << "," << (r.UncertainShare < 0 ? std::string() : std::to_string(r.UncertainShare)) << ","
        << (r.FillFragments < 0 ? std::string() : std::to_string(r.FillFragments)) << ","
        << r.MapSize << "," << (r.StillMs < 0 ? std::string() : std::to_string(r.StillMs)) << ","
        << (r.StillRatio < 0 ? std::string() : std::to_string(r.StillRatio)) << "\n";
  }
}

void WriteMarkdown(const std::string& path, const std::vector<Row>& rows,
  const std::vector<std::string>& failures, const std::vector<std::string>& references,
  const Options& o)
{
  std::ofstream out(path);
  const char* moving = o.MovingLight && o.MovingCamera
    ? "the light and the camera moving before every frame (no cached maps, view samples "
      "rendered every frame). "
    : o.MovingLight  ? "the light moving before every frame (no cached shadow maps; the view "
                       "samples are kept). "
    : o.MovingCamera ? "the camera moving before every frame (view samples rendered every frame). "
                     : "nothing moving, the shadow work redone every frame (cached shadow maps "
                       "and view samples are reused). ";
  out
    << "# Shadow techniques: error against run time\n\n"
    << "Median of " << o.Frames << " frames after " << o.Warmup
    << " warm-up frame(s), glFinish before each clock reading, " << moving
    << "Error is measured per light (one row each; the frame times are the frame's, all "
       "lights shadowed) against the exact reference on the same view samples: mismatch "
       "rate over lit-candidate samples for hard lights (near-ties excluded), mean absolute "
       "error of visibility for area/linear lights.\n\n"
    << "| scene | technique | setting | light | shadowed by | size | median ms | × no-shadow | "
       "extract | samples | "
       "technique | shading | mismatch | false lit | false shadow | ties | MAE | p95 | uncertain | "
       "fill | map | still ms (×) |\n"
    << "|---|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|-"
       "--:|---:|---:|\n";
  auto phase = [](double v) { return v < 0 ? std::string("–") : Fixed(v, 1); };
  for (const Row& r : rows)
  {
    out << "| " << r.Scene << " | " << r.Technique << " | " << r.Setting << " | " << r.Light << " "
        << r.LightKind << " | " << (r.LightTechnique.empty() ? "–" : r.LightTechnique) << " | "
        << r.Width << "×" << r.Height << " | " << Fixed(r.MedianMs, 1) << " | "
        << Fixed(r.RatioToNoShadow, 2) << " | " << phase(r.ExtractionMs) << " | "
        << phase(r.SamplesMs) << " | " << phase(r.TechniqueMs) << " | " << phase(r.ShadingMs)
        << " | " << Sci(r.MismatchRate) << " | " << r.FalseLit << " | " << r.FalseShadow << " | "
        << r.Ties << " | " << Fixed(r.MAE, 4) << " | " << Fixed(r.P95, 3) << " | "
        << (r.UncertainShare < 0 ? std::string("–") : Fixed(100.0 * r.UncertainShare, 2) + " %")
        << " | " << (r.FillFragments < 0 ? std::string("–") : std::to_string(r.FillFragments))
        << " | " << (r.MapSize.empty() ? std::string("–") : r.MapSize) << " | "
        << (r.StillMs < 0 ? std::string("–")
                          : Fixed(r.StillMs, 1) + " (" + Fixed(r.StillRatio, 2) + ")")
        << " |\n";
  }
  if (!references.empty())
  {
    out << "\nReference per scene:\n\n";
    for (const std::string& line : references)
    {
      out << "- " << line << "\n";
    }
  }
  bool gears = false;
  for (const Row& r : rows)
  {
    if (r.GearsStats.empty())
    {
      continue;
    }
    if (!gears)
    {
      out << "\nGEARS statistics of the last frame and the last light it handled (Wang et al. "
             "2014, Tables 5-6): busy cells / cells, triangles per busy cell (max, mean), "
             "global-list "
             "triangles, assignments and the share that block at least one light sample, light "
             "samples the reference traced, phase times, and the number of view samples whose "
             "visibility differs from the ray tracer at the same k in the same run.\n\n";
      gears = true;
    }
    out << "- " << r.Scene << " " << r.Setting << " light " << r.Light << ": " << r.GearsStats
        << "\n";
  }
  if (!failures.empty())
  {
    out << "\nNot measured (a scene that could not be read or had no light to measure, or a "
           "technique that failed on it; no point above):\n\n";
    for (const std::string& f : failures)
    {
      out << "- " << f << "\n";
    }
  }
}

// One log-log panel per scene: x = median frame time, y = error (0 drawn at the floor).
bool WriteChart(const std::string& path, const std::vector<Row>& rows, std::string& error)
{
  const double floorError = 1e-6;
  std::vector<std::string> scenes;
  for (const Row& r : rows)
  {
    if (std::find(scenes.begin(), scenes.end(), r.Scene) == scenes.end())
    {
      scenes.push_back(r.Scene);
    }
  }
  vtkNew<vtkContextView> view;
  view->GetRenderWindow()->SetOffScreenRendering(1);
  view->GetRenderWindow()->SetMultiSamples(0);
  view->GetRenderWindow()->SetSize(1100, 440 * static_cast<int>(scenes.size()));
  view->GetRenderer()->SetBackground(1, 1, 1);
  vtkNew<vtkChartMatrix> matrix;
  view->GetScene()->AddItem(matrix);
  matrix->SetSize(vtkVector2i(1, static_cast<int>(scenes.size())));
  // Room on the left for the error axis title.
  matrix->SetBorders(70, 45, 20, 30);
  matrix->SetGutter(vtkVector2f(30.0f, 70.0f)); // scene title clear of the x axis title above
  for (size_t s = 0; s < scenes.size(); ++s)
  {
    auto* chart = vtkChartXY::SafeDownCast(
      matrix->GetChart(vtkVector2i(0, static_cast<int>(scenes.size() - 1 - s))));
    chart->SetTitle(scenes[s]);
    chart->SetShowLegend(true);
    chart->GetAxis(vtkAxis::BOTTOM)->SetTitle("median frame time (ms)");
    chart->GetAxis(vtkAxis::BOTTOM)->SetLogScale(true);
    vtkAxis* errorAxis = chart->GetAxis(vtkAxis::LEFT);
    errorAxis->SetTitle("error (0 drawn at 1e-6)");
    errorAxis->SetLogScale(true);
    errorAxis->SetBehavior(vtkAxis::FIXED);
    errorAxis->SetUnscaledRange(0.3 * floorError, 2.0);
    // The time axis runs a decade past the slowest point: the legend (top right) then sits
    // over empty space and never hides a point.
    double tmin = std::numeric_limits<double>::max(), tmax = 0.0;
    for (const Row& r : rows)
    {
      if (r.Scene == scenes[s])
      {
        tmin = std::min(tmin, std::max(r.MedianMs, 1e-3));
        tmax = std::max(tmax, std::max(r.MedianMs, 1e-3));
      }
    }
    vtkAxis* timeAxis = chart->GetAxis(vtkAxis::BOTTOM);
    timeAxis->SetBehavior(vtkAxis::FIXED);
    timeAxis->SetUnscaledRange(tmin / 1.5, tmax * 12.0);
    std::map<std::string, vtkSmartPointer<vtkTable>> series;
    for (const Row& r : rows)
    {
      if (r.Scene != scenes[s])
      {
        continue;
      }
      const std::string label = TechniqueSpec{ r.Technique, r.Setting }.Label() +
        (r.SceneLights > 1 ? " light " + std::to_string(r.Light) : std::string());
      auto table = vtkSmartPointer<vtkTable>::New();
      vtkNew<vtkFloatArray> x;
      x->SetName("time");
      vtkNew<vtkFloatArray> y;
      y->SetName(label.c_str());
      x->InsertNextValue(static_cast<float>(std::max(r.MedianMs, 1e-3)));
      const double e = r.ErrorKind == "hard" ? r.MismatchRate : r.MAE;
      y->InsertNextValue(static_cast<float>(std::max(e, floorError)));
      table->AddColumn(x);
      table->AddColumn(y);
      series[label] = table;
    }
    // One colour per technique, one marker per setting within it.
    std::map<std::string, size_t> colours;
    std::map<std::string, int> markers;
    const int markerStyles[] = { vtkPlotPoints::CIRCLE, vtkPlotPoints::SQUARE,
      vtkPlotPoints::DIAMOND, vtkPlotPoints::CROSS, vtkPlotPoints::PLUS };
    for (auto& entry : series)
    {
      const std::string technique = entry.first.substr(0, entry.first.find(' '));
      if (!colours.count(technique))
      {
        const size_t next = colours.size();
        colours[technique] = next;
      }
      const int marker = markers[technique]++;
      auto* plot = vtkPlotPoints::SafeDownCast(chart->AddPlot(vtkChart::POINTS));
      plot->SetInputData(entry.second, 0, 1);
      plot->SetLabel(entry.first);
      const double* rgb = Palette[colours[technique] % PaletteSize];
      plot->SetColor(rgb[0], rgb[1], rgb[2]);
      plot->SetMarkerStyle(markerStyles[marker % 5]);
      plot->SetMarkerSize(marker % 5 >= 3 ? 14.0f : 10.0f);
      plot->SetWidth(3.0);
    }
  }
  return SaveChart(view, path, error);
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

// "1e4,1e5" -> { 10000, 100000 }: counts from 8 (the coarsest sphere) to 1e9.
bool ParseCounts(const std::string& text, std::vector<vtkIdType>& counts)
{
  counts.clear();
  for (const auto& item : Split(text, ','))
  {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (!end || *end || !(v >= 8.0) || v > 1e9)
    {
      return false;
    }
    counts.push_back(static_cast<vtkIdType>(std::llround(v)));
  }
  return !counts.empty();
}

// The command line into `o`. Returns -1 to go on, or the exit status.
int ParseArguments(int argc, char* argv[], Options& o)
{
  bool sizeGiven = false, scenesGiven = false, techniquesGiven = false, budgetGiven = false;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto value = [&]() -> std::string
    {
      if (i + 1 >= argc)
      {
        std::exit(Usage((a + " needs a value").c_str()));
      }
      return argv[++i];
    };
    if (a == "--scenes")
    {
      o.SceneNames = Split(value(), ',');
      scenesGiven = true;
    }
    else if (a == "--techniques")
    {
      o.TechniqueTexts = Split(value(), ',');
      techniquesGiven = true;
    }
    else if (a == "--size")
    {
      if (!penumbra_cli::ParseSize(value(), o.Width, o.Height))
      {
        return Usage("--size expects WxH, e.g. 640x480");
      }
      sizeGiven = true;
    }
    else if (a == "--frames" || a == "--warmup")
    {
      const std::string v = value();
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (!end || *end || n < (a == "--frames" ? 1 : 0) || n > 1000)
      {
        return Usage((a + " expects a count").c_str());
      }
      (a == "--frames" ? o.Frames : o.Warmup) = static_cast<int>(n);
    }
    else if (a == "--out")
    {
      o.OutDir = value();
    }
    else if (a == "--moving-light")
    {
      o.MovingLight = true;
    }
    else if (a == "--moving-camera")
    {
      o.MovingCamera = true;
    }
    else if (a == "--still-frames")
    {
      o.StillFrames = true;
    }
    else if (a == "--no-images")
    {
      o.Images = false;
    }
    else if (a == "--mismatch-lists")
    {
      o.MismatchLists = true;
    }
    else if (a == "--scale-sweep")
    {
      // The counts are optional: a following argument that is not an option is the list.
      const bool listed = i + 1 < argc && argv[i + 1][0] != '-';
      if (!ParseCounts(listed ? argv[++i] : "1e4,1e5,1e6,1e7", o.SweepTriangles))
      {
        return Usage("--scale-sweep expects triangle counts from 8 to 1e9, e.g. 1e4,1e5,1e6");
      }
    }
    else if (a == "--budget")
    {
      const std::string v = value();
      char* end = nullptr;
      o.BudgetSeconds = std::strtod(v.c_str(), &end);
      if (!end || *end || !(o.BudgetSeconds > 0.0))
      {
        return Usage("--budget expects seconds, e.g. 120");
      }
      budgetGiven = true;
    }
    else if (a == "-h" || a == "--help")
    {
      Usage(nullptr);
      return 0;
    }
    else
    {
      return Usage(("unknown argument " + a).c_str());
    }
  }
  if (o.OutDir.empty())
  {
    return Usage("--out DIR is required");
  }
  if (o.SweepTriangles.empty() && budgetGiven)
  {
    return Usage("--budget bounds the points of --scale-sweep");
  }
  if (!o.SweepTriangles.empty())
  {
    if (scenesGiven || o.MovingCamera || o.StillFrames)
    {
      return Usage("--scale-sweep renders its own scene and turns the camera: no --scenes, "
                   "--moving-camera or --still-frames (--moving-light adds rows with the sun "
                   "turning)");
    }
    o.Width = sizeGiven ? o.Width : SweepWidth;
    o.Height = sizeGiven ? o.Height : SweepHeight;
    o.TechniqueTexts = techniquesGiven ? o.TechniqueTexts : Split(SweepTechniques, ',');
  }
  if (o.SceneNames.empty() || o.TechniqueTexts.empty())
  {
    return Usage("nothing to measure");
  }
  return -1;
}

// Bad names and options are refused before anything is measured, not after the points
// before them have run. Fills o.Techniques and creates the output folder. Returns -1 to go
// on, or the exit status.
int CheckOptions(Options& o)
{
  for (const auto& t : o.TechniqueTexts)
  {
    TechniqueSpec spec;
    std::string error;
    if (!ParseTechnique(t, spec, error))
    {
      return Usage(error.c_str());
    }
    o.Techniques.push_back(spec);
  }
  for (const auto& sceneName : o.SweepTriangles.empty() ? o.SceneNames : std::vector<std::string>())
  {
    if (!vtksys::SystemTools::FileExists(ResolveScene(sceneName), true))
    {
      return Usage(("no scene file " + ResolveScene(sceneName)).c_str());
    }
  }
  vtkNew<vtkPenumbraTechniques> registry;
  for (const auto& spec : o.Techniques)
  {
    vtkNew<vtkRenderer> probe;
    if (!registry->Apply(probe, spec.Name.c_str(), spec.Options.dump().c_str()))
    {
      return Usage((spec.Name + " " + spec.Setting + ": " + registry->GetErrorMessage()).c_str());
    }
  }
  // Every point needs the no-shadow time for its ratio: measure it even if not asked for.
  if (std::none_of(o.Techniques.begin(), o.Techniques.end(),
        [](const TechniqueSpec& t) { return t.Name == "none"; }))
  {
    o.Techniques.insert(
      o.Techniques.begin(), TechniqueSpec{ "none", "default", nlohmann::json::object() });
  }
  if (!vtksys::SystemTools::MakeDirectory(o.OutDir))
  {
    std::cerr << "penumbra-bench: cannot create " << o.OutDir << "\n";
    return 2;
  }
  return -1;
}

// The rows so far, and what could not be measured. A technique that refuses a scene or
// fails is reported and skipped; the other points are still measured and written, and the
// exit status says that something was missing.
struct BenchRun
{
  std::vector<Row> Rows;
  std::vector<std::string> Failures;
  std::vector<std::string> References; // per scene: which reference the errors are against
  int Done = 0, Total = 0;

  void Fail(const std::string& what, const std::string& why)
  {
    std::cerr << "\npenumbra-bench: " << what << ": " << why << "\n";
    std::string line = what + ": " + why;
    std::replace(line.begin(), line.end(), '\n', ' ');
    this->Failures.push_back(line);
  }
};

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
    vtkLight* Light = nullptr;
    int LightIndex = -1;                  // in VTK's shader numbering
    vtkPenumbraAreaLight* Area = nullptr; // Light, if it is an area or linear light
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
    m->Light = l.first;
    m->LightIndex = l.second;
    m->Area = vtkPenumbraAreaLight::SafeDownCast(l.first);
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

// GEARS grid statistics of the last frame (Wang et al. 2014, Tables 5-6 analogues), and how
// many samples differ from the ray tracer at the same k.
std::string GearsStatistics(vtkPenumbraGearsShadows* gears, vtkPenumbraShadowPass* pass,
  const Measured& ctx, const TechniqueSpec& spec)
{
  std::ostringstream stats;
  stats << gears->GetNumberOfOccupiedCells() << " / " << gears->GetNumberOfCells()
        << " cells, triangles per cell max " << gears->GetMaxTrianglesPerCell() << " mean "
        << Fixed(gears->GetAverageTrianglesPerCell(), 1) << ", global "
        << gears->GetNumberOfGlobalTriangles() << ", assignments "
        << gears->GetNumberOfAssignments() << " of which blocking "
        << Fixed(100.0 * gears->GetBlockingShare(), 1) << " %, " << gears->GetNumberOfTracedRays()
        << " undecided light samples in " << gears->GetNumberOfSamplesWithTracedRays()
        << " view samples traced by the reference; grid " << Fixed(gears->GetGridTimeMs(), 1)
        << " ms, masks " << Fixed(gears->GetMaskTimeMs(), 1) << " ms, trace "
        << Fixed(gears->GetTraceTimeMs(), 1) << " ms";
  if (gears->GetLastPath() == vtkPenumbraGearsShadows::PATH_GPU)
  {
    stats << "; masks by the compute shader, " << gears->GetNumberOfFlaggedSamples()
          << " view samples redone on the CPU";
  }
  auto traced = ctx.TracedAtK.find(SamplesKey(spec.Setting));
  vtkFloatArray* mine = pass->GetVisibility(ctx.LightIndex);
  if (traced != ctx.TracedAtK.end() && mine &&
    mine->GetNumberOfTuples() == traced->second->GetNumberOfTuples())
  {
    vtkIdType differ = 0;
    for (vtkIdType i = 0; i < mine->GetNumberOfTuples(); ++i)
    {
      differ += mine->GetValue(i) != traced->second->GetValue(i);
    }
    stats << "; differs from raytraced " << SamplesKey(spec.Setting) << " in " << differ
          << " samples";
  }
  return stats.str();
}

// The pass's phases and technique statistics of the last frame into `row`; returns a copy of
// its visibility of light `m`, or nullptr for passes that expose none.
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
  if (vtkPenumbraShadowTechnique* technique = pass->GetLightTechnique(m.LightIndex))
  {
    // The share of the last light the technique handled in the last frame (the measured
    // light in single-light scenes).
    row.UncertainShare = technique->GetUncertainFraction();
    if (auto* volumes = vtkPenumbraShadowVolumeShadows::SafeDownCast(technique))
    {
      row.FillFragments = volumes->GetNumberOfFillFragments();
    }
    int size[2];
    double need[2];
    auto* maps = vtkPenumbraShadowMapShadows::SafeDownCast(technique);
    if (maps && maps->GetMapSize(pass->GetLight(m.LightIndex), size, need))
    {
      row.MapSize = std::to_string(size[0]) + "×" + std::to_string(size[1]);
      if (need[0] > 0.0 || need[1] > 0.0)
      {
        row.MapSize += " (need " + std::to_string(std::lround(need[0])) + "×" +
          std::to_string(std::lround(need[1])) + ")";
      }
    }
    if (auto* llsm = vtkPenumbraLinkedListShadows::SafeDownCast(technique))
    {
      std::cerr << "\n"
                << ctx.Label << " " << spec.Name << " " << spec.Setting << ": listed "
                << Fixed(100.0 * llsm->GetListedFraction(), 1) << " %, lists max "
                << llsm->GetMaxListLength() << " mean " << Fixed(llsm->GetMeanListLength(), 2)
                << ", " << llsm->GetNumberOfTests() << " tests, "
                << llsm->GetNumberOfTracedSamples() << " traced; classify "
                << Fixed(llsm->GetClassifyTimeMs(), 1) << " ms, lists "
                << Fixed(llsm->GetListTimeMs(), 1) << " ms, raster "
                << Fixed(llsm->GetRasterTimeMs(), 1) << " ms, trace "
                << Fixed(llsm->GetTraceTimeMs(), 1) << " ms\n";
    }
    if (auto* rmsm = vtkPenumbraResolutionMatchedShadows::SafeDownCast(technique))
    {
      std::cerr << "\n"
                << ctx.Label << " " << spec.Label()
                << " (last light of the last frame): " << rmsm->GetNumberOfRequestedPages()
                << " pages requested (levels " << rmsm->GetRequestedLevels()[0] << "-"
                << rmsm->GetRequestedLevels()[1] << "), " << rmsm->GetNumberOfRefinedPages()
                << " refined at edges, " << rmsm->GetNumberOfRenderedPages() << " rendered in "
                << rmsm->GetNumberOfSuperpages() << " superpages, "
                << rmsm->GetNumberOfResidentPages() << " resident, coarser share "
                << Fixed(rmsm->GetCoarserShare(), 4) << "; requests "
                << Fixed(rmsm->GetRequestTimeMs(), 1) << " ms, pages "
                << Fixed(rmsm->GetPageTimeMs(), 1) << " ms, lookup "
                << Fixed(rmsm->GetLookupTimeMs(), 1) << " ms\n";
    }
    auto* gears = vtkPenumbraGearsShadows::SafeDownCast(technique);
    if (gears && gears->GetLastLightWasArea() && m.Area)
    {
      row.GearsStats = GearsStatistics(gears, pass, m, spec);
      std::cerr << "\n"
                << ctx.Label << " gears " << spec.Setting << " light " << m.LightIndex << ": "
                << row.GearsStats << "\n";
    }
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
    estimate = RecoverVisibility(ctx.Renderer, ctx.Window, m.Light, ctx.Samples, measurable);
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
  vtkLight* moving = ctx.Lights.front()->Light;
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

// results.csv, results.md (also printed) and chart.png; returns the exit status.
int WriteResults(const Options& o, const BenchRun& run)
{
  WriteCSV(o.OutDir + "/results.csv", run.Rows);
  WriteMarkdown(o.OutDir + "/results.md", run.Rows, run.Failures, run.References, o);
  std::string chartError;
  if (!WriteChart(o.OutDir + "/chart.png", run.Rows, chartError))
  {
    std::cerr << "penumbra-bench: chart: " << chartError << "\n";
    return 3;
  }
  std::ifstream md(o.OutDir + "/results.md");
  std::cout << md.rdbuf();
  return run.Failures.empty() ? 0 : 3;
}
}

int main(int argc, char* argv[])
{
  penumbra_cli::InstallMessageWindow("penumbra-bench", true);
  Options options;
  int status = ParseArguments(argc, argv, options);
  status = status < 0 ? CheckOptions(options) : status;
  if (status >= 0)
  {
    return status;
  }
  if (!options.SweepTriangles.empty())
  {
    return RunSweep(options);
  }
  BenchRun run;
  run.Total = static_cast<int>(options.SceneNames.size() * (options.Techniques.size() + 1));
  for (const auto& sceneName : options.SceneNames)
  {
    status = MeasureScene(sceneName, options, run);
    if (status >= 0)
    {
      return status;
    }
  }
  Progress(run.Total, run.Total, "writing results");
  return WriteResults(options, run);
}
