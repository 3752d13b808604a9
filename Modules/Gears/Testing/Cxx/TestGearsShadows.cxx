// vtkPenumbraGearsShadows (Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for
// Rendering Shadows", Computer Graphics Forum 33(6), 2014) against the exact reference on the same
// view samples:
// - k x k masks bit-identical to the reference's ray cast (vtkPenumbraReference::
//   ComputeAreaMasks) for k = 4, 8, 16 on the area-light scene (rectangle and line lights)
//   and on the sphere-light scene (a point light with a radius, shadowed as its disc: the
//   masks run over the disc's grid with the corner cells never lit),
//   visibility identical for every sample outside reference ties, few samples handed back to
//   the reference, the same answer for every grid resolution;
// - a 1e-6 m light gives the point-light shadows;
// - a 1 km light gives finite, smooth visibility without umbra;
// - the penumbra of a straight occluder edge matches the closed form, sample by sample;
// - the GL 4.3 compute path gives the same masks, visibility and blocking statistics as the
//   CPU path on every one of these scenes (the 1 km light's long lists exceed llvmpipe's
//   65535 loop iterations per invocation group: without the shader's loop probe, 9 of its
//   samples lose blockers), and falls back to the CPU path with a message
//   where it cannot run (no OpenGL window, more than 32 light samples per row);
// - a dense mesh under a large light gives the reference's visibility and masks whether its
//   long-list cells are masked from the casters' tree (DenseCells), ray traced whole, or
//   masked from their lists (TraceThreshold 0);
// - bad input is refused without a crash.
#include "vtkActor.h"
#include "vtkCameraPass.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkRendererCollection.h"
#include "vtkSmartPointer.h"
#include "vtkTypeUInt32Array.h"
#include "vtkUnsignedCharArray.h"

#include "PenumbraTestMacros.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace
{
vtkPenumbraShadowPass* ShadowPass(vtkRenderer* renderer)
{
  return vtkPenumbraShadowPass::GetInstalled(renderer);
}

vtkSmartPointer<vtkRenderer> ReadScene(const std::string& file, vtkPenumbraSceneReader* reader)
{
  reader->SetFileName((std::string(PENUMBRA_SCENES_DIR) + "/" + file).c_str());
  if (!reader->Read())
  {
    std::cerr << "cannot read " << file << ": " << reader->GetErrorMessage() << std::endl;
    return nullptr;
  }
  return reader->GetRenderer();
}

// A rendered frame: the view samples and scene geometry the shadow pass extracted.
struct Frame
{
  vtkSmartPointer<vtkRenderWindow> Window;
  vtkPenumbraShadowPass* Pass = nullptr;
};

int RenderFrame(vtkRenderer* renderer, int width, int height, Frame& frame)
{
  frame.Window = vtkSmartPointer<vtkRenderWindow>::Take(vtkRenderWindow::New());
  frame.Window->SetSize(width, height);
  frame.Window->SetMultiSamples(0);
  frame.Window->AddRenderer(renderer);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, "gears", "{}"));
  frame.Window->Render();
  frame.Pass = ShadowPass(renderer);
  CHECK(frame.Pass != nullptr);
  CHECK(vtkPenumbraGearsShadows::SafeDownCast(frame.Pass->GetTechnique()) != nullptr);
  CHECK(frame.Pass->GetViewSamples()->GetNumberOfValidSamples() > 0);
  return EXIT_SUCCESS;
}

