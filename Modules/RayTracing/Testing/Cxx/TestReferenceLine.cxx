// The exact linear-light reference (vtkPenumbraLineReference) against closed forms: a
// straight occluder edge under a linear light parallel to the receiver gives a linear ramp,
// exactly (up to float32 sample positions), also at georeferenced coordinates; the sampled
// reference converges to it (error below 1 / (2k)); the tangent-plane rule cuts the light
// segment; lights that are off, invalid samples and bad input.
#include "vtkFloatArray.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraLineReference.h"
#include "vtkPenumbraReference.h"
#include "vtkPlaneSource.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

using namespace penumbra_test;

namespace
{
// The straight edge of PenumbraReferenceScenes.h (closed-form ramp).
using namespace penumbra_test::straight_edge;

int EdgeRamp(const double offset[3], double tolerance)
{
  vtkNew<vtkRenderer> renderer;
  auto ground = AddRectangle(renderer, -10, 10, -10, 10, 0, offset);
  AddRectangle(renderer, -20, 0, -20, 20, h, offset);
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  CHECK(geometry->Update(renderer));

  vtkNew<vtkPenumbraViewSamples> samples;
  samples->SetSize(LineSamples, 1);
  samples->SetOrigin(geometry->GetOrigin());
  samples->SetCameraPosition(offset[0], offset[1] - 3, offset[2] + 10);
  const int groundIndex = geometry->GetPropIndex(ground);
  const double up[3] = { 0, 0, 1 };
  for (int i = 0; i < LineSamples; ++i)
  {
    const double p[3] = { offset[0] + SampleX(i), offset[1], offset[2] };
    samples->SetSample(i, p, up, groundIndex, FindTriangleXY(geometry, groundIndex, p[0], p[1]));
  }
  vtkNew<vtkPenumbraAreaLight> light;
  light->SetShapeToLine();
  light->SetPosition(offset[0], offset[1], offset[2] + H);
  light->SetFocalPoint(offset[0], offset[1], offset[2]);
  light->SetUp(0, 1, 0);
  light->SetWidth(W);
  double u[3], v[3], n[3];
  CHECK(light->GetAxes(u, v, n));
  CHECK(std::fabs(std::fabs(u[0]) - 1.0) < 1e-12); // the segment runs across the edge

  vtkNew<vtkPenumbraLineReference> exact;
  exact->SetGeometry(geometry);
  vtkNew<vtkFloatArray> vis;
  CHECK(exact->ComputeVisibility(samples, light, vis));
  CHECK(exact->GetNumberOfTies() == 0);
  CHECK(vis->GetNumberOfTuples() == LineSamples);
  double worst = 0.0;
  for (int i = 0; i < LineSamples; ++i)
  {
    worst = std::max(worst, std::fabs(vis->GetValue(i) - Ramp(SampleX(i))));
  }
  std::cout << "offset " << offset[0] << ": exact max |v - ramp| = " << worst << ", "
            << exact->GetNumberOfCandidates() << " candidate triangles in "
            << exact->GetLastTimeMs() << " ms\n";
  CHECK(worst <= tolerance);

  // The sampled reference at k cell centres along the line converges to it: below 1/(2k),
  // and at k = 32 closer than at k = 8.
  vtkNew<vtkPenumbraReference> sampled;
  sampled->SetGeometry(geometry);
  double errorAt[2] = { 0, 0 };
  const int ks[2] = { 8, 32 };
  for (int which = 0; which < 2; ++which)
  {
    vtkNew<vtkFloatArray> approx;
    CHECK(sampled->ComputeConvergedVisibility(samples, light, ks[which], approx));
    for (int i = 0; i < LineSamples; ++i)
    {
      errorAt[which] =
        std::max(errorAt[which], std::fabs(double(approx->GetValue(i)) - vis->GetValue(i)));
    }
    std::cout << "  sampled k = " << ks[which] << ": max |v_k - exact| = " << errorAt[which]
              << "\n";
    CHECK(errorAt[which] <= 0.5 / ks[which] + tolerance);
  }
  CHECK(errorAt[1] < errorAt[0]);
  // Building once, reusing after.
  CHECK(exact->ComputeVisibility(samples, light, vis));
  CHECK(exact->GetNumberOfBuilds() == 1);
  return EXIT_SUCCESS;
}

// A wall sample at x = 0 facing +x, above the occluder: the tangent plane keeps the half
// x > 0 of the light, nothing blocks it, so 0.5; a light that is off gives 1; an invalid
// sample -1; bad input fails with a message and no crash.
int Rules()
{
  const double zero[3] = { 0, 0, 0 };
  vtkNew<vtkRenderer> renderer;
  auto ground = AddRectangle(renderer, -10, 10, -10, 10, 0, zero);
  AddRectangle(renderer, -20, 0, -20, 20, h, zero);
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  CHECK(geometry->Update(renderer));
  vtkNew<vtkPenumbraViewSamples> samples;
  samples->SetSize(3, 1);
  samples->SetOrigin(geometry->GetOrigin());
  samples->SetCameraPosition(5, 0, 3);
  const double wall[3] = { 0, 0, 3 }, east[3] = { 1, 0, 0 };
  samples->SetSample(0, wall, east, geometry->GetPropIndex(ground), -1);
  const double under[3] = { -1, 0, 0 }, up[3] = { 0, 0, 1 };
  const int groundIndex = geometry->GetPropIndex(ground);
  samples->SetSample(1, under, up, groundIndex, FindTriangleXY(geometry, groundIndex, -1, 0));
  // Sample 2 stays invalid (prop -1).
  vtkNew<vtkPenumbraAreaLight> light;
  light->SetShapeToLine();
  light->SetPosition(0, 0, H);
  light->SetFocalPoint(0, 0, 0);
  light->SetUp(0, 1, 0);
  light->SetWidth(W);
  vtkNew<vtkPenumbraLineReference> exact;
  vtkNew<ErrorCounter> errors;
  exact->AddObserver(vtkCommand::ErrorEvent, errors);
  vtkNew<vtkFloatArray> vis;
  CHECK(!exact->ComputeVisibility(samples, light, vis)); // no geometry
  CHECK(std::string(exact->GetErrorMessage()).find("SetGeometry") != std::string::npos);
  exact->SetGeometry(geometry);
  CHECK(exact->ComputeVisibility(samples, light, vis));
  CHECK(std::fabs(vis->GetValue(0) - 0.5) < 1e-6);
  CHECK(vis->GetValue(1) == 0.0f); // under the occluder, x = -1: umbra
  CHECK(vis->GetValue(2) == -1.0f);
  light->SwitchOff();
  CHECK(exact->ComputeVisibility(samples, light, vis));
  CHECK(vis->GetValue(0) == 1.0f && vis->GetValue(1) == 1.0f && vis->GetValue(2) == -1.0f);
  light->SwitchOn();
  light->SetShapeToRectangle();
  CHECK(!exact->ComputeVisibility(samples, light, vis));
  CHECK(std::string(exact->GetErrorMessage()).find("Line") != std::string::npos);
  CHECK(!exact->ComputeVisibility(nullptr, light, vis));
  CHECK(errors->Count == 3);
  return EXIT_SUCCESS;
}
}

int TestReferenceLine(int, char*[])
{
  const double zero[3] = { 0, 0, 0 };
  RUN(EdgeRamp(zero, 1e-5));
  const double city[3] = { 4.5e5, 5.6e6, 120.0 }; // georeferenced coordinates (UTM-like)
  RUN(EdgeRamp(city, 1e-4));
  RUN(Rules());
  return EXIT_SUCCESS;
}
