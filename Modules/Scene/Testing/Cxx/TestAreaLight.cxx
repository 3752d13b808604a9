// Area, linear and disc lights: the fixed sample positions every technique and the reference
// share (a disc's: the grid cells whose centre lies inside it, numbered row by row, the same
// through GetSamplePositions for any k), the emitter frame, its TransformMatrix, and the
// validity checks behind the scene files' errors.
#include "vtkDoubleArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkSmartPointer.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>

#include "PenumbraTestMacros.h"

namespace
{
int CheckDisc()
{
  vtkNew<vtkPenumbraAreaLight> disc;
  disc->SetPosition(1, 2, 3);
  disc->SetFocalPoint(1, 2, 0);
  disc->SetShapeToDisc();
  disc->SetWidth(2.0);
  CHECK(std::string(disc->GetShapeAsString()) == "Disc" && disc->GetNumberOfRows() == 8);
  const int expected[] = { 1, 4, 12, 52 }; // k = 1, 2, 4, 8
  int e = 0;
  for (int k : { 1, 2, 4, 8, 13, 64 })
  {
    disc->SetSamplesPerAxis(k);
    const int n = disc->GetNumberOfSamples();
    CHECK(k > 8 || n == expected[e++]);
    // The kept cells converge on the disc's share of its square, pi / 4.
    CHECK(k < 13 || std::fabs(static_cast<double>(n) / (k * k) - vtkMath::Pi() / 4) < 0.03);
    vtkNew<vtkDoubleArray> all;
    CHECK(disc->GetSamplePositions(k, all) && all->GetNumberOfTuples() == n);
    int index = 0;
    for (int j = 0; j < k; ++j)
    {
      int first, last;
      CHECK(disc->GetRowCells(j, first, last));
      CHECK(first + last == k - 1); // symmetric about the centre column
      for (int i = first; i <= last; ++i, ++index)
      {
        double p[3], q[3];
        CHECK(disc->GetSamplePosition(index, p) && disc->GetCellPosition(i, j, q));
        for (int c = 0; c < 3; ++c)
        {
          CHECK(p[c] == q[c] && p[c] == all->GetComponent(index, c)); // one rule, bit for bit
        }
        CHECK(std::hypot(p[0] - 1, p[1] - 2) <= 1.0 && p[2] == 3.0);
      }
    }
    CHECK(index == n);
    double p[3];
    CHECK(!disc->GetSamplePosition(n, p));
  }
  // The disc's size is its Width; its Height is not used.
  disc->SetHeight(0.0);
  CHECK(std::string(disc->GetValidityMessage()).empty());
  disc->SetWidth(0.0);
  CHECK(!std::string(disc->GetValidityMessage()).empty());

  // A sphere light's stand-in: positional lights only, a positive finite radius.
  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetPosition(0, 0, 4);
  point->SetFocalPoint(0, 0, 0);
  point->SetIntensity(0.5);
  vtkNew<vtkPenumbraAreaLight> standIn;
  CHECK(standIn->SetFromLightRadius(point, 0.25));
  CHECK(standIn->GetShape() == vtkPenumbraAreaLight::Disc && standIn->GetWidth() == 0.5);
  CHECK(standIn->GetIntensity() == 0.5 && standIn->GetPosition()[2] == 4.0);
  CHECK(std::string(standIn->GetValidityMessage()).empty());
  CHECK(!standIn->SetFromLightRadius(point, -1.0) && !standIn->SetFromLightRadius(point, NAN));
  point->SetPositional(false);
  CHECK(!standIn->SetFromLightRadius(point, 0.25));
  return EXIT_SUCCESS;
}
}