// GEARS against the reference for one light of a rendered frame at the light's own k, on
// the CPU path and on the compute path (in the frame's OpenGL context): both must give the
// reference's masks, and the same blocking statistics.
int CompareWithReference(const std::string& label, Frame& frame, vtkPenumbraAreaLight* light,
  int grid, double maxUncertainShare)
{
  vtkIdType necessary = -1;
  for (const int path : { vtkPenumbraGearsShadows::PATH_CPU, vtkPenumbraGearsShadows::PATH_GPU })
  {
    const bool gpu = path == vtkPenumbraGearsShadows::PATH_GPU;
    vtkPenumbraSceneGeometry* geometry = frame.Pass->GetGeometry();
    vtkPenumbraViewSamples* samples = frame.Pass->GetViewSamples();
    vtkNew<vtkPenumbraGearsShadows> gears;
    gears->KeepMasksOn();
    gears->SetGridResolution(grid);
    gears->SetPath(path);
    // Mask every cell (no cell handed to the ray tracer whole): these comparisons are about
    // the masks, and both paths must then visit the same triangles.
    gears->SetTraceThreshold(0.0);
    vtkNew<vtkFloatArray> vis;
    vtkRenderer* renderer = frame.Window->GetRenderers()->GetFirstRenderer();
    CHECK(gears->ComputeVisibility(renderer, geometry, samples, light, vis));
    // The compute path must really run here (Mesa llvmpipe has GL 4.5).
    CHECK(gears->GetLastPath() == path);
    CHECK(std::string(gears->GetPathMessage()).empty());

    vtkNew<vtkPenumbraReference> reference;
    reference->SetGeometry(geometry);
    vtkNew<vtkFloatArray> ref;
    CHECK(reference->ComputeVisibility(samples, light, ref));
    vtkNew<vtkTypeUInt32Array> refMasks;
    CHECK(reference->ComputeAreaMasks(samples, light, refMasks));
    vtkUnsignedCharArray* ties = reference->GetTies();
    vtkTypeUInt32Array* masks = gears->GetMasks();
    vtkUnsignedCharArray* uncertain = gears->GetUncertainSamples();
    CHECK(masks->GetNumberOfComponents() == refMasks->GetNumberOfComponents());
    CHECK(masks->GetNumberOfTuples() == refMasks->GetNumberOfTuples());

    const vtkIdType n = samples->GetNumberOfSamples();
    const int words = refMasks->GetNumberOfComponents();
    vtkIdType visMismatch = 0, maskMismatch = 0, bitMismatch = 0, compared = 0, tieCount = 0;
    vtkIdType penumbra = 0;
    for (vtkIdType s = 0; s < n; ++s)
    {
      if (ties->GetValue(s))
      {
        ++tieCount;
        continue;
      }
      visMismatch += vis->GetValue(s) != ref->GetValue(s);
      const float v = ref->GetValue(s);
      penumbra += v > 0.0f && v < 1.0f;
      if (uncertain->GetValue(s) || !samples->IsValid(s))
      {
        continue;
      }
      ++compared;
      bool same = true;
      for (int w = 0; w < words; ++w)
      {
        const vtkTypeUInt32 diff =
          masks->GetTypedComponent(s, w) ^ refMasks->GetTypedComponent(s, w);
        bitMismatch += __builtin_popcount(diff);
        same = same && diff == 0;
      }
      maskMismatch += !same;
    }
    const vtkIdType valid = samples->GetNumberOfValidSamples();
    std::printf("%-36s %s k=%2d grid %4d: valid %lld, penumbra %lld, masks compared %lld, "
                "uncertain %lld (%.3f%%, %lld rays), ties %lld, mask mismatches %lld (%lld bits), "
                "visibility mismatches %lld; cells %lld/%lld, tri/cell max %lld avg %.1f, "
                "global %lld, blocking share %.1f%%, tests %lld; grid %.1f ms, masks %.1f ms, "
                "trace %.1f ms (reference %.1f ms), flagged for the CPU %lld\n",
      label.c_str(), gpu ? "gpu" : "cpu", light->GetSamplesPerAxis(), grid,
      static_cast<long long>(valid), static_cast<long long>(penumbra),
      static_cast<long long>(compared),
      static_cast<long long>(gears->GetNumberOfSamplesWithTracedRays()),
      100.0 * gears->GetUncertainFraction(), static_cast<long long>(gears->GetNumberOfTracedRays()),
      static_cast<long long>(tieCount), static_cast<long long>(maskMismatch),
      static_cast<long long>(bitMismatch), static_cast<long long>(visMismatch),
      static_cast<long long>(gears->GetNumberOfOccupiedCells()),
      static_cast<long long>(gears->GetNumberOfCells()),
      static_cast<long long>(gears->GetMaxTrianglesPerCell()), gears->GetAverageTrianglesPerCell(),
      static_cast<long long>(gears->GetNumberOfGlobalTriangles()),
      100.0 * gears->GetBlockingShare(), static_cast<long long>(gears->GetNumberOfSegmentTests()),
      gears->GetGridTimeMs(), gears->GetMaskTimeMs(), gears->GetTraceTimeMs(),
      reference->GetLastTimeMs(), static_cast<long long>(gears->GetNumberOfFlaggedSamples()));
    CHECK(maskMismatch == 0);
    CHECK(visMismatch == 0);
    CHECK(compared > 0);
    CHECK(gears->GetUncertainFraction() <= maxUncertainShare);
    CHECK(gears->GetNumberOfAssignments() >= gears->GetNumberOfNecessaryAssignments());
    // The shader decides most samples itself; the CPU path never flags anything.
    CHECK(gpu ? gears->GetNumberOfFlaggedSamples() <= valid / 10
              : gears->GetNumberOfFlaggedSamples() == 0);
    // Same decisions in the same order: the same triangles set new bits.
    CHECK(necessary < 0 || gears->GetNumberOfNecessaryAssignments() == necessary);
    necessary = gears->GetNumberOfNecessaryAssignments();
  }
  return EXIT_SUCCESS;
}

