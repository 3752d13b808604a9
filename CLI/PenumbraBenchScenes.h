// What the files of penumbra-bench's scene benchmark share: the rows it measures and the run
// they accumulate in. Arguments in penumbra-bench.cxx, measuring in PenumbraBenchScenes.cxx,
// the results in PenumbraBenchReport.cxx. Not a public API.
#ifndef PenumbraBenchScenes_h
#define PenumbraBenchScenes_h

#include "PenumbraBench.h"

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

namespace penumbra_bench
{
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
  // The technique's statistics of the last frame for this light (vtkPenumbraStatistics,
  // "name value, ..."), with "differs_from_raytraced" on area lights; empty for VTK's pass.
  std::string Statistics;
};

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

// A scene name of Data/Scenes, or a path (penumbra-bench.cxx).
std::string ResolveScene(const std::string& name);
int MeasureScene(const std::string& sceneName, const Options& o, BenchRun& run);
int WriteResults(const Options& o, const BenchRun& run);
}

#endif
