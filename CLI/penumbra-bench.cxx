// penumbra-bench: error against run time for every shadow technique, on the same scenes and
// view samples, next to its peers (no shadows, VTK's vtkShadowMapPass, the exact reference).
//
//   penumbra-bench [--scenes A,B,...] [--techniques T[:k=v;k=v],...] [--size WxH]
//                  [--frames N] [--warmup N] [--moving-light] [--still-frames] [--no-images]
//                  --out DIR
//
// Writes DIR/results.csv, DIR/results.md and DIR/chart.png (and, unless --no-images, each
// point's image and error image). Scenes are names of files in Data/Scenes or paths to scene
// files. A progress bar goes to stderr.
//
// Method, per scene:
//  - the view samples and the exact visibility of the scene's first shadowed light come from
//    the ray-traced reference on the very same camera and window size (for an area or linear
//    light: a converged 64 x 64-sample estimate; for hard lights: one exact ray per sample,
//    near-ties reported and excluded);
//  - each technique renders `warmup` frames, then `frames` timed frames (glFinish before the
//    clock stops); the median is reported, with the phases of vtkPenumbraShadowPass. Nothing
//    moves by default, so techniques that cache (shadow maps) are timed on reuse; with
//    --moving-light the measured light moves by a negligible amount before every frame
//    (1e-9 of its position's scale), which invalidates such caches, and is put back for one
//    untimed frame before the error is measured;
//  - techniques with a `samples` option (k x k soft shadows: gears, raytraced) only run on
//    scenes whose measured light is an area or linear light; GEARS points also print their
//    grid statistics and the samples that differ from raytraced at the same k;
//  - its visibility for that light is read from the pass, or, for passes that do not expose
//    one (VTK's vtkShadowMapPass), recovered as the ratio of a white, diffuse-only render
//    with shadows to the same render without, lit by that light alone.

#include "PenumbraCLI.h"

#include "vtkActor.h"
#include "vtkActorCollection.h"
#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkAxis.h"
#include "vtkCameraPass.h"
#include "vtkChartMatrix.h"
#include "vtkChartLegend.h"
#include "vtkChartXY.h"
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
#include "vtkPenumbraMetrics.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraShadowVolumeShadows.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
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
#include <limits>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#ifndef PENUMBRA_SCENES_DIR
#define PENUMBRA_SCENES_DIR "Data/Scenes"
#endif

namespace
{
using penumbra_cli::Clock;
using penumbra_cli::MsSince;

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

struct TechniqueSpec
{
  std::string Name;
  std::string Setting; // "resolution=2048" or "default"
  nlohmann::json Options = nlohmann::json::object();
};

struct Row
{
  std::string Scene, Technique, Setting, ErrorKind;
  int Width = 0, Height = 0;
  double MedianMs = 0, MinMs = 0;
  double ExtractionMs = -1, SamplesMs = -1, TechniqueMs = -1, ShadingMs = -1;
  double MismatchRate = 0, MAE = 0, RMSE = 0, MaxError = 0, P95 = 0;
  // Hybrid techniques: share of samples handed to the exact fallback; -1 = not applicable.
  double UncertainShare = -1;
  // Shadow volumes with measure_fill: rasterized volume fragments per frame; -1 = not measured.
  long long FillFragments = -1;
  vtkIdType FalseLit = 0, FalseShadow = 0, Candidates = 0, Ties = 0;
  double RatioToNoShadow = 0;
  // --still-frames: median frame when nothing changes (the pass reuses its visibility).
  double StillMs = -1, StillRatio = -1;
  // GEARS (seed 002 Tables 5-6 analogues): per-cell loads and the share of assigned
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
               " [--size WxH] [--frames N] [--warmup N] [--moving-light] [--still-frames] [--no-images]"
               " --out DIR\n";
  return 2;
}

std::vector<std::string> Split(const std::string& s, char sep)
{
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep))
  {
    if (!item.empty())
    {
      out.push_back(item);
    }
  }
  return out;
}