// Where the compute path cannot run, the CPU path answers and says why: no OpenGL window,
// and more than 32 light samples per row.
int CheckComputeFallback(Frame& frame, vtkPenumbraAreaLight* light)
{
  vtkRenderer* renderer = frame.Window->GetRenderers()->GetFirstRenderer();
  vtkPenumbraSceneGeometry* geometry = frame.Pass->GetGeometry();
  vtkPenumbraViewSamples* samples = frame.Pass->GetViewSamples();
  vtkNew<vtkPenumbraGearsShadows> cpu;
  vtkNew<vtkFloatArray> expected;
  CHECK(cpu->ComputeVisibility(nullptr, geometry, samples, light, expected));
  CHECK(cpu->GetLastPath() == vtkPenumbraGearsShadows::PATH_CPU);
  const int original = light->GetSamplesPerAxis();
  struct Case
  {
    vtkRenderer* Renderer;
    int K;
    const char* Expected;
  };
  for (const Case& c :
    { Case{ nullptr, original, "no OpenGL render window" }, Case{ renderer, 40, "32 bits" } })
  {
    light->SetSamplesPerAxis(c.K);
    vtkNew<vtkFloatArray> reference;
    CHECK(cpu->ComputeVisibility(nullptr, geometry, samples, light, reference));
    vtkNew<vtkPenumbraGearsShadows> gears;
    gears->SetPath(vtkPenumbraGearsShadows::PATH_GPU);
    vtkNew<vtkFloatArray> vis;
    const int display = vtkObject::GetGlobalWarningDisplay();
    vtkObject::GlobalWarningDisplayOff(); // the fallback warning is expected here
    CHECK(gears->ComputeVisibility(c.Renderer, geometry, samples, light, vis));
    vtkObject::SetGlobalWarningDisplay(display);
    const std::string message = gears->GetPathMessage();
    std::printf("compute path fallback (k = %d): %s\n", c.K, message.c_str());
    CHECK(gears->GetLastPath() == vtkPenumbraGearsShadows::PATH_CPU);
    CHECK(message.find(c.Expected) != std::string::npos);
    CHECK(vis->GetNumberOfTuples() == reference->GetNumberOfTuples());
    for (vtkIdType s = 0; s < vis->GetNumberOfTuples(); ++s)
    {
      CHECK(vis->GetValue(s) == reference->GetValue(s));
    }
  }
  light->SetSamplesPerAxis(original);
  return EXIT_SUCCESS;
}

