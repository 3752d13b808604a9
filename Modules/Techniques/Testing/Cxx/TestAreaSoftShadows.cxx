// The approximate soft-shadow techniques of area and linear lights on one perspective map
// (`pcss`: Fernando 2005; `single-sample-soft`: Brabec, "Shadow Techniques for Interactive
// and Real-Time Applications", PhD thesis, 2003, ch. 11), each against a closed form:
// - a straight edge over a plane under a rectangle and under a segment light: the visible
//   fraction across the penumbra is the part of the light on the lit side of the plane
//   through the edge and the sample, within the stated mean bound;
// - a tilted receiver without casters: the visible fraction is the part of the light above
//   its tangent plane (the reference's rule), equal to the converged reference;
// - a zero-size light is refused with a clear error, and a scene without casters renders.
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraMetrics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace
{
using penumbra_technique_tests::TestWindow;

// Collects the text of the error events it observes.
class ErrorText : public vtkCommand
{
public:
  static ErrorText* New() { return new ErrorText; }
  void Execute(vtkObject*, unsigned long, void* callData) override
  {
    this->Text += static_cast<const char*>(callData);
    this->Text += "\n";
  }
  std::string Text;
};

const char* const Techniques[] = { "pcss", "single-sample-soft" };

// The fraction of (a, b) uniform in [-1, 1]^2 with h0 + a alpha + b beta > 0, by midpoint
// integration over a fine grid (the oracle; the shaders use a closed form).
double FractionAbove(double h0, double alpha, double beta, bool line)
{
  const int n = 2000;
  const int rows = line ? 1 : n;
  long long above = 0;
  for (int j = 0; j < rows; ++j)
  {
    const double b = line ? 0.0 : (j + 0.5) / n * 2.0 - 1.0;
    // Count the a's with h0 + a alpha + b beta > 0 in closed form per row.
    const double c = h0 + b * beta;
    if (alpha == 0.0)
    {
      above += c > 0.0 ? n : 0;
      continue;
    }
    const double a0 = -c / alpha; // the row's boundary
    const double lo = alpha > 0.0 ? a0 : -1.0, hi = alpha > 0.0 ? 1.0 : a0;
    const double len = std::max(0.0, std::min(1.0, hi) - std::max(-1.0, lo));
    above += static_cast<long long>(std::llround(len / 2.0 * n));
  }
  return static_cast<double>(above) / (static_cast<double>(rows) * n);
}

vtkSmartPointer<vtkActor> PlaneActor(const double origin[3], const double p1[3], const double p2[3])
{
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(origin[0], origin[1], origin[2]);
  plane->SetPoint1(p1[0], p1[1], p1[2]);
  plane->SetPoint2(p2[0], p2[1], p2[2]);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(plane->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  return actor;
}

// An area light (rectangle or segment, `size` wide) at `position` facing `focal`.
vtkSmartPointer<vtkPenumbraAreaLight> AreaLight(
  const double position[3], const double focal[3], double size, bool line)
{
  auto light = vtkSmartPointer<vtkPenumbraAreaLight>::New();
  light->SetPosition(position[0], position[1], position[2]);
  light->SetFocalPoint(focal[0], focal[1], focal[2]);
  light->SetWidth(size);
  light->SetHeight(size);
  light->SetUp(1, 1, 0); // axes at 45 degrees to the edge: a trapezoidal penumbra
  light->SetSamplesPerAxis(8);
  if (line)
  {
    light->SetShapeToLine();
  }
  return light;
}

// The ground z = 0 under a thin plate at z = PlateHeight covering x < 0 (a straight edge
// along y), a light of `size` at height LightHeight over the edge, the camera looking down
// at the penumbra. Sample x at ground: the light point (cx + a hu_x + b hv_x) is hidden
// iff the segment meets the plate, i.e. its x at the plate's height is negative.
constexpr double PlateHeight = 1.0;
constexpr double LightHeight = 3.0;

int CheckStraightEdge(const char* technique, bool line, double size, double bound)
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  const double g0[3] = { -4, -3, 0 }, g1[3] = { 4, -3, 0 }, g2[3] = { -4, 3, 0 };
  const double q0[3] = { -6, -5, PlateHeight }, q1[3] = { 0, -5, PlateHeight },
               q2[3] = { -6, 5, PlateHeight };
  renderer->AddActor(PlaneActor(g0, g1, g2));
  renderer->AddActor(PlaneActor(q0, q1, q2));
  const double position[3] = { 0.1, 0.0, LightHeight }, focal[3] = { 0.1, 0.0, 0.0 };
  auto light = AreaLight(position, focal, size, line);
  renderer->AddLight(light);
  vtkCamera* cam = renderer->GetActiveCamera();
  cam->SetParallelProjection(true);
  cam->SetPosition(0.0, -0.4, 0.5); // under the plate's height: the ground is seen
  cam->SetFocalPoint(0.0, 0.0, 0.0);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(0.6);
  cam->SetClippingRange(0.01, 10.0);
  vtkNew<vtkPenumbraTechniques> techniques;
  // The map is fitted to the few metres seen (about a millimetre per texel): the penumbra
  // is some 300 texels wide, so the taps may reach that far.
  CHECK(techniques->Apply(renderer, technique, "{\"max_radius\": 1024}"));
  auto window = TestWindow(renderer, 160, 120);
  window->Render();
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(renderer);
  CHECK(pass && pass->GetVisibility(0) && pass->GetViewSamples());
  vtkFloatArray* vis = pass->GetVisibility(0);
  vtkPenumbraViewSamples* samples = pass->GetViewSamples();
  double u[3], v[3], n[3], centre[3];
  CHECK(light->GetAxes(u, v, n));
  light->GetCentre(centre);
  const double hu = 0.5 * size * u[0], hv = line ? 0.0 : 0.5 * size * v[0];
  // The oracle is checked against the converged reference on the same samples.
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(pass->GetGeometry());
  vtkNew<vtkFloatArray> exact;
  CHECK(reference->ComputeConvergedVisibility(samples, light, 64, exact));
  double sum = 0.0, worst = 0.0, oracle = 0.0;
  vtkIdType count = 0, penumbra = 0;
  for (vtkIdType i = 0; i < samples->GetNumberOfSamples(); ++i)
  {
    double p[3];
    if (!samples->GetWorldPosition(i, p) || std::abs(p[2]) > 1e-3 || std::abs(p[1]) > 0.3)
    {
      continue; // the ground near the middle of the edge only
    }
    // x of the segment p -> light point at the plate's height, >= 0 for visible points:
    // p_x + (l_x - p_x) t with t = PlateHeight / LightHeight.
    const double t = PlateHeight / LightHeight;
    const double h0 = p[0] * (1.0 - t) + centre[0] * t;
    const double expected = FractionAbove(h0, hu * t, hv * t, line);
    const double error = std::abs(vis->GetValue(i) - expected);
    sum += error;
    oracle = std::max(oracle, std::abs(exact->GetValue(i) - expected));
    worst = std::max(worst, error);
    ++count;
    penumbra += expected > 0.05 && expected < 0.95 ? 1 : 0;
  }
  CHECK(count > 1000 && penumbra > 200);
  const double mae = sum / count;
  std::printf(
    "%s, straight edge under a %s of %g m: %lld ground samples (%lld in the penumbra), "
    "MAE %.4f (bound %.3f), max %.3f; converged reference within %.3f of the closed form\n",
    technique, line ? "segment" : "rectangle", size, static_cast<long long>(count),
    static_cast<long long>(penumbra), mae, bound, worst, oracle);
  CHECK(oracle < 0.03);
  CHECK(mae <= bound);
  window->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// A receiver tilted 75 degrees about y, no caster at all, a 2 m light 2 m above the origin:
// most of the receiver sees the light cut by its tangent plane. The technique's value is the
// part of the light above that plane, as the converged reference counts it.
int CheckHorizon(const char* technique, bool line)
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  const double tilt = 75.0 * 3.14159265358979 / 180.0;
  const double dx = std::cos(tilt), dz = std::sin(tilt);
  const double o[3] = { -1.5 * dx, -1.5, -1.5 * dz }, p1[3] = { 1.5 * dx, -1.5, 1.5 * dz },
               p2[3] = { -1.5 * dx, 1.5, -1.5 * dz };
  renderer->AddActor(PlaneActor(o, p1, p2));
  const double position[3] = { 0.3, 0.0, 2.0 }, focal[3] = { 0.3, 0.0, 0.0 };
  auto light = AreaLight(position, focal, 2.0, line);
  renderer->AddLight(light);
  vtkCamera* cam = renderer->GetActiveCamera();
  cam->SetPosition(4.0 * dz + 1.0, 0.5, -4.0 * dx + 1.0);
  cam->SetFocalPoint(0, 0, 0);
  cam->SetViewUp(0, 0, 1);
  renderer->ResetCamera();
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, technique, "{}"));
  auto window = TestWindow(renderer, 128, 96);
  window->Render();
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(renderer);
  CHECK(pass && pass->GetVisibility(0));
  vtkFloatArray* vis = pass->GetVisibility(0);
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(pass->GetGeometry());
  vtkNew<vtkFloatArray> exact;
  CHECK(reference->ComputeConvergedVisibility(pass->GetViewSamples(), light, 64, exact));
  vtkNew<vtkPenumbraMetrics> metrics;
  CHECK(metrics->CompareSoft(vis, exact));
  vtkIdType partial = 0;
  for (vtkIdType i = 0; i < exact->GetNumberOfTuples(); ++i)
  {
    const float e = exact->GetValue(i);
    partial += e > 0.05f && e < 0.95f ? 1 : 0;
  }
  std::printf("%s, tilted receiver under a %s, no casters: %lld samples see part of the light, "
              "MAE %.4f against the converged reference\n",
    technique, line ? "segment" : "rectangle", static_cast<long long>(partial), metrics->GetMAE());
  CHECK(partial > 1000);
  // The reference's 64 (x 64) light samples resolve the fraction to 1/64.
  CHECK(metrics->GetMAE() < 0.01);
  window->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// A zero-size light is refused by the light's validity check with a clear error (the pass