bool ParseTechnique(const std::string& text, TechniqueSpec& spec, std::string& error)
{
  const size_t colon = text.find(':');
  spec.Name = text.substr(0, colon);
  spec.Setting = "default";
  if (!vtkPenumbraTechniques::HasTechnique(spec.Name.c_str()))
  {
    error = "unknown technique \"" + spec.Name + "\" (see penumbra-render --list-techniques)";
    return false;
  }
  if (colon != std::string::npos)
  {
    spec.Setting = text.substr(colon + 1);
    for (const auto& kv : Split(spec.Setting, ';'))
    {
      const size_t eq = kv.find('=');
      if (eq == std::string::npos || eq == 0)
      {
        error = "technique setting \"" + kv + "\" is not KEY=VALUE";
        return false;
      }
      const std::string v = kv.substr(eq + 1);
      nlohmann::json parsed = nlohmann::json::parse(v, nullptr, false);
      spec.Options[kv.substr(0, eq)] = parsed.is_discarded() ? nlohmann::json(v) : parsed;
    }
  }
  return true;
}

std::string ResolveScene(const std::string& name)
{
  if (vtksys::SystemTools::FileExists(name, true))
  {
    return name;
  }
  return std::string(PENUMBRA_SCENES_DIR) + "/" + name + ".json";
}

void Progress(int done, int total, const std::string& what)
{
  const int width = 30;
  const int filled = total > 0 ? width * done / total : width;
  std::cerr << "\r[" << std::string(static_cast<size_t>(filled), '#')
            << std::string(static_cast<size_t>(width - filled), '.') << "] " << done << "/"
            << total << " " << std::left << std::setw(48) << what.substr(0, 48) << std::flush;
  if (done == total)
  {
    std::cerr << "\n";
  }
}

// The first light that is on and actually emits: the one whose shadows are measured.
int MeasuredLight(vtkRenderer* ren, vtkLight** light)
{
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
    if (l->GetIntensity() > 0.0)
    {
      *light = l;
      return shaderIndex;
    }
    ++shaderIndex;
  }
  return -1;
}

vtkPenumbraShadowPass* ShadowPassOf(vtkRenderer* ren)
{
  auto* camera = vtkCameraPass::SafeDownCast(ren->GetPass());
  return camera ? vtkPenumbraShadowPass::SafeDownCast(camera->GetDelegatePass()) : nullptr;
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
  win->Render(); // the first frame after the switch computes; the rest reuse it
  win->WaitForCompletion();
  std::vector<double> times;
  for (int f = 0; f < frames; ++f)
  {
    const auto t0 = Clock::now();
    win->Render();
    win->WaitForCompletion();
    times.push_back(MsSince(t0));
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
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
    vis->SetValue(i, ok ? std::min(1.0f, a->GetValue(i) / lit) : (samples->IsValid(i) ? 0.0f : -1.0f));
  }
  return vis;
}

std::string Fixed(double v, int digits)
{
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
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
  out << "scene,technique,setting,width,height,median_ms,min_ms,extraction_ms,samples_ms,"
         "technique_ms,shading_ms,ratio_to_no_shadow,error_kind,mismatch_rate,false_lit,"
         "false_shadow,candidates,ties,mae,rmse,max_error,p95_error,uncertain_share,fill_fragments,"
         "still_ms,still_ratio_to_no_shadow\n";
  for (const Row& r : rows)
  {
    out << r.Scene << "," << r.Technique << ",\"" << r.Setting << "\"," << r.Width << ","
        << r.Height << "," << r.MedianMs << "," << r.MinMs << "," << r.ExtractionMs << ","
        << r.SamplesMs << "," << r.TechniqueMs << "," << r.ShadingMs << "," << r.RatioToNoShadow
        << "," << r.ErrorKind << "," << r.MismatchRate << "," << r.FalseLit << ","
        << r.FalseShadow << "," << r.Candidates << "," << r.Ties << "," << r.MAE << "," << r.RMSE
        << "," << r.MaxError << "," << r.P95 << ","
        << (r.UncertainShare < 0 ? std::string() : std::to_string(r.UncertainShare)) << ","
        << (r.FillFragments < 0 ? std::string() : std::to_string(r.FillFragments)) << ","
        << (r.StillMs < 0 ? std::string() : std::to_string(r.StillMs)) << ","
        << (r.StillRatio < 0 ? std::string() : std::to_string(r.StillRatio)) << "\n";
  }
}