// List overflow: with room for only 1024 entries the grid is coarsened with a warning and
// the answer does not change. A point light is ray traced by the reference.
int CheckOverflowAndOtherLights(Frame& frame)
{
  vtkPenumbraSceneGeometry* geometry = frame.Pass->GetGeometry();
  vtkPenumbraViewSamples* samples = frame.Pass->GetViewSamples();
  vtkLight* light = frame.Pass->GetLight(0);
  vtkNew<vtkPenumbraGearsShadows> roomy;
  vtkNew<vtkFloatArray> expected;
  CHECK(roomy->ComputeVisibility(nullptr, geometry, samples, light, expected));
  CHECK(roomy->GetEffectiveGridResolution() == 128);
  vtkNew<vtkPenumbraGearsShadows> cramped;
  cramped->SetMaxListEntries(1024);
  vtkNew<vtkFloatArray> degraded;
  const int display = vtkObject::GetGlobalWarningDisplay();
  vtkObject::GlobalWarningDisplayOff(); // the coarsening warning is expected here
  CHECK(cramped->ComputeVisibility(nullptr, geometry, samples, light, degraded));
  vtkObject::SetGlobalWarningDisplay(display);
  std::printf("overflow: grid %d -> %d, %lld global triangles\n", cramped->GetGridResolution(),
    cramped->GetEffectiveGridResolution(),
    static_cast<long long>(cramped->GetNumberOfGlobalTriangles()));
  CHECK(cramped->GetEffectiveGridResolution() < 128);
  for (vtkIdType s = 0; s < samples->GetNumberOfSamples(); ++s)
  {
    CHECK(degraded->GetValue(s) == expected->GetValue(s));
  }

  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetConeAngle(180.0);
  point->SetPosition(1, 1, 4);
  vtkNew<vtkFloatArray> hard;
  CHECK(roomy->ComputeVisibility(nullptr, geometry, samples, point, hard));
  CHECK(!roomy->GetLastLightWasArea());
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(geometry);
  vtkNew<vtkFloatArray> ref;
  CHECK(reference->ComputeVisibility(samples, point, ref));
  for (vtkIdType s = 0; s < samples->GetNumberOfSamples(); ++s)
  {
    CHECK(hard->GetValue(s) == ref->GetValue(s));
  }
  return EXIT_SUCCESS;
}

// (a) The area-light scene: a rectangle (k = 8 in the file) and a line light (k = 16), each
// at k = 4, 8, 16; the result must not depend on the grid resolution.
int CheckAreaLightScene()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> renderer = ReadScene("area_light.json", reader);
  CHECK(renderer != nullptr);
  Frame frame;
  RUN(RenderFrame(renderer, 160, 120, frame));
  for (int i = 0; i < frame.Pass->GetNumberOfLights(); ++i)
  {
    auto* light = vtkPenumbraAreaLight::SafeDownCast(frame.Pass->GetLight(i));
    CHECK(light != nullptr);
    const std::string label = std::string("area_light.json ") +
      (light->GetShape() == vtkPenumbraAreaLight::Line ? "line" : "rectangle");
    const int original = light->GetSamplesPerAxis();
    for (int k : { 4, 8, 16 })
    {
      light->SetSamplesPerAxis(k);
      RUN(CompareWithReference(label, frame, light, 128, 0.05));
    }
    for (int grid : { 1, 7, 512 })
    {
      RUN(CompareWithReference(label, frame, light, grid, 0.05));
    }
    light->SetSamplesPerAxis(original);
  }
  RUN(CheckOverflowAndOtherLights(frame));
  RUN(CheckComputeFallback(frame, vtkPenumbraAreaLight::SafeDownCast(frame.Pass->GetLight(0))));
  return EXIT_SUCCESS;
}

// Renders a scene file whose first light is an area light and compares GEARS with the
// reference for it at its own k.
int CheckSceneLight(const std::string& file, vtkPenumbraSceneReader* reader, Frame& frame,
  vtkPenumbraAreaLight*& light, double maxUncertainShare)
{
  vtkSmartPointer<vtkRenderer> renderer = ReadScene(file, reader);
  CHECK(renderer != nullptr);
  RUN(RenderFrame(renderer, 160, 120, frame));
  light = vtkPenumbraAreaLight::SafeDownCast(frame.Pass->GetLight(0));
  CHECK(light != nullptr);
  return CompareWithReference(file, frame, light, 128, maxUncertainShare);
}