int TestAreaLight(int, char*[])
{
  RUN(CheckDisc());
  vtkNew<vtkPenumbraAreaLight> light;
  light->SetPosition(1, 2, 10);
  light->SetFocalPoint(1, 2, 0); // emits along -z
  light->SetUp(0, 1, 0);
  light->SetWidth(4.0);
  light->SetHeight(2.0);
  light->SetSamplesPerAxis(4);
  CHECK(std::string(light->GetValidityMessage()).empty());
  CHECK(light->GetNumberOfSamples() == 16);

  double u[3], v[3], n[3];
  CHECK(light->GetAxes(u, v, n));
  CHECK(std::fabs(n[2] + 1.0) < 1e-15 && std::fabs(v[1] - 1.0) < 1e-15);
  CHECK(std::fabs(vtkMath::Dot(u, v)) < 1e-15 && std::fabs(vtkMath::Dot(u, n)) < 1e-15);
  CHECK(std::fabs(u[0] + 1.0) < 1e-15); // U = V x N = y x -z = -x

  // Cell centres of a 4 x 4 grid over 4 x 2: offsets along U are -1.5, -0.5, 0.5, 1.5 and
  // along V -0.75, -0.25, 0.25, 0.75; their mean is the centre.
  double mean[3] = { 0, 0, 0 };
  for (int s = 0; s < 16; ++s)
  {
    double p[3];
    CHECK(light->GetSamplePosition(s, p));
    const double su = -(p[0] - 1.0); // along U = -x
    const double sv = p[1] - 2.0;
    CHECK(std::fabs(su - (-1.5 + (s % 4))) < 1e-12);
    CHECK(std::fabs(sv - (-0.75 + 0.5 * (s / 4))) < 1e-12);
    CHECK(p[2] == 10.0);
    for (int c = 0; c < 3; ++c)
    {
      mean[c] += p[c] / 16.0;
    }
  }
  CHECK(std::fabs(mean[0] - 1.0) < 1e-12 && std::fabs(mean[1] - 2.0) < 1e-12);
  double p[3];
  CHECK(!light->GetSamplePosition(16, p) && !light->GetSamplePosition(-1, p));

  // A line has k samples along U only.
  light->SetShapeToLine();
  CHECK(light->GetNumberOfSamples() == 4);
  CHECK(light->GetSamplePosition(3, p) && std::fabs(p[1] - 2.0) < 1e-15);

  // Up parallel to the emission direction still gives an orthonormal frame.
  light->SetUp(0, 0, 5);
  CHECK(light->GetAxes(u, v, n));
  CHECK(std::fabs(vtkMath::Norm(u) - 1.0) < 1e-12 && std::fabs(vtkMath::Dot(v, n)) < 1e-12);

  // Clones keep the extent (lights get cloned by VTK passes).
  vtkSmartPointer<vtkLight> clone = vtkSmartPointer<vtkLight>::Take(light->ShallowClone());
  auto* area = vtkPenumbraAreaLight::SafeDownCast(clone);
  CHECK(area && area->GetWidth() == 4.0 && area->GetShape() == vtkPenumbraAreaLight::Line);

  // Invalid lights explain themselves.
  light->SetShapeToRectangle();
  light->SetWidth(0.0);
  CHECK(std::string(light->GetValidityMessage()).find("positive") != std::string::npos);
  light->SetWidth(std::numeric_limits<double>::quiet_NaN());
  CHECK(std::string(light->GetValidityMessage()).find("finite") != std::string::npos);
  light->SetWidth(1e-6); // tiny is valid
  light->SetHeight(1e-6);
  CHECK(std::string(light->GetValidityMessage()).empty());
  light->SetFocalPoint(1, 2, 10);
  CHECK(std::string(light->GetValidityMessage()).find("direction") != std::string::npos);

  // A TransformMatrix moves the emitter like a light placed at the transformed pose: a
  // quarter turn about z and a shift (the camera-light case).
  vtkNew<vtkPenumbraAreaLight> local;
  local->SetPosition(1, 2, 10);
  local->SetFocalPoint(1, 2, 0);
  local->SetUp(0, 1, 0);
  local->SetWidth(4.0);
  local->SetHeight(2.0);
  local->SetSamplesPerAxis(3);
  vtkNew<vtkMatrix4x4> motion;
  const double rows[16] = { 0, -1, 0, 5, 1, 0, 0, -3, 0, 0, 1, 7, 0, 0, 0, 1 };
  motion->DeepCopy(rows);
  local->SetTransformMatrix(motion);
  CHECK(std::string(local->GetValidityMessage()).empty());
  vtkNew<vtkPenumbraAreaLight> placed; // the same pose without a matrix
  placed->SetPosition(5 - 2, -3 + 1, 17);
  placed->SetFocalPoint(5 - 2, -3 + 1, 7);
  placed->SetUp(-1, 0, 0);
  placed->SetWidth(4.0);
  placed->SetHeight(2.0);
  placed->SetSamplesPerAxis(3);
  double centre[3];
  local->GetCentre(centre);
  CHECK(centre[0] == 3.0 && centre[1] == -2.0 && centre[2] == 17.0);
  for (int s = 0; s < 9; ++s)
  {
    double a[3], b[3];
    CHECK(local->GetSamplePosition(s, a) && placed->GetSamplePosition(s, b));
    CHECK(std::sqrt(vtkMath::Distance2BetweenPoints(a, b)) < 1e-12);
  }
  // A scaling matrix would change the size: refused with a clear message.
  motion->SetElement(0, 1, -2.0);
  local->SetTransformMatrix(motion);
  CHECK(std::string(local->GetValidityMessage()).find("rotation") != std::string::npos);
  return EXIT_SUCCESS;
}