void WriteMarkdown(const std::string& path, const std::vector<Row>& rows,
  const std::vector<std::string>& failures, int frames, int warmup, bool movingLight)
{
  std::ofstream out(path);
  out << "# Shadow techniques: error against run time\n\n"
      << "Median of " << frames << " frames after " << warmup
      << " warm-up frame(s), glFinish before each clock reading, "
      << (movingLight ? "the light moving before every frame (no cached shadow maps). "
                      : "nothing moving (cached shadow maps are reused). ")
      << "Error is measured on the "
         "scene's first light against the exact reference on the same view samples: mismatch "
         "rate over lit-candidate samples for hard lights (near-ties excluded), mean absolute "
         "error of visibility for area/linear lights.\n\n"
      << "| scene | technique | setting | size | median ms | × no-shadow | extract | samples | "
         "technique | shading | mismatch | false lit | false shadow | ties | MAE | p95 | uncertain | "
         "fill | still ms (×) |\n"
      << "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  auto phase = [](double v) { return v < 0 ? std::string("–") : Fixed(v, 1); };
  for (const Row& r : rows)
  {
    out << "| " << r.Scene << " | " << r.Technique << " | " << r.Setting << " | " << r.Width
        << "×" << r.Height << " | " << Fixed(r.MedianMs, 1) << " | "
        << Fixed(r.RatioToNoShadow, 2) << " | " << phase(r.ExtractionMs) << " | "
        << phase(r.SamplesMs) << " | " << phase(r.TechniqueMs) << " | " << phase(r.ShadingMs)
        << " | " << Sci(r.MismatchRate) << " | " << r.FalseLit << " | " << r.FalseShadow << " | "
        << r.Ties << " | " << Fixed(r.MAE, 4) << " | " << Fixed(r.P95, 3) << " | "
        << (r.UncertainShare < 0 ? std::string("–") : Fixed(100.0 * r.UncertainShare, 2) + " %")
        << " | " << (r.FillFragments < 0 ? std::string("–") : std::to_string(r.FillFragments))
        << " | "
        << (r.StillMs < 0 ? std::string("–")
                          : Fixed(r.StillMs, 1) + " (" + Fixed(r.StillRatio, 2) + ")")
        << " |\n";
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
      out << "\nGEARS statistics of the last frame and the last light it handled (seed 002 "
             "Tables 5-6): busy cells / cells, triangles per busy cell (max, mean), global-list "
             "triangles, assignments and the share that block at least one light sample, light "
             "samples the reference traced, phase times, and the number of view samples whose "
             "visibility differs from the ray tracer at the same k in the same run.\n\n";
      gears = true;
    }
    out << "- " << r.Scene << " " << r.Setting << ": " << r.GearsStats << "\n";
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
  const double palette[][3] = { { 0.1, 0.1, 0.1 }, { 0.85, 0.33, 0.1 }, { 0.0, 0.45, 0.74 },
    { 0.47, 0.67, 0.19 }, { 0.49, 0.18, 0.56 }, { 0.93, 0.69, 0.13 }, { 0.3, 0.75, 0.93 } };
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
      const std::string label = r.Technique + (r.Setting == "default" ? "" : " " + r.Setting);
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
      const double* rgb = palette[colours[technique] % (sizeof(palette) / sizeof(palette[0]))];
      plot->SetColor(rgb[0], rgb[1], rgb[2]);
      plot->SetMarkerStyle(markerStyles[marker % 5]);
      plot->SetMarkerSize(marker % 5 >= 3 ? 14.0f : 10.0f);
      plot->SetWidth(3.0);
    }
  }
  penumbra_cli::ErrorLog log;
  log.Watch(view->GetRenderWindow());
  view->GetRenderWindow()->Render();
  vtkSmartPointer<vtkImageData> image = penumbra_cli::GrabRGB(view->GetRenderWindow());
  vtkNew<vtkPenumbraImageIO> io;
  if (log.Raised() || !io->Write(image, path.c_str()))
  {
    error = log.Raised() ? log.FirstError() : io->GetErrorMessage();
    return false;
  }
  return true;
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
}