// (b) The city block under a 30 m x 20 m light (long building edges, contact with the
// ground, a 200 m scale), at k = 4, 8 and the file's 16.
int CheckCityScene()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  Frame frame;
  vtkPenumbraAreaLight* light = nullptr;
  RUN(CheckSceneLight("city_area_light.json", reader, frame, light, 0.05));
  for (int k : { 4, 8 })
  {
    light->SetSamplesPerAxis(k);
    RUN(CompareWithReference("city_area_light.json", frame, light, 128, 0.05));
  }
  return EXIT_SUCCESS;
}

// (b') A point light with a radius (vtkPenumbraShadowKeys::LIGHT_RADIUS): the pass shadows
// it as its disc, whose light samples are the cells of the k x k grid inside it; GEARS masks
// the grid and must give the reference's masks over the disc's samples, on both paths.
int CheckSphereLight()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  Frame frame;
  vtkPenumbraAreaLight* light = nullptr;
  RUN(CheckSceneLight("sphere_light.json", reader, frame, light, 0.2));
  CHECK(light->GetShape() == vtkPenumbraAreaLight::Disc && light->GetNumberOfSamples() == 52);
  for (int k : { 4, 16, 32 })
  {
    light->SetSamplesPerAxis(k);
    RUN(CompareWithReference("sphere_light.json disc", frame, light, 128, 0.2));
  }
  return EXIT_SUCCESS;
}

// (c) A 1e-6 m light: the same shadows as a point light at its centre, and GEARS matches
// the reference at the light's own k.
int CheckTinyLight()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  Frame frame;
  vtkPenumbraAreaLight* light = nullptr;
  RUN(CheckSceneLight("torture/tiny_area_light.json", reader, frame, light, 0.02));

  vtkNew<vtkPenumbraGearsShadows> gears;
  vtkNew<vtkFloatArray> soft;
  vtkPenumbraViewSamples* samples = frame.Pass->GetViewSamples();
  CHECK(gears->ComputeVisibility(nullptr, frame.Pass->GetGeometry(), samples, light, soft));
  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetConeAngle(180.0);
  point->SetPosition(light->GetPosition());
  point->SetFocalPoint(light->GetFocalPoint());
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(frame.Pass->GetGeometry());
  vtkNew<vtkFloatArray> hard;
  CHECK(reference->ComputeVisibility(samples, point, hard));
  vtkIdType differ = 0, shadowed = 0, partial = 0;
  for (vtkIdType s = 0; s < samples->GetNumberOfSamples(); ++s)
  {
    const float v = soft->GetValue(s);
    partial += v > 0.0f && v < 1.0f;
    if (reference->GetTies()->GetValue(s))
    {
      continue;
    }
    shadowed += hard->GetValue(s) == 0.0f && samples->IsValid(s);
    differ += hard->GetValue(s) != v;
  }
  std::printf("tiny light vs point light: %lld shadowed samples, %lld partial, %lld differ\n",
    static_cast<long long>(shadowed), static_cast<long long>(partial),
    static_cast<long long>(differ));
  CHECK(shadowed > 0);
  CHECK(differ == 0);
  return EXIT_SUCCESS;
}

// (d) A 1 km light 500 m up: every sample finite in [0, 1], no umbra on the ground, and the
// visibility varies slowly from pixel to pixel.
int CheckHugeLight()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  Frame frame;
  vtkPenumbraAreaLight* light = nullptr;
  RUN(CheckSceneLight("torture/huge_area_light.json", reader, frame, light, 0.05));
  vtkFloatArray* vis = frame.Pass->GetVisibility(0);
  vtkPenumbraViewSamples* samples = frame.Pass->GetViewSamples();
  CHECK(vis != nullptr);
  const int w = samples->GetWidth();
  const int h = samples->GetHeight();
  float lowest = 1.0f, largestStep = 0.0f;
  for (int y = 0; y < h; ++y)
  {
    for (int x = 0; x < w; ++x)
    {
      const vtkIdType s = samples->GetSampleIndex(x, y);
      const float v = vis->GetValue(s);
      CHECK(std::isfinite(v));
      if (!samples->IsValid(s))
      {
        CHECK(v == -1.0f);
        continue;
      }
      CHECK(v >= 0.0f && v <= 1.0f);
      const float nz = samples->GetNormals()->GetComponent(s, 2);
      if (nz < 0.99f)
      {
        continue; // the ball itself: its terminator is a hard facing edge
      }
      lowest = std::min(lowest, v);
      if (x + 1 < w && samples->IsValid(s + 1) &&
        samples->GetNormals()->GetComponent(s + 1, 2) >= 0.99f)
      {
        largestStep = std::max(largestStep, std::fabs(vis->GetValue(s + 1) - v));
      }
    }
  }
  std::printf("huge light: darkest ground sample %.3f, largest step between neighbours %.3f\n",
    lowest, largestStep);
  CHECK(lowest > 0.5f);       // a 0.6 m ball under a 1 km light: no umbra
  CHECK(largestStep < 0.05f); // smooth: no ground pixel jumps by 5 % of the light
  return EXIT_SUCCESS;
}

