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

#include "PenumbraBenchScenes.h"
#include "PenumbraCLI.h"

#include "vtkNew.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderer.h"
#include "vtksys/SystemTools.hxx"

#include <nlohmann/json.hpp>

#include <cmath>

#ifndef PENUMBRA_SCENES_DIR
#define PENUMBRA_SCENES_DIR "Data/Scenes"
#endif

namespace penumbra_bench
{
std::string ResolveScene(const std::string& name)
{
  if (vtksys::SystemTools::FileExists(name, true))
  {
    return name;
  }
  return std::string(PENUMBRA_SCENES_DIR) + "/" + name + ".json";
}
}

namespace
{
using namespace penumbra_bench;

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