// renders it unshadowed), never a crash or a NaN.
int CheckZeroSizeLight(const char* technique)
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  const double g0[3] = { -1, -1, 0 }, g1[3] = { 1, -1, 0 }, g2[3] = { -1, 1, 0 };
  renderer->AddActor(PlaneActor(g0, g1, g2));
  const double position[3] = { 0, 0, 2 }, focal[3] = { 0, 0, 0 };
  auto light = AreaLight(position, focal, 0.0, false);
  renderer->AddLight(light);
  renderer->ResetCamera();
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, technique, "{}"));
  auto window = TestWindow(renderer, 64, 48);
  // The errors go to an observer (ctest fails on error output).
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(renderer);
  CHECK(pass != nullptr && pass->GetTechnique() != nullptr);
  vtkNew<ErrorText> errors;
  pass->AddObserver(vtkCommand::ErrorEvent, errors);
  pass->GetTechnique()->AddObserver(vtkCommand::ErrorEvent, errors);
  window->Render();
  const std::string text = errors->Text;
  const size_t at = text.find("invalid area light: size must be positive");
  CHECK(at != std::string::npos);
  std::printf("%s, zero-size light refused: %s\n", technique,
    text.substr(at, text.find('\n', at) - at).c_str());
  window->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}
}

int TestAreaSoftShadows(int, char*[])
{
  // The straight-edge bounds: twice the MAE measured on Mesa llvmpipe plus
  // 0.005 (pcss 0.0078 and 0.0037, single-sample-soft 0.0004 and 0.0003).
  const double edgeBounds[2] = { 0.021, 0.0058 };
  for (int t = 0; t < 2; ++t)
  {
    RUN(CheckStraightEdge(Techniques[t], false, 1.0, edgeBounds[t]));
    RUN(CheckStraightEdge(Techniques[t], true, 1.0, edgeBounds[t]));
    RUN(CheckHorizon(Techniques[t], false));
    RUN(CheckHorizon(Techniques[t], true));
    RUN(CheckZeroSizeLight(Techniques[t]));
  }
  return EXIT_SUCCESS;
}