int main(int argc, char* argv[])
{
  std::vector<std::string> sceneNames = { "default", "isosurface", "city_area_light" };
  std::vector<std::string> techniqueTexts = { "none", "vtk-shadowmap:resolution=1024",
    "vtk-shadowmap:resolution=2048", "vtk-shadowmap:resolution=4096", "raytraced",
    "conservative:resolution=1024", "conservative:resolution=2048",
    "shadowmap:resolution=1024", "shadowmap:resolution=4096",
    "shadowmap:resolution=2048;filter=pcf", "volumes", "volumes:silhouettes=gpu",
    "volumes:measure_fill=true", "raytraced:samples=4", "gears:samples=4",
    "raytraced:samples=8", "gears:samples=8", "raytraced:samples=16", "gears:samples=16" };
  std::string outDir;
  int width = 640, height = 480, frames = 5, warmup = 1;
  bool images = true;
  bool movingLight = false;
  bool stillFrames = false;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
      {
        std::exit(Usage((a + " needs a value").c_str()));
      }
      return argv[++i];
    };
    if (a == "--scenes")
    {
      sceneNames = Split(value(), ',');
    }
    else if (a == "--techniques")
    {
      techniqueTexts = Split(value(), ',');
    }
    else if (a == "--size")
    {
      if (!penumbra_cli::ParseSize(value(), width, height))
      {
        return Usage("--size expects WxH, e.g. 640x480");
      }
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
      (a == "--frames" ? frames : warmup) = static_cast<int>(n);
    }
    else if (a == "--out")
    {
      outDir = value();
    }
    else if (a == "--still-frames")
    {
      stillFrames = true;
    }
    else if (a == "--moving-light")
    {
      movingLight = true;
    }
    else if (a == "--no-images")
    {
      images = false;
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
  if (outDir.empty())
  {
    return Usage("--out DIR is required");
  }
  if (sceneNames.empty() || techniqueTexts.empty())
  {
    return Usage("nothing to measure");
  }
  std::vector<TechniqueSpec> techniques;
  for (const auto& t : techniqueTexts)
  {
    TechniqueSpec spec;
    std::string error;
    if (!ParseTechnique(t, spec, error))
    {
      return Usage(error.c_str());
    }
    techniques.push_back(spec);
  }
  // Bad names and options are refused before anything is measured, not after the scenes
  // before them have run.
  for (const auto& sceneName : sceneNames)
  {
    if (!vtksys::SystemTools::FileExists(ResolveScene(sceneName), true))
    {
      return Usage(("no scene file " + ResolveScene(sceneName)).c_str());
    }
  }
  {
    vtkNew<vtkPenumbraTechniques> registry;
    for (const auto& spec : techniques)
    {
      vtkNew<vtkRenderer> probe;
      if (!registry->Apply(probe, spec.Name.c_str(), spec.Options.dump().c_str()))
      {
        return Usage((spec.Name + " " + spec.Setting + ": " + registry->GetErrorMessage()).c_str());
      }
    }
  }
  // Every point needs the no-shadow time for its ratio: measure it even if not asked for.
  if (std::none_of(techniques.begin(), techniques.end(),
        [](const TechniqueSpec& t) { return t.Name == "none"; }))
  {
    techniques.insert(techniques.begin(), TechniqueSpec{ "none", "default", nlohmann::json::object() });
  }
  if (!vtksys::SystemTools::MakeDirectory(outDir))
  {
    std::cerr << "penumbra-bench: cannot create " << outDir << "\n";
    return 2;
  }

  std::vector<Row> rows;
  // A technique that refuses a scene (e.g. an area light for a hard-shadow technique) or
  // fails is reported and skipped; the other points are still measured and written, and the
  // exit status says that something was missing.
  std::vector<std::string> failures;
  auto fail = [&](const std::string& what, const std::string& why) {
    std::cerr << "\npenumbra-bench: " << what << ": " << why << "\n";
    std::string line = what + ": " + why;
    std::replace(line.begin(), line.end(), '\n', ' ');
    failures.push_back(line);
  };
  const int total = static_cast<int>(sceneNames.size() * (techniques.size() + 1));
  int done = 0;
  for (const auto& sceneName : sceneNames)
  {
    const std::string path = ResolveScene(sceneName);
    const std::string label = vtksys::SystemTools::GetFilenameWithoutLastExtension(path);
    Progress(done, total, label + ": loading");
    vtkNew<vtkPenumbraSceneReader> reader;
    reader->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
    reader->SetFileName(path.c_str());
    if (!reader->Read())
    {
      fail(label, reader->GetErrorMessage());
      done += static_cast<int>(techniques.size()) + 1;
      continue;
    }
    vtkRenderer* ren = reader->GetRenderer();
    penumbra_cli::ErrorLog errors;
    std::string windowError;
    vtkSmartPointer<vtkRenderWindow> win =
      penumbra_cli::MakeWindow(width, height, ren, errors, windowError);
    if (!win)
    {
      std::cerr << "\npenumbra-bench: " << windowError << "\n";
      return 3;
    }

    // Reference: view samples and exact visibility of the measured light.
    Progress(done, total, label + ": reference");
    vtkNew<vtkPenumbraTechniques> registry;
    registry->Apply(ren, "raytraced", "{}");
    win->Render();
    vtkPenumbraShadowPass* refPass = ShadowPassOf(ren);
    vtkLight* light = nullptr;
    const int lightIndex = MeasuredLight(ren, &light);
    if (!refPass || lightIndex < 0 || errors.Raised())
    {
      fail(label, errors.Raised() ? errors.FirstError() : "no light to measure");
      errors.Clear();
      done += static_cast<int>(techniques.size()) + 1;
      registry->Apply(ren, "none", "");
      win->Finalize();
      continue;
    }
    vtkNew<vtkPenumbraViewSamples> samples;
    samples->DeepCopy(refPass->GetViewSamples());
    auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
    const std::string errorKind = area ? "soft" : "hard";
    vtkNew<vtkFloatArray> reference;
    vtkNew<vtkUnsignedCharArray> ties;
    if (area)
    {
      vtkNew<vtkPenumbraReference> converged;
      converged->SetGeometry(refPass->GetGeometry());
      converged->ComputeConvergedVisibility(samples, area, 64, reference);
    }
    else
    {
      reference->DeepCopy(refPass->GetVisibility(lightIndex));
      auto* tracer = vtkPenumbraRayTracedShadows::SafeDownCast(refPass->GetTechnique());
      ties->DeepCopy(tracer->GetReference()->GetTies());
    }
    ++done;

    double noShadowMs = 0.0;
    // The ray tracer's visibility per setting ("samples=16"), so a GEARS point at the same k
    // can be checked for exactness on the full-size frame.
    std::map<std::string, vtkSmartPointer<vtkFloatArray>> tracedAtK;
    for (const auto& spec : techniques)
    {
      const std::string what = label + ": " + spec.Name + " " + spec.Setting;
      if (!area && spec.Options.contains("samples"))
      {
        ++done; // a light-sample count means nothing for a hard light
        continue;
      }
      Progress(done, total, what);
      if (!registry->Apply(ren, spec.Name.c_str(), spec.Options.dump().c_str()))
      {
        fail(what, registry->GetErrorMessage()); // options were checked before the run
        ++done;
        continue;
      }
      if (area)
      {
        vtkPenumbraShadowPass* applied = ShadowPassOf(ren);
        if (applied && applied->GetTechnique() && !applied->GetTechnique()->HandlesAreaLights())
        {
          ++done; // a hard-shadow technique has nothing to say about an area light
          continue;
        }
      }
      // --moving-light: a new light position for every frame, restored afterwards.
      double home[3];
      light->GetPosition(home);
      const double scale = 1e-9 * (1.0 + std::fabs(home[0]) + std::fabs(home[1]) + std::fabs(home[2]));
      // Timed frames redo the shadow work (the pass would otherwise reuse a still frame's
      // visibility); --still-frames times that reuse separately.
      if (vtkPenumbraShadowPass* timed = ShadowPassOf(ren))
      {
        timed->ReuseUnchangedFramesOff();
      }
      auto frame = [&](int f) {
        if (movingLight)
        {
          light->SetPosition(home[0] + (f + 1) * scale, home[1], home[2]);
        }
        win->Render();
        win->WaitForCompletion();
      };
      for (int f = 0; f < warmup; ++f)
      {
        frame(f);
      }
      std::vector<double> times;
      for (int f = 0; f < frames; ++f)
      {
        const auto t0 = Clock::now();
        frame(warmup + f);
        times.push_back(MsSince(t0));
      }
      if (movingLight)
      {
        light->SetPosition(home);
        win->Render();
        win->WaitForCompletion();
      }
      if (errors.Raised())
      {
        fail(what, "rendering failed: " + errors.FirstError());
        errors.Clear();
        ++done;
        continue;
      }
      std::sort(times.begin(), times.end());
      Row row;
      row.Scene = label;
      row.Technique = spec.Name;
      row.Setting = spec.Setting;
      row.Width = width;
      row.Height = height;
      row.MedianMs = times[times.size() / 2];
      row.MinMs = times.front();
      row.ErrorKind = errorKind;
      if (spec.Name == "none")
      {
        noShadowMs = row.MedianMs;
      }

      vtkSmartPointer<vtkFloatArray> estimate;
      vtkSmartPointer<vtkUnsignedCharArray> measurable; // null: every valid sample counts
      vtkPenumbraShadowPass* pass = ShadowPassOf(ren);
      if (pass)
      {
        row.ExtractionMs = pass->GetExtractionTimeMs();
        row.SamplesMs = pass->GetSamplesTimeMs();
        row.TechniqueMs = pass->GetTechniqueTimeMs();
        row.ShadingMs = pass->GetShadingTimeMs();
        if (vtkPenumbraShadowTechnique* technique = pass->GetTechnique())
        {
          // The share of the last light the technique handled in the last frame (the
          // measured light in single-light scenes).
          row.UncertainShare = technique->GetUncertainFraction();
          if (auto* volumes = vtkPenumbraShadowVolumeShadows::SafeDownCast(technique))
          {
            row.FillFragments = volumes->GetNumberOfFillFragments();
          }
          auto* gearsTechnique = vtkPenumbraGearsShadows::SafeDownCast(technique);
          if (gearsTechnique && gearsTechnique->GetLastLightWasArea())
          {
            std::ostringstream stats;
            stats << gearsTechnique->GetNumberOfOccupiedCells() << " / "
                  << gearsTechnique->GetNumberOfCells() << " cells, triangles per cell max "
                  << gearsTechnique->GetMaxTrianglesPerCell() << " mean "
                  << Fixed(gearsTechnique->GetAverageTrianglesPerCell(), 1) << ", global "
                  << gearsTechnique->GetNumberOfGlobalTriangles() << ", assignments "
                  << gearsTechnique->GetNumberOfAssignments() << " of which blocking "
                  << Fixed(100.0 * gearsTechnique->GetBlockingShare(), 1) << " %, "
                  << gearsTechnique->GetNumberOfTracedRays() << " undecided light samples in "
                  << gearsTechnique->GetNumberOfSamplesWithTracedRays()
                  << " view samples traced by the reference; grid "
                  << Fixed(gearsTechnique->GetGridTimeMs(), 1) << " ms, masks "
                  << Fixed(gearsTechnique->GetMaskTimeMs(), 1) << " ms, trace "
                  << Fixed(gearsTechnique->GetTraceTimeMs(), 1) << " ms";
            if (gearsTechnique->GetLastPath() == vtkPenumbraGearsShadows::PATH_GPU)
            {
              stats << "; masks by the compute shader, "
                    << gearsTechnique->GetNumberOfFlaggedSamples()
                    << " view samples redone on the CPU";
            }
            auto traced = tracedAtK.find(SamplesKey(spec.Setting));
            vtkFloatArray* mine = pass->GetVisibility(lightIndex);
            if (traced != tracedAtK.end() && mine &&
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
            row.GearsStats = stats.str();
            std::cerr << "\n" << label << " gears " << spec.Setting << ": " << row.GearsStats
                      << "\n";
          }
        }
        estimate = vtkSmartPointer<vtkFloatArray>::New();
        if (vtkFloatArray* v = pass->GetVisibility(lightIndex))
        {
          estimate->DeepCopy(v);
        }
        if (spec.Name == "raytraced")
        {
          tracedAtK[SamplesKey(spec.Setting)] = estimate;
        }
      }
      if (stillFrames)
      {
        row.StillMs = TimeStillFrames(ren, win, frames); // after the phases were read
      }
      if (!estimate || estimate->GetNumberOfTuples() != samples->GetNumberOfSamples())
      {
        measurable = vtkSmartPointer<vtkUnsignedCharArray>::New();
        estimate = RecoverVisibility(ren, win, light, samples, measurable);
      }
      vtkNew<vtkPenumbraMetrics> metrics;
      if (!area)
      {
        metrics->CompareHard(estimate, reference, ties, measurable);
        row.MismatchRate = metrics->GetMismatchRate();
        row.FalseLit = metrics->GetFalseLit();
        row.FalseShadow = metrics->GetFalseShadow();
        row.Candidates = metrics->GetCandidates();
        row.Ties = metrics->GetTies();
        if (images)
        {
          metrics->WriteErrorImage(width, height,
            (outDir + "/" + FileSafe(label + "__" + spec.Name + "_" + spec.Setting) + "_error.png").c_str());
        }
      }
      metrics->CompareSoft(estimate, reference, measurable, area ? nullptr : ties.Get());
      row.MAE = metrics->GetMAE();
      row.RMSE = metrics->GetRMSE();
      row.MaxError = metrics->GetMaxError();
      row.P95 = metrics->GetP95Error();
      if (area && images)
      {
        metrics->WriteErrorImage(width, height,
          (outDir + "/" + FileSafe(label + "__" + spec.Name + "_" + spec.Setting) + "_error.png").c_str());
      }
      if (images)
      {
        win->Render();
        vtkNew<vtkPenumbraImageIO> io;
        io->Write(penumbra_cli::GrabRGB(win),
          (outDir + "/" + FileSafe(label + "__" + spec.Name + "_" + spec.Setting) + ".png").c_str());
      }
      rows.push_back(row);
      ++done;
    }
    for (Row& r : rows)
    {
      if (r.Scene == label)
      {
        r.RatioToNoShadow = noShadowMs > 0 ? r.MedianMs / noShadowMs : 0.0;
        r.StillRatio = r.StillMs >= 0 && noShadowMs > 0 ? r.StillMs / noShadowMs : -1.0;
      }
    }
    registry->Apply(ren, "none", "");
    win->Finalize();
  }
  Progress(total, total, "writing results");

  WriteCSV(outDir + "/results.csv", rows);
  WriteMarkdown(outDir + "/results.md", rows, failures, frames, warmup, movingLight);
  std::string chartError;
  if (!WriteChart(outDir + "/chart.png", rows, chartError))
  {
    std::cerr << "penumbra-bench: chart: " << chartError << "\n";
    return 3;
  }
  std::ifstream md(outDir + "/results.md");
  std::cout << md.rdbuf();
  return failures.empty() ? 0 : 3;
}
