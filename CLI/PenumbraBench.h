// Pieces penumbra-bench's two runs share: the scene benchmark (error against run time,
// penumbra-bench.cxx) and the scale sweep (run time against triangle count,
// PenumbraBenchSweep.cxx). Not a public API.
#ifndef PenumbraBench_h
#define PenumbraBench_h

#include "vtkType.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

class vtkContextView;
class vtkFloatArray;
class vtkIntArray;
class vtkLight;
class vtkPenumbraViewSamples;
class vtkUnsignedCharArray;
class vtkPenumbraShadowPass;
class vtkRenderWindow;
class vtkRenderer;

namespace penumbra_bench
{
// A technique as given on the command line: "shadowmap:resolution=2048;filter=pcf".
struct TechniqueSpec
{
  std::string Name;
  std::string Setting; // "resolution=2048" or "default"
  nlohmann::json Options = nlohmann::json::object();

  // "shadowmap resolution=2048", or the name alone for the default setting.
  std::string Label() const
  {
    return this->Setting == "default" ? this->Name : this->Name + " " + this->Setting;
  }
};

// Everything the command line sets; each default is the member initialiser.
struct Options
{
  std::vector<std::string> SceneNames = { "default", "isosurface", "city_area_light",
    "sphere_light" };
  std::vector<std::string> TechniqueTexts = { "none", "auto", "vtk-shadowmap:resolution=1024",
    "vtk-shadowmap:resolution=2048", "vtk-shadowmap:resolution=4096", "raytraced",
    "conservative:resolution=1024", "conservative:resolution=2048", "llsm", "llsm-hybrid",
    "shadowmap:resolution=1024", "shadowmap:resolution=4096",
    "shadowmap:resolution=2048;filter=pcf", "shadowmap:resolution=2048;filter=bilinear", "resm",
    "rmsm", "volumes", "volumes:silhouettes=gpu", "volumes:measure_fill=true", "pcss",
    "single-sample-soft", "soft-shadowmap", "adaptive-soft:samples=4", "adaptive-soft:samples=8",
    "raytraced:samples=4", "gears:samples=4", "raytraced:samples=8", "gears:samples=8",
    "raytraced:samples=16", "gears:samples=16" };
  // The parsed TechniqueTexts, with `none` first if it was not asked for (every point is
  // compared with the unshadowed frame).
  std::vector<TechniqueSpec> Techniques;
  std::string OutDir;
  int Width = 640, Height = 480, Frames = 5, Warmup = 1;
  bool Images = true;
  bool MovingLight = false;
  // --moving-camera: the camera moves by a negligible amount before every frame, so the view
  // samples are rendered again (a still camera keeps them between frames).
  bool MovingCamera = false;
  // --still-frames: also time frames in which nothing changes (the pass reuses its visibility).
  bool StillFrames = false;
  // --mismatch-lists: per hard light and point, the samples that disagree with the
  // reference and what surrounds them (WriteMismatchList()).
  bool MismatchLists = false;

  // --scale-sweep: caster triangle counts; empty = the scene benchmark runs instead.
  std::vector<vtkIdType> SweepTriangles;
  // Wall-clock seconds a sweep point may spend on its timed frames. Two minutes keeps a
  // 1e7-triangle sweep of five techniques within an hour on a 2-core software rasterizer
  // while every technique that is interactive at all still gets its frames measured.
  double BudgetSeconds = 120.0;
};

// The sweep's defaults where the command line leaves them open: a 720p frame, and the
// techniques whose growth with triangle count the sweep is about.
constexpr int SweepWidth = 1280, SweepHeight = 720;
const char* const SweepTechniques = "none,raytraced,shadowmap,conservative,volumes";

std::vector<std::string> Split(const std::string& s, char sep);
bool ParseTechnique(const std::string& text, TechniqueSpec& spec, std::string& error);

// The Penumbra shadow pass the renderer draws with, or nullptr (no shadows, VTK's passes).
vtkPenumbraShadowPass* ShadowPassOf(vtkRenderer* ren);

// One-line progress bar on stderr.
void Progress(int done, int total, const std::string& what);

std::string Fixed(double v, int digits);

// The timed frames of one point. Frames are finished (glFinish) before the clock is read.
struct FrameTimes
{
  std::vector<double> Ms; // timed frames, sorted
  // Why the point was cut short (over its budget); empty when every frame ran.
  std::string OverBudget;
  double Median() const { return this->Ms[this->Ms.size() / 2]; }
};

// Renders `warmup` untimed frames, then `frames` timed ones; `before(f)` runs before frame f
// (0-based over warm-up and timed frames, outside the clock) and `afterTimed()` after each
// timed frame (outside the clock: reading the pass's phase timers). A point stops early
// when the last warm-up frame (the first frame if there is none) took more than
// budgetMs / frames, when any warm-up frame alone took more than budgetMs, or when the timed
// frames together exceed budgetMs; FrameTimes::OverBudget says which.
FrameTimes TimeFrames(vtkRenderWindow* win, int warmup, int frames, double budgetMs,
  const std::function<void(int)>& before, const std::function<void()>& afterTimed = nullptr);

// Colours of the charts' series, one per technique.
constexpr int PaletteSize = 7;
extern const double Palette[PaletteSize][3];

// Renders a chart view offscreen and writes it as PNG; false with `error` set on failure.
bool SaveChart(vtkContextView* view, const std::string& path, std::string& error);

// --mismatch-lists: writes `path` (CSV), one row per measured sample whose `estimate`
// disagrees with `reference` (thresholded at 0.5, ties excluded): its pixel, both answers,
// the Chebyshev distance in pixels to the reference's nearest shadow boundary (4: none within
// 3), whether an 8-neighbour is background, another prop or a surface turned by more than
// ~10 degrees (silhouette, crease, contact), the cosine to the light and, from `levels`
// (may be null), the level rmsm looked it up at. Returns a one-line summary by category.
std::string WriteMismatchList(const std::string& path, vtkPenumbraViewSamples* samples,
  vtkFloatArray* estimate, vtkFloatArray* reference, vtkUnsignedCharArray* ties, vtkLight* light,
  vtkIntArray* levels);

// The scale sweep (--scale-sweep): writes sweep.csv, sweep.md and sweep.png into
// options.OutDir and returns the exit status.
int RunSweep(const Options& options);
}

#endif