// (e) Straight occluder edge: a square light of width w facing down at height H, a plate at
// height hp covering x < 0, ground samples along y = 0. A light sample at su (along x) is
// visible from ground point x exactly when the ray passes the plate's edge plane x = 0 above
// the plate: x + (su - x) hp / H > 0, i.e. su > -x (H - hp) / hp. So visibility is the share
// of the k columns with su_i > -x (H - hp) / hp, and the penumbra spans the closed-form width
// w hp / (H - hp) (its sampled extent: (w - w / k) hp / (H - hp)).
int CheckPenumbraWidth()
{
  const double H = 4.0, hp = 2.0, w = 1.0;
  const int k = 16;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkPlaneSource> ground;
  ground->SetOrigin(-3, -2, 0);
  ground->SetPoint1(3, -2, 0);
  ground->SetPoint2(-3, 2, 0);
  vtkNew<vtkPlaneSource> plate;
  plate->SetOrigin(-5, -5, hp);
  plate->SetPoint1(0, -5, hp);
  plate->SetPoint2(-5, 5, hp);
  for (vtkPlaneSource* source : { ground.Get(), plate.Get() })
  {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(source->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    renderer->AddActor(actor);
  }
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  CHECK(geometry->Update(renderer));
  vtkNew<vtkPenumbraAreaLight> light;
  light->SetPosition(0, 0, H);
  light->SetFocalPoint(0, 0, 0);
  light->SetUp(0, 1, 0);
  light->SetWidth(w);
  light->SetHeight(w);
  light->SetSamplesPerAxis(k);

  // Ground samples every 1/256 m from x = -1 to 1 (offset so no sample sits on a column's
  // exact threshold); triangle id unknown (-1), so the ground's own triangles are tested too.
  const int count = 512;
  vtkNew<vtkPenumbraViewSamples> samples;
  samples->SetSize(count, 1);
  samples->SetCameraPosition(0, 0, 10);
  for (int i = 0; i < count; ++i)
  {
    const double p[3] = { -1.0 + (i + 0.37) / 256.0, 0.0, 0.0 };
    const double up[3] = { 0, 0, 1 };
    samples->SetSample(i, p, up, 0, -1);
  }
  vtkNew<vtkPenumbraGearsShadows> gears;
  vtkNew<vtkFloatArray> vis;
  CHECK(gears->ComputeVisibility(nullptr, geometry, samples, light, vis));
  double first = 1e300, last = -1e300;
  int wrong = 0;
  for (int i = 0; i < count; ++i)
  {
    double p[3];
    CHECK(samples->GetWorldPosition(i, p));
    const double threshold = -p[0] * (H - hp) / hp;
    int columns = 0;
    for (int c = 0; c < k; ++c)
    {
      columns += ((c + 0.5) / k - 0.5) * w > threshold;
    }
    const float expected = static_cast<float>(columns) / k;
    wrong += vis->GetValue(i) != expected;
    if (vis->GetValue(i) > 0.0f && vis->GetValue(i) < 1.0f)
    {
      first = std::min(first, p[0]);
      last = std::max(last, p[0]);
    }
  }
  const double sampled = (w - w / k) * hp / (H - hp);
  std::printf("penumbra of a straight edge: %d samples off the closed form; extent %.4f m "
              "(closed form %.4f m for k = %d, %.4f m for a continuous light), uncertain %lld\n",
    wrong, last - first, sampled, k, w * hp / (H - hp),
    static_cast<long long>(gears->GetNumberOfUncertainSamples()));
  CHECK(wrong == 0);
  CHECK(gears->GetNumberOfUncertainSamples() == 0);
  CHECK(gears->GetNumberOfTracedRays() == 0);
  // Within one sample spacing (1/256 m) at either end.
  CHECK(std::fabs((last - first) - sampled) <= 2.0 / 256.0);
  return EXIT_SUCCESS;
}

int CheckBadInput()
{
  vtkNew<vtkPenumbraGearsShadows> gears;
  vtkNew<vtkFloatArray> out;
  vtkNew<vtkPenumbraAreaLight> light;
  const int display = vtkObject::GetGlobalWarningDisplay();
  vtkObject::GlobalWarningDisplayOff();
  const int refused = gears->ComputeVisibility(nullptr, nullptr, nullptr, light, out);
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  vtkNew<vtkPenumbraViewSamples> samples;
  samples->SetSize(4, 4);
  light->SetWidth(-1.0);
  const int badLight = gears->ComputeVisibility(nullptr, geometry, samples, light, out);
  vtkObject::SetGlobalWarningDisplay(display);
  CHECK(refused == 0);
  CHECK(badLight == 0);
  // No samples, and no triangles at all: valid input, nothing to shadow.
  light->SetWidth(1.0);
  light->SetPosition(0, 0, 2);
  light->SetFocalPoint(0, 0, 0);
  vtkNew<vtkPenumbraViewSamples> none;
  CHECK(gears->ComputeVisibility(nullptr, geometry, none, light, out) == 1);
  CHECK(out->GetNumberOfTuples() == 0);
  const double p[3] = { 0.2, 0.1, 0.0 }, up[3] = { 0, 0, 1 };
  samples->SetSample(5, p, up, 0, -1);
  CHECK(gears->ComputeVisibility(nullptr, geometry, samples, light, out) == 1);
  CHECK(out->GetNumberOfTuples() == 16);
  CHECK(out->GetValue(5) == 1.0f);
  CHECK(out->GetValue(0) == -1.0f);
  vtkNew<vtkPenumbraTechniques> techniques;
  vtkNew<vtkRenderer> renderer;
  CHECK(techniques->Apply(renderer, "gears", "{\"samples\": 12}") == 0);
  CHECK(techniques->Apply(renderer, "gears", "{\"grid\": 0}") == 0);
  CHECK(techniques->Apply(renderer, "gears", "{\"gird\": 64}") == 0);
  CHECK(techniques->Apply(renderer, "gears", "{\"path\": \"cuda\"}") == 0);
  CHECK(techniques->Apply(renderer, "gears", "{\"samples\": 16, \"grid\": 64}") == 1);
  CHECK(techniques->Apply(renderer, "gears", "{\"path\": \"gpu\"}") == 1);
  CHECK(techniques->Apply(renderer, "raytraced", "{\"samples\": 8}") == 1);
  return EXIT_SUCCESS;
}
}

