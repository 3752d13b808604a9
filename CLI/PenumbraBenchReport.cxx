// penumbra-bench: the scene benchmark's results, results.csv, results.md and chart.png.

#include "PenumbraBenchScenes.h"
#include "PenumbraCLI.h"

#include "vtkAxis.h"
#include "vtkChartMatrix.h"
#include "vtkChartXY.h"
#include "vtkContextScene.h"
#include "vtkContextView.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkPlotPoints.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkTable.h"

#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

namespace
{
using namespace penumbra_bench;

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
  bool listed = false;
  for (const Row& r : rows)
  {
    if (r.Statistics.empty())
    {
      continue;
    }
    if (!listed)
    {
      out << "\nEach technique's statistics of the last frame (vtkPenumbraStatistics: counts, "
             "shares and phase times in ms; the figures other than map sizes describe the last "
             "light the technique handled). On area lights, differs_from_raytraced counts the "
             "view samples whose visibility differs from the ray tracer at the same number of "
             "light samples in the same run (GEARS: Wang et al. 2014, Tables 5-6 analogues).\n\n";
      listed = true;
    }
    out << "- " << r.Scene << " " << r.Technique << " " << r.Setting << " light " << r.Light << ": "
        << r.Statistics << "\n";
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
}

namespace penumbra_bench
{
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
