// penumbra-bench --scale-sweep: how each technique's frame time grows with the caster's
// triangle count, next to the unshadowed frame's.
//
// The scene is generated, not read: a UV sphere (the caster, N triangles) 1.5 m above a 10 m
// ground plane (2 triangles), lit by one directional light whose shadow lies in view. The
// sphere is built once per N and shared by every technique; its window is closed before the
// next N is built, so only one tessellation is alive at a time.
//
// Per N and technique two rows: the camera still (techniques may reuse the last frame's
// visibility) and the camera turning 0.5 degrees about the scene centre before every frame
// (nothing view-dependent can be reused); with --moving-light a third, the camera still and
// the sun turning 0.5 degrees about the vertical before every frame (nothing that depends on
// the light can be reused: maps, fits, volumes). Per row: median frame time, the shadow pass's
// technique and view-sample phases, and the process's peak resident memory during the row.
// Per technique and camera, the cost exponent: the least-squares slope of log(frame ms)
// against log(triangles). Writes sweep.csv, sweep.md (also printed), sweep.png, and
// sweep_scene.png (the first shadowed frame, to check what was measured).

#include "PenumbraBench.h"
#include "PenumbraCLI.h"

#include "vtkActor.h"
#include "vtkAxis.h"
#include "vtkCamera.h"
#include "vtkChartLegend.h"
#include "vtkChartXY.h"
#include "vtkContextScene.h"
#include "vtkContextView.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPen.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraImageIO.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPlaneSource.h"
#include "vtkPlotPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"
#include "vtkTable.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#ifdef __GLIBC__
#include <malloc.h> // malloc_trim
#endif
#include <set>
#include <sstream>

namespace penumbra_bench
{
namespace
{
struct SweepRow
{
  vtkIdType Triangles = 0; // the caster's; the ground adds 2
  TechniqueSpec Technique;
  enum Motion
  {
    Still,
    CameraTurns,
    LightTurns
  } Moves = Still;
  double MedianMs = -1, MinMs = -1;
  // The still row's first frame after the technique is installed: scene extraction,
  // acceleration structures, shader compilation. Not a warm-up frame: the budget check
  // after the warm-up must see a frame like the timed ones.
  double FirstFrameMs = -1;
  double TechniqueMs = -1, SamplesMs = -1; // medians over the timed frames; -1: no Penumbra pass
  double RssBeforeMB = -1, PeakRssMB = -1; // -1: not available on this system
  // (PeakRssMB - none's PeakRssMB at the same count and camera) per caster triangle, in
  // bytes: what the shadows cost in memory on top of plain VTK. NaN: not available.
  double BytesPerTriangleOverNone = NAN;
  std::string NotMeasured; // why; empty when measured
  bool OverBudget = false;
  double RatioToNone = -1, Exponent = NAN, ExponentMinusNone = NAN;
  // The slope between the series' two largest counts: the growth where fixed per-pixel
  // costs no longer hide it.
  double ExponentLastTwo = NAN;