// A dense mesh (a 38 k-triangle isosurface) under a large area light, where a grid cell
// meets hundreds of tiny triangles: GEARS must give the ray tracer's visibility with its
// default TraceThreshold, the long-list cells masked from the casters' tree (the default,
// which skips nodes over blocked light samples) or traced whole, the others masked from
// their lists (both kinds of cell must occur, or the test proves nothing), and with every
// cell masked from its list.
int CheckDenseMesh()
{
  vtkNew<vtkPenumbraSceneReader> reader;
  vtkSmartPointer<vtkRenderer> renderer = ReadScene("iso_area_light.json", reader);
  CHECK(renderer != nullptr);
  Frame frame;
  RUN(RenderFrame(renderer, 96, 72, frame));
  auto* light = vtkPenumbraAreaLight::SafeDownCast(frame.Pass->GetLight(0));
  CHECK(light != nullptr);
  vtkPenumbraSceneGeometry* geometry = frame.Pass->GetGeometry();
  vtkPenumbraViewSamples* samples = frame.Pass->GetViewSamples();
  CHECK(geometry->GetNumberOfTriangles() > 30000);
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(geometry);
  vtkNew<vtkFloatArray> ref;
  CHECK(reference->ComputeVisibility(samples, light, ref));
  vtkNew<vtkUnsignedCharArray> ties;
  ties->DeepCopy(reference->GetTies());
  vtkNew<vtkTypeUInt32Array> refMasks;
  CHECK(reference->ComputeAreaMasks(samples, light, refMasks));
  const vtkIdType valid = samples->GetNumberOfValidSamples();
  const struct
  {
    double Threshold;
    int Dense;
  } runs[] = { { 0.5, vtkPenumbraGearsShadows::DENSE_TREE },
    { 0.5, vtkPenumbraGearsShadows::DENSE_TRACE }, { 0.0, vtkPenumbraGearsShadows::DENSE_TREE } };
  for (const auto& run : runs)
  {
    const double threshold = run.Threshold;
    vtkNew<vtkPenumbraGearsShadows> gears;
    gears->SetTraceThreshold(threshold);
    gears->SetDenseCells(run.Dense);
    gears->KeepMasksOn();
    vtkNew<vtkFloatArray> vis;
    CHECK(gears->ComputeVisibility(nullptr, geometry, samples, light, vis));
    vtkIdType differ = 0, penumbra = 0, maskDiffer = 0, masksCompared = 0;
    vtkTypeUInt32Array* masks = gears->GetMasks();
    CHECK(masks->GetNumberOfComponents() == refMasks->GetNumberOfComponents());
    for (vtkIdType s = 0; s < samples->GetNumberOfSamples(); ++s)
    {
      differ += vis->GetValue(s) != ref->GetValue(s);
      penumbra += ref->GetValue(s) > 0.0f && ref->GetValue(s) < 1.0f;
      if (!samples->IsValid(s) || ties->GetValue(s) || gears->GetUncertainSamples()->GetValue(s))
      {
        continue;
      }
      ++masksCompared;
      for (int w = 0; w < masks->GetNumberOfComponents(); ++w)
      {
        if (masks->GetTypedComponent(s, w) != refMasks->GetTypedComponent(s, w))
        {
          ++maskDiffer;
          break;
        }
      }
    }
    const vtkIdType traced = gears->GetNumberOfTracedCellSamples();
    const vtkIdType walked = gears->GetNumberOfTreeSamples();
    std::printf("dense mesh, trace threshold %.3f, dense cells %s: %lld triangles, valid %lld, "
                "penumbra %lld, traced cells' samples %lld, tree samples %lld, tri/cell max "
                "%lld, visibility differs in %lld, masks in %lld of %lld\n",
      threshold, run.Dense == vtkPenumbraGearsShadows::DENSE_TREE ? "tree" : "trace",
      static_cast<long long>(geometry->GetNumberOfTriangles()), static_cast<long long>(valid),
      static_cast<long long>(penumbra), static_cast<long long>(traced),
      static_cast<long long>(walked), static_cast<long long>(gears->GetMaxTrianglesPerCell()),
      static_cast<long long>(differ), static_cast<long long>(maskDiffer),
      static_cast<long long>(masksCompared));
    CHECK(differ == 0);
    CHECK(maskDiffer == 0);
    CHECK(masksCompared > valid / 2);
    CHECK(penumbra > valid / 20);
    const vtkIdType dense = run.Dense == vtkPenumbraGearsShadows::DENSE_TREE ? walked : traced;
    CHECK(threshold > 0.0 ? dense > 0 && dense < valid / 2 : traced == 0 && walked == 0);
    CHECK(traced + walked == dense);
  }
  return EXIT_SUCCESS;
}

int TestGearsShadows(int, char*[])
{
  RUN(CheckDenseMesh());
  RUN(CheckBadInput());
  RUN(CheckPenumbraWidth());
  RUN(CheckAreaLightScene());
  RUN(CheckCityScene());
  RUN(CheckSphereLight());
  RUN(CheckTinyLight());
  RUN(CheckHugeLight());
  return EXIT_SUCCESS;
}
