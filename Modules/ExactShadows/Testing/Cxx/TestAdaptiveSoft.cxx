// adaptive-soft (vtkPenumbraRayTracedShadows with an adaptive block; Brabec 2003, ch. 11.3)
// against raytraced at the same k on the same view samples (160 x 120):
// - every top-level lattice sample (every `block`-th pixel, the last row and column) is
//   traced, so it equals raytraced exactly;
// - the mean absolute difference from raytraced stays within a stated bound, and the share
//   of traced samples is well below 1 (the technique skips work);
// - a tolerance of 1 interpolates more blocks (fewer samples traced, more samples differ),
//   a tolerance of 0 fewer (fewer samples differ) than the default;
// - hard lights are traced at every sample: the same answer as raytraced;
// - out-of-range options are refused.
#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace
{
using penumbra_technique_tests::ReadScene;
using penumbra_technique_tests::TestWindow;

struct Run
{
  std::vector<std::vector<float>> Visibility; // per light
  std::vector<bool> Area;                     // per light
  double TracedFraction = -1.0;               // adaptive runs: the last area light's
  long long Differ = 0;                       // samples that differ from raytraced
  int Width = 0, Height = 0;
};

int Render(const char* scene, const char* technique, const char* options, Run& run)
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> renderer = ReadScene(scene, reader);
  CHECK(renderer != nullptr);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, technique, options));
  vtkSmartPointer<vtkRenderWindow> window = TestWindow(renderer, 160, 120);
  window->Render();
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(renderer);
  CHECK(pass != nullptr);
  vtkPenumbraViewSamples* samples = pass->GetViewSamples();
  run.Width = samples->GetWidth();
  run.Height = samples->GetHeight();
  CHECK(samples->GetNumberOfSamples() == static_cast<vtkIdType>(run.Width) * run.Height);
  for (int i = 0; i < pass->GetNumberOfLights(); ++i)
  {
    vtkFloatArray* vis = pass->GetVisibility(i);
    CHECK(vis != nullptr);
    run.Visibility.emplace_back(vis->GetPointer(0), vis->GetPointer(0) + vis->GetNumberOfTuples());
    run.Area.push_back(vtkPenumbraAreaLight::SafeDownCast(pass->GetLight(i)) != nullptr);
    if (auto* used = vtkPenumbraRayTracedShadows::SafeDownCast(pass->GetLightTechnique(i)))
    {
      if (run.Area.back())
      {
        run.TracedFraction = used->GetUncertainFraction();
      }
    }
  }
  return EXIT_SUCCESS;
}

bool OnLattice(int x, int y, int width, int height, int block)
{
  return (x % block == 0 || x == width - 1) && (y % block == 0 || y == height - 1);
}

// adaptive-soft with `options` against raytraced at k = 4 on `scene`: lattice samples equal,
// mean absolute difference over the area lights' samples at most `bound`.
int Compare(const char* scene, const std::string& options, int block, double bound, Run& adaptive)
{
  Run exact;
  RUN(Render(scene, "raytraced", "{\"samples\": 4}", exact));
  RUN(Render(scene, "adaptive-soft", options.c_str(), adaptive));
  CHECK(exact.Visibility.size() == adaptive.Visibility.size());
  for (size_t k = 0; k < exact.Visibility.size(); ++k)
  {
    const std::vector<float>& a = adaptive.Visibility[k];
    const std::vector<float>& e = exact.Visibility[k];
    CHECK(a.size() == e.size());
    double sum = 0.0;
    vtkIdType count = 0, differ = 0;
    for (int y = 0; y < exact.Height; ++y)
    {
      for (int x = 0; x < exact.Width; ++x)
      {
        const size_t s = static_cast<size_t>(y) * exact.Width + x;
        CHECK(a[s] >= -1.0f && a[s] <= 1.0f);
        if (!exact.Area[k] || OnLattice(x, y, exact.Width, exact.Height, block))
        {
          CHECK(a[s] == e[s]); // traced exactly: hard lights and the lattice
        }
        if (e[s] >= 0.0f)
        {
          sum += std::fabs(a[s] - e[s]);
          ++count;
          differ += a[s] != e[s];
        }
      }
    }
    const double mad = count ? sum / count : 0.0;
    std::printf("%-22s %-34s light %zu: mean |adaptive - raytraced| %.5f (bound %.5f), %lld of "
                "%lld samples differ, traced %.3f\n",
      scene, options.c_str(), k, mad, bound, static_cast<long long>(differ),
      static_cast<long long>(count), adaptive.TracedFraction);
    CHECK(mad <= bound);
    adaptive.Differ += differ;
  }
  return EXIT_SUCCESS;
}
}

int TestAdaptiveSoft(int, char*[])
{
  {
    // Out-of-range settings are refused by name, the edges of the ranges accepted.
    vtkNew<vtkPenumbraTechniques> techniques;
    vtkNew<vtkRenderer> renderer;
    CHECK(techniques->Apply(renderer, "adaptive-soft", "{\"block\": 1}") == 0);
    CHECK(techniques->Apply(renderer, "adaptive-soft", "{\"block\": 17}") == 0);
    CHECK(techniques->Apply(renderer, "adaptive-soft", "{\"tolerance\": -0.1}") == 0);
    CHECK(techniques->Apply(renderer, "adaptive-soft", "{\"tolerance\": 2}") == 0);
    CHECK(techniques->Apply(renderer, "adaptive-soft", "{\"block\": 2, \"tolerance\": 1}") == 1);
  }
  // Measured on llvmpipe: area_light 0.0030 / 0.0021 per light, traced 0.28;
  // linear_light (block 4) 0.0008, traced 0.34. Bound: twice the largest plus 2e-3.
  Run area, linear, loose, strict;
  RUN(Compare("area_light.json", "{\"samples\": 4}", 8, 0.0080, area));
  CHECK(area.TracedFraction > 0.0 && area.TracedFraction < 0.6);
  RUN(Compare("linear_light.json", "{\"samples\": 4, \"block\": 4}", 4, 0.0080, linear));
  CHECK(linear.TracedFraction > 0.0 && linear.TracedFraction < 0.6);
  // The tolerance decides how many blocks are refined.
  RUN(Compare("area_light.json", "{\"samples\": 4, \"tolerance\": 1}", 8, 0.05, loose));
  RUN(Compare("area_light.json", "{\"samples\": 4, \"tolerance\": 0}", 8, 0.0080, strict));
  CHECK(loose.TracedFraction < area.TracedFraction);
  CHECK(loose.Differ > area.Differ && area.Differ > strict.Differ);
  return EXIT_SUCCESS;
}