  // What moves between frames, as the tables and the CSV's `camera` column name it.
  std::string Camera() const
  {
    return this->Moves == Still ? "still"
                                : (this->Moves == CameraTurns ? "moving" : "light moving");
  }
  std::string Series() const { return this->Technique.Label() + " " + this->Camera(); }
};

// Linux's peak resident set of this process (VmHWM) can be reset to the current resident set
// by writing "5" to /proc/self/clear_refs; reading it after a row gives that row's peak.
// Freed heap memory is handed back to the system first, so the resident set left over from
// earlier rows is memory still in use, not the allocator's reserve.
bool ResetPeakMemory()
{
#ifdef __GLIBC__
  malloc_trim(0);
#endif
  std::ofstream out("/proc/self/clear_refs");
  out << "5";
  out.flush();
  return static_cast<bool>(out);
}

// A "VmHWM:   123456 kB" line of /proc/self/status in MB, or -1.
double StatusMB(const std::string& key)
{
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
  {
    if (line.rfind(key + ":", 0) == 0)
    {
      return std::strtod(line.c_str() + key.size() + 1, nullptr) / 1024.0;
    }
  }
  return -1.0;
}

double Median(std::vector<double> v)
{
  if (v.empty())
  {
    return -1.0;
  }
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// vtkSphereSource makes 2 T (P - 2) triangles from T meridians and P parallels (poles
// included); P - 2 = sqrt(N / 4) and T = 2 (P - 2) give about N triangles in near-square
// facets, so the silhouette gets finer with N like a real tessellated surface's.
vtkSmartPointer<vtkPolyData> MakeCaster(vtkIdType triangles)
{
  const int bands = std::max(1, static_cast<int>(std::lround(std::sqrt(triangles / 4.0))));
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(2 * bands);
  sphere->SetPhiResolution(bands + 2);
  sphere->SetRadius(1.0);
  sphere->SetCenter(0.0, 0.0, 1.5);
  sphere->Update();
  return sphere->GetOutput();
}

void AddActor(vtkRenderer* ren, vtkPolyData* mesh, double r, double g, double b)
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(mesh);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  actor->GetProperty()->SetAmbient(0.25); // the shadow stays readable, not black
  actor->GetProperty()->SetDiffuse(0.8);
  ren->AddActor(actor);
}

// The caster over the ground, one directional light (the sun at 50 degrees elevation from
// the south-east, so the shadow falls north-west of the sphere, toward the camera's left),
// and a camera from the south-west looking at the scene centre, which frames both.
void SetUpSweepScene(vtkRenderer* ren, vtkPolyData* caster)
{
  vtkNew<vtkPlaneSource> ground;
  ground->SetOrigin(-5.0, -5.0, 0.0);
  ground->SetPoint1(5.0, -5.0, 0.0);
  ground->SetPoint2(-5.0, 5.0, 0.0);
  ground->Update();
  AddActor(ren, ground->GetOutput(), 0.86, 0.84, 0.80);
  AddActor(ren, caster, 0.85, 0.33, 0.1);
  ren->SetBackground(0.55, 0.68, 0.85);

  const double elevation = vtkMath::RadiansFromDegrees(50.0);
  const double azimuth = vtkMath::RadiansFromDegrees(135.0);
  vtkNew<vtkLight> sun;
  sun->SetLightTypeToSceneLight();
  sun->SetPositional(false);
  sun->SetFocalPoint(0.0, 0.0, 0.0);
  sun->SetPosition(std::cos(elevation) * std::sin(azimuth), std::cos(elevation) * std::cos(azimuth),
    std::sin(elevation));
  ren->AddLight(sun);

  vtkCamera* camera = ren->GetActiveCamera();
  camera->SetFocalPoint(-0.4, 0.4, 0.75); // between the sphere and its shadow
  camera->SetPosition(-0.4 - 3.2, 0.4 - 4.8, 0.75 + 3.9);
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->SetViewAngle(30.0);
  ren->ResetCameraClippingRange();
}

// What the rows of one N share.
struct SweepScene
{
  vtkRenderer* Renderer = nullptr;
  vtkRenderWindow* Window = nullptr;
  penumbra_cli::ErrorLog* Errors = nullptr;
};

// One row: the applied technique with the camera still or turning, or the sun turning; fills
// the row's times, phases and memory, or says why it is not measured.
void MeasureSweepRow(const SweepScene& scene, const Options& o, SweepRow& row)
{
  vtkCamera* camera = scene.Renderer->GetActiveCamera();
  double position[3], focal[3], up[3];
  camera->GetPosition(position);
  camera->GetFocalPoint(focal);
  camera->GetViewUp(up);
  vtkLight* sun = vtkLight::SafeDownCast(scene.Renderer->GetLights()->GetItemAsObject(0));
  double sunPosition[3];
  sun->GetPosition(sunPosition);
  vtkPenumbraShadowPass* pass = ShadowPassOf(scene.Renderer);
  if (pass)
  {
    pass->ReuseUnchangedFramesOff(); // time the shadow work, not the reuse of a still frame
  }
  std::vector<double> techniqueMs, samplesMs;
  const bool peak = ResetPeakMemory();
  row.RssBeforeMB = peak ? StatusMB("VmRSS") : -1.0;
  if (row.Moves == SweepRow::Still)
  {
    const auto t0 = penumbra::Clock::now();
    scene.Window->Render();
    scene.Window->WaitForCompletion();
    row.FirstFrameMs = penumbra::ElapsedMs(t0);
    if (row.FirstFrameMs > 1000.0 * o.BudgetSeconds)
    {
      row.PeakRssMB = peak ? StatusMB("VmHWM") : -1.0;
      row.NotMeasured = "over budget: the first frame took " + Fixed(row.FirstFrameMs / 1000.0, 1) +
        " s, more than the whole budget";
      row.OverBudget = true;
      return;
    }
  }
  const FrameTimes times = TimeFrames(
    scene.Window, o.Warmup, o.Frames, 1000.0 * o.BudgetSeconds,
    [&](int)
    {
      if (row.Moves == SweepRow::CameraTurns)
      {
        camera->Azimuth(0.5); // about the view-up axis through the focal point
        scene.Renderer->ResetCameraClippingRange();
      }
      else if (row.Moves == SweepRow::LightTurns)
      {
        double p[3];
        sun->GetPosition(p);
        const double a = vtkMath::RadiansFromDegrees(0.5);
        sun->SetPosition(p[0] * std::cos(a) - p[1] * std::sin(a),
          p[0] * std::sin(a) + p[1] * std::cos(a), p[2]); // about the vertical
      }
    },
    [&]()
    {
      if (pass)
      {
        techniqueMs.push_back(pass->GetTechniqueTimeMs());
        samplesMs.push_back(pass->GetSamplesTimeMs());
      }
    });
  row.PeakRssMB = peak ? StatusMB("VmHWM") : -1.0;
  camera->SetPosition(position);
  camera->SetFocalPoint(focal);
  camera->SetViewUp(up);
  sun->SetPosition(sunPosition);
  scene.Renderer->ResetCameraClippingRange();
  if (scene.Errors->Raised())
  {
    row.NotMeasured = "rendering failed: " + scene.Errors->FirstError();
    scene.Errors->Clear();
    return;
  }
  if (!times.OverBudget.empty())
  {
    row.NotMeasured = "over budget: " + times.OverBudget;
    row.OverBudget = true;
    return;
  }
  row.MedianMs = times.Median();
  row.MinMs = times.Ms.front();
  row.TechniqueMs = Median(techniqueMs);
  row.SamplesMs = Median(samplesMs);
}

// Least-squares slope of log(median ms) against log(triangles) over a series' measured rows
// (with `lastTwo`, only its two largest counts); NaN with fewer than two counts.
double Exponent(const std::vector<SweepRow>& rows, const std::string& series, bool lastTwo = false)
{
  std::vector<const SweepRow*> points;
  for (const SweepRow& r : rows)
  {
    if (r.Series() == series && r.NotMeasured.empty())
    {
      points.push_back(&r);
    }
  }
  if (lastTwo && points.size() > 2)
  {
    std::sort(points.begin(), points.end(),
      [](const SweepRow* a, const SweepRow* b) { return a->Triangles > b->Triangles; });
    points.resize(2);
  }
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const SweepRow* r : points)
  {
    const double x = std::log(static_cast<double>(r->Triangles)), y = std::log(r->MedianMs);
    n += 1;
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double d = n * sxx - sx * sx;
  return n >= 2 && d > 0 ? (n * sxy - sx * sy) / d : NAN;
}

// Ratios to `none` at the same count and camera, and each series' exponent with its
// difference to none's.
void Summarize(std::vector<SweepRow>& rows)
{
  for (SweepRow& r : rows)
  {
    const SweepRow* none = nullptr;
    for (const SweepRow& s : rows)
    {
      none = s.Technique.Name == "none" && s.Triangles == r.Triangles && s.Moves == r.Moves &&
          s.NotMeasured.empty()
        ? &s
        : none;
    }
    if (none && r.NotMeasured.empty())
    {
      r.RatioToNone = r.MedianMs / none->MedianMs;
    }
    if (none && &r != none && r.PeakRssMB >= 0 && none->PeakRssMB >= 0 && r.Triangles > 0)
    {
      r.BytesPerTriangleOverNone =
        (r.PeakRssMB - none->PeakRssMB) * 1024.0 * 1024.0 / static_cast<double>(r.Triangles);
    }
    r.Exponent = Exponent(rows, r.Series());
    r.ExponentLastTwo = Exponent(rows, r.Series(), true);
    r.ExponentMinusNone =
      r.Exponent - Exponent(rows, TechniqueSpec{ "none", "default" }.Label() + " " + r.Camera());
  }
}

std::string Optional(double v, int digits)
{
  return v < 0 || std::isnan(v) ? std::string() : Fixed(v, digits);
}

std::string Dash(const std::string& s)
{
  return s.empty() ? "–" : s;
}

void WriteSweepCSV(const std::string& path, const std::vector<SweepRow>& rows, const Options& o)
{
  std::ofstream out(path);
  out << "triangles,technique,setting,camera,width,height,frames,median_ms,min_ms,ratio_to_none,"
         "first_frame_ms,technique_ms,samples_ms,rss_before_mb,peak_rss_mb,bytes_per_triangle_over_"
         "none,"
         "exponent,exponent_minus_none,exponent_last_two,status\n";
  for (const SweepRow& r : rows)
  {
    const double e = r.Exponent, d = r.ExponentMinusNone, l = r.ExponentLastTwo;
    out << r.Triangles << "," << r.Technique.Name << ",\"" << r.Technique.Setting << "\","
        << r.Camera() << "," << o.Width << "," << o.Height << "," << o.Frames << ","
        << Optional(r.MedianMs, 3) << "," << Optional(r.MinMs, 3) << ","
        << Optional(r.RatioToNone, 3) << "," << Optional(r.FirstFrameMs, 3) << ","
        << Optional(r.TechniqueMs, 3) << "," << Optional(r.SamplesMs, 3) << ","
        << Optional(r.RssBeforeMB, 0) << "," << Optional(r.PeakRssMB, 0) << ","
        << (std::isnan(r.BytesPerTriangleOverNone) ? "" : Fixed(r.BytesPerTriangleOverNone, 1))
        << "," << (std::isnan(e) ? "" : Fixed(e, 3)) << "," << (std::isnan(d) ? "" : Fixed(d, 3))
        << "," << (std::isnan(l) ? "" : Fixed(l, 3)) << ",\""
        << (r.NotMeasured.empty() ? "measured" : "not measured: " + r.NotMeasured) << "\"\n";
  }
}

void WriteSweepMarkdown(
  const std::string& path, const std::vector<SweepRow>& rows, const Options& o)
{
  std::ofstream out(path);
  out << "# Scale sweep: frame time against triangle count\n\n"
      << "Scene: a UV sphere (the caster, N triangles) 1.5 m above a 10 m ground plane (2 "
         "triangles) under one directional light, its shadow in view; "
      << o.Width << "×" << o.Height << ". Median of " << o.Frames << " frames after " << o.Warmup
      << " warm-up frame(s), glFinish before each clock reading. *still*: the camera does not "
         "move (a technique may reuse the last frame's visibility); *moving*: the camera turns "
         "0.5° about the scene centre before every frame (warm-up frames included); *light "
         "moving* (with --moving-light): the camera still, the sun turns 0.5° about the vertical "
         "before every frame. *first "
         "frame*: the first frame after the technique is installed (scene extraction, "
         "acceleration structures, shaders), rendered before the still row's warm-up. *technique* "
         "and *samples*: medians "
         "over the timed frames of vtkPenumbraShadowPass's technique phase (all lights) and "
         "view-sample phase (– where the pass is not Penumbra's). *peak RSS*: the process's "
         "peak resident memory (VmHWM) during the row (first frame included), after returning "
         "freed heap memory to the system (malloc_trim) and resetting the peak to the resident "
         "set just before the row (writing 5 to /proc/self/clear_refs); it includes everything "
         "resident then (VTK, the sphere, the GL driver — llvmpipe's buffers and textures are "
         "process memory), shown as *RSS before*. *B/tri over none*: (peak RSS − the none row's "
         "peak RSS at the same count and camera) × 2^20 / caster triangles, what the shadows "
         "cost in memory per triangle on top of plain VTK; memory an earlier technique of the "
         "same count left resident is in it too (compare *RSS before*), so run one technique "
         "per process (--techniques none,T) to measure one technique alone. A row whose timed "
         "frames would exceed "
      << o.BudgetSeconds
      << " s (judged from the last warm-up frame), or whose first frame alone does, is not "
         "measured, nor are the larger counts of its series.\n\n"
      << "| triangles | technique | camera | median ms | × none | first frame ms | technique ms | "
         "samples ms | RSS before MB | peak RSS MB | B/tri over none | note |\n"
      << "|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n";
  for (const SweepRow& r : rows)
  {
    out << "| " << r.Triangles << " | " << r.Technique.Label() << " | " << r.Camera() << " | "
        << Dash(Optional(r.MedianMs, 1)) << " | " << Dash(Optional(r.RatioToNone, 2)) << " | "
        << Dash(Optional(r.FirstFrameMs, 0)) << " | " << Dash(Optional(r.TechniqueMs, 1)) << " | "
        << Dash(Optional(r.SamplesMs, 1)) << " | " << Dash(Optional(r.RssBeforeMB, 0)) << " | "
        << Dash(Optional(r.PeakRssMB, 0)) << " | "
        << (std::isnan(r.BytesPerTriangleOverNone) ? "–" : Fixed(r.BytesPerTriangleOverNone, 0))
        << " | " << (r.NotMeasured.empty() ? "" : "not measured: " + r.NotMeasured) << " |\n";
  }
  out << "\nCost exponent: least-squares slope of log(median frame ms) against log(caster "
         "triangles) over the measured counts (1: linear growth). A technique whose exponent "
         "exceeds none's grows faster than the unshadowed frame. Small counts are dominated by "
         "per-pixel costs that do not grow with N, so the slope between the two largest counts "
         "is given too.\n\n"
      << "| technique | camera | exponent | exponent − none's | slope, two largest counts | counts "
         "measured |\n"
      << "|---|---|---:|---:|---:|---:|\n";
  std::set<std::string> done;
  for (const SweepRow& r : rows)
  {
    if (!done.insert(r.Series()).second)
    {
      continue;
    }
    const auto measured = std::count_if(rows.begin(), rows.end(),
      [&](const SweepRow& s) { return s.Series() == r.Series() && s.NotMeasured.empty(); });
    out << "| " << r.Technique.Label() << " | " << r.Camera() << " | "
        << (std::isnan(r.Exponent) ? "–" : Fixed(r.Exponent, 2)) << " | "
        << (std::isnan(r.ExponentMinusNone) ? "–" : Fixed(r.ExponentMinusNone, 2)) << " | "
        << (std::isnan(r.ExponentLastTwo) ? "–" : Fixed(r.ExponentLastTwo, 2)) << " | " << measured
        << " |\n";
  }
}

// Log-log: median frame time against caster triangles, one line per technique and camera
// (still solid with circles, camera moving dashed with squares, light moving dotted with
// diamonds, one colour per technique).
bool WriteSweepChart(const std::string& path, const std::vector<SweepRow>& rows, std::string& error)
{
  vtkNew<vtkContextView> view;
  view->GetRenderWindow()->SetOffScreenRendering(1);
  view->GetRenderWindow()->SetMultiSamples(0);
  view->GetRenderWindow()->SetSize(1000, 640);
  view->GetRenderer()->SetBackground(1, 1, 1);
  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  chart->SetTitle("Frame time against caster triangles");
  chart->SetShowLegend(true);
  chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::LEFT);
  chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  double range[4] = { std::numeric_limits<double>::max(), 0.0, std::numeric_limits<double>::max(),
    0.0 };
  std::vector<std::string> series, techniques;
  for (const SweepRow& r : rows)
  {
    if (!r.NotMeasured.empty())
    {
      continue;
    }
    range[0] = std::min(range[0], static_cast<double>(r.Triangles));
    range[1] = std::max(range[1], static_cast<double>(r.Triangles));
    range[2] = std::min(range[2], r.MedianMs);
    range[3] = std::max(range[3], r.MedianMs);
    if (std::find(series.begin(), series.end(), r.Series()) == series.end())
    {
      series.push_back(r.Series());
    }
    if (std::find(techniques.begin(), techniques.end(), r.Technique.Label()) == techniques.end())
    {
      techniques.push_back(r.Technique.Label());
    }
  }
  if (series.empty())
  {
    error = "no measured point to draw";
    return false;
  }
  for (const std::string& name : series)
  {
    vtkNew<vtkTable> table;
    vtkNew<vtkFloatArray> x, y;
    x->SetName("triangles");
    y->SetName(name.c_str());
    const SweepRow* first = nullptr;
    for (const SweepRow& r : rows)
    {
      if (r.Series() == name && r.NotMeasured.empty())
      {
        first = first ? first : &r;
        x->InsertNextValue(static_cast<float>(r.Triangles));
        y->InsertNextValue(static_cast<float>(r.MedianMs));
      }
    }
    table->AddColumn(x);
    table->AddColumn(y);
    // A line of one point is an error to VTK: a lone count is drawn as a marker.
    auto* plot = vtkPlotPoints::SafeDownCast(
      chart->AddPlot(x->GetNumberOfTuples() > 1 ? vtkChart::LINE : vtkChart::POINTS));
    plot->SetInputData(table, 0, 1);
    plot->SetLabel(name);
    const auto colour = std::find(techniques.begin(), techniques.end(), first->Technique.Label()) -
      techniques.begin();
    const double* rgb = Palette[colour % PaletteSize];
    plot->SetColor(rgb[0], rgb[1], rgb[2]);
    plot->SetWidth(2.0);
    const int line[] = { vtkPen::SOLID_LINE, vtkPen::DASH_LINE, vtkPen::DOT_LINE };
    const int marker[] = { vtkPlotPoints::CIRCLE, vtkPlotPoints::SQUARE, vtkPlotPoints::DIAMOND };
    plot->GetPen()->SetLineType(line[first->Moves]);
    plot->SetMarkerStyle(marker[first->Moves]);
    plot->SetMarkerSize(8.0f);
  }
  // Room above the slowest point for the legend, which sits top left over the small counts.
  const struct
  {
    int Axis;
    const char* Title;
    double Min, Max;
  } axes[] = { { vtkAxis::BOTTOM, "caster triangles", range[0] / 1.5, range[1] * 1.5 },
    { vtkAxis::LEFT, "median frame time (ms)", range[2] / 1.5, range[3] * 30.0 } };
  for (const auto& a : axes)
  {
    vtkAxis* axis = chart->GetAxis(a.Axis);
    axis->SetTitle(a.Title);
    axis->SetLogScale(true);
    axis->SetBehavior(vtkAxis::FIXED);
    axis->SetUnscaledRange(a.Min, a.Max);
  }
  return SaveChart(view, path, error);
}
}

int RunSweep(const Options& o)
{
  std::vector<SweepRow> rows;
  std::vector<SweepRow::Motion> motions = { SweepRow::Still, SweepRow::CameraTurns };
  if (o.MovingLight)
  {
    motions.push_back(SweepRow::LightTurns);
  }
  const int total =
    static_cast<int>(o.SweepTriangles.size() * o.Techniques.size() * motions.size());
  int done = 0;
  bool failed = false;
  // Series that ran out of budget: cost grows with N, so their larger counts are not tried.
  std::set<std::string> overBudget;
  bool sceneImage = false;
  for (const vtkIdType target : o.SweepTriangles)
  {
    Progress(done, total, std::to_string(target) + " triangles: building the sphere");
    vtkSmartPointer<vtkPolyData> caster = MakeCaster(target);
    vtkNew<vtkRenderer> ren;
    SetUpSweepScene(ren, caster);
    penumbra_cli::ErrorLog errors;
    std::string windowError;
    vtkSmartPointer<vtkRenderWindow> win =
      penumbra_cli::MakeWindow(o.Width, o.Height, ren, errors, windowError);
    if (!win)
    {
      std::cerr << "\npenumbra-bench: " << windowError << "\n";
      return 3;
    }
    const SweepScene scene{ ren, win, &errors };
    vtkNew<vtkPenumbraTechniques> registry;
    for (const TechniqueSpec& spec : o.Techniques)
    {
      // Applied once for all rows: the moving rows start from the still row's caches.
      std::string refused;
      if (spec.Options.contains("samples"))
      {
        refused = "a light-sample count means nothing for a directional light";
      }
      else if (!registry->Apply(ren, spec.Name.c_str(), spec.Options.dump().c_str()))
      {
        refused = registry->GetErrorMessage();
        failed = true;
      }
      for (const SweepRow::Motion motion : motions)
      {
        SweepRow row;
        row.Triangles = caster->GetNumberOfPolys();
        row.Technique = spec;
        row.Moves = motion;
        Progress(done, total, std::to_string(row.Triangles) + ": " + row.Series());
        if (!refused.empty())
        {
          row.NotMeasured = refused;
        }
        else if (overBudget.count(row.Series()))
        {
          row.NotMeasured = "over budget at a smaller count";
          row.OverBudget = true;
        }
        else
        {
          MeasureSweepRow(scene, o, row);
          failed = failed || (!row.NotMeasured.empty() && !row.OverBudget);
        }
        if (row.OverBudget)
        {
          overBudget.insert(row.Series());
        }
        if (motion == SweepRow::Still && spec.Name != "none" && row.NotMeasured.empty() &&
          !sceneImage)
        {
          // What the sweep renders: the first shadowed still frame, for the reader to check.
          vtkNew<vtkPenumbraImageIO> io;
          sceneImage =
            io->Write(penumbra_cli::GrabRGB(win), (o.OutDir + "/sweep_scene.png").c_str());
        }
        rows.push_back(row);
        ++done;
      }
    }
    registry->Apply(ren, "none", "");
    win->Finalize();
  }
  Progress(total, total, "writing results");
  Summarize(rows);
  WriteSweepCSV(o.OutDir + "/sweep.csv", rows, o);
  WriteSweepMarkdown(o.OutDir + "/sweep.md", rows, o);
  std::ifstream md(o.OutDir + "/sweep.md");
  std::cout << md.rdbuf();
  std::string chartError;
  if (!WriteSweepChart(o.OutDir + "/sweep.png", rows, chartError))
  {
    std::cerr << "penumbra-bench: sweep chart: " << chartError << "\n";
    return 3;
  }
  return failed ? 3 : 0;
}
}
