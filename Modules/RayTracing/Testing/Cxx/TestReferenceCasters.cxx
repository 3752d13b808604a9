// What is drawn, cast through the exact tracer. A wireframe square drawn 2 pixels wide over a
// plane, under a light straight above, shadows thin lines (the tubes' footprint, sample for
// sample), not a filled square; the same square as a surface shadows the filled square. Tubes
// belong to no drawn triangle, so samples whose triangle is unknown are shadowed by them too.
// The pieces a clipping plane leaves of a triangle never shadow that triangle's samples, and
// do shadow the others'.
#include "vtkCellArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkLight.h"
#include "vtkPenumbraReference.h"
#include "vtkPlane.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkProperty.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

using namespace penumbra_test;

namespace
{
constexpr int Res = 64; // samples over [-4, 4]^2: centres 1/16 from every multiple of 1/8
constexpr double Lo = -4.0;
constexpr double Hi = 4.0;
constexpr double Pi = 3.14159265358979323846;

// The square [-2, 2]^2 at height 1 as one polygon.
vtkSmartPointer<vtkActor> AddSquare(vtkRenderer* renderer)
{
  vtkNew<vtkPoints> points;
  points->InsertNextPoint(-2, -2, 1);
  points->InsertNextPoint(2, -2, 1);
  points->InsertNextPoint(2, 2, 1);
  points->InsertNextPoint(-2, 2, 1);
  vtkNew<vtkCellArray> polys;
  const vtkIdType ids[4] = { 0, 1, 2, 3 };
  polys->InsertNextCell(4, ids);
  vtkNew<vtkPolyData> square;
  square->SetPoints(points);
  square->SetPolys(polys);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(square);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  renderer->AddActor(actor);
  return actor;
}

// Whether the tubes along the square's edges shadow ground point c straight below: within
// half a tube's width of an edge, along the edge's length (the caps are flat). A tube whose
// triangle has circumradius R is between 1.5 R and sqrt(3) R wide; `ambiguous` flags a
// sample in between.
bool InTubes(const double c[2], double halfWidthMin, double halfWidthMax, bool& ambiguous)
{
  bool inside = false;
  for (int axis = 0; axis < 2; ++axis)
  {
    const double along = c[1 - axis];
    if (!(std::fabs(along) < 2.0))
    {
      continue;
    }
    for (double edge : { -2.0, 2.0 })
    {
      const double d = std::fabs(c[axis] - edge);
      ambiguous = ambiguous || (d >= halfWidthMin && d <= halfWidthMax);
      inside = inside || d < halfWidthMin;
    }
  }
  return inside;
}

// A directional light straight above.
vtkSmartPointer<vtkLight> OverheadSun()
{
  auto sun = vtkSmartPointer<vtkLight>::New();
  sun->SetPositional(false);
  sun->SetPosition(0, 0, 1);
  sun->SetFocalPoint(0, 0, 0);
  return sun;
}

int Shadowed(
  vtkPenumbraReference* reference, vtkPenumbraViewSamples* samples, vtkLight* sun, vtkIdType& count)
{
  vtkNew<vtkFloatArray> vis;
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  count = 0;
  for (vtkIdType s = 0; s < vis->GetNumberOfTuples(); ++s)
  {
    count += vis->GetValue(s) == 0.0f ? 1 : 0;
  }
  return EXIT_SUCCESS;
}
int Wireframe()
{
  vtkNew<vtkRenderer> renderer;
  auto ground = AddRectangle(renderer, -4, 4, -4, 4, 0);
  auto square = AddSquare(renderer);
  square->GetProperty()->SetRepresentationToWireframe();
  square->GetProperty()->SetLineWidth(2.0);
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  geometry->SetPixelSize(0.125); // tubes 0.25 wide
  CHECK(geometry->Update(renderer));
  CHECK(geometry->GetPropTriangleCount(1) == 4 * 8);
  const double zero[3] = { 0, 0, 0 };
  vtkNew<vtkPenumbraViewSamples> samples;
  FillGroundSamples(samples, geometry, geometry->GetPropIndex(ground), zero, Res, Lo, Hi);

  vtkSmartPointer<vtkLight> sun = OverheadSun();
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(geometry);
  vtkNew<vtkFloatArray> vis;
  CHECK(reference->ComputeVisibility(samples, sun, vis));

  const double r = Pi * 0.25 / (3.0 * std::sqrt(3.0)); // the tubes' circumradius
  bool ambiguous = false;
  vtkIdType expected = 0, shadowed = 0, bad = 0;
  for (int j = 0; j < Res; ++j)
  {
    for (int i = 0; i < Res; ++i)
    {
      double c[2];
      PixelCentre(i, j, Res, Lo, Hi, c);
      const bool shadow = InTubes(c, 0.75 * r, 0.5 * std::sqrt(3.0) * r, ambiguous);
      const float v = vis->GetValue(j * Res + i);
      expected += shadow ? 1 : 0;
      shadowed += v == 0.0f ? 1 : 0;
      bad += (shadow ? v != 0.0f : v != 1.0f) ? 1 : 0;
    }
  }
  std::cout << "wireframe: shadowed " << shadowed << ", tube footprint " << expected << "\n";
  CHECK(!ambiguous);
  CHECK(expected == 4 * 2 * 32 - 4); // two sample rows per edge, inner corners counted once
  CHECK(bad == 0 && shadowed == expected);
  CHECK(reference->GetNumberOfTies() == 0);

  // Samples whose triangle is unknown (-1) are shadowed by tubes all the same: a tube
  // belongs to no drawn triangle, so it is nobody's own triangle.
  vtkIdTypeArray* triangles = samples->GetTriangleIds();
  for (vtkIdType s = 0; s < triangles->GetNumberOfTuples(); ++s)
  {
    triangles->SetValue(s, -1);
  }
  triangles->Modified();
  vtkIdType unknownOwn = 0;
  RUN(Shadowed(reference, samples, sun, unknownOwn));
  CHECK(unknownOwn == expected);

  // The same square as a surface shadows the filled square: 32 x 32 samples.
  square->GetProperty()->SetRepresentationToSurface();
  CHECK(geometry->Update(renderer));
  FillGroundSamples(samples, geometry, geometry->GetPropIndex(ground), zero, Res, Lo, Hi);
  vtkIdType filled = 0;
  RUN(Shadowed(reference, samples, sun, filled));
  std::cout << "surface: shadowed " << filled << "\n";
  CHECK(filled == 32 * 32);
  return EXIT_SUCCESS;
}

// Samples just below a square cut in half by a clipping plane (its two drawn triangles keep
// receiving, their pieces cast), under a light straight above: each sample's ray meets the
// piece above it at a distance far beyond the tie band. A sample labelled with the drawn
// triangle that owns that piece is lit (its own pieces never block); labelled with the other
// triangle, it is shadowed.
int OwnPieces()
{
  vtkNew<vtkRenderer> renderer;
  auto square = AddRectangle(renderer, -1, 1, -1, 1, 0);
  vtkNew<vtkPlane> plane;
  plane->SetOrigin(0.3, 0, 0);
  plane->SetNormal(-1, 0, 0); // keeps x <= 0.3
  square->GetMapper()->AddClippingPlane(plane);
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  CHECK(geometry->Update(renderer));
  CHECK(
    geometry->GetPropTriangleCount(0) > 2 && !geometry->IsOccluder(0) && !geometry->IsOccluder(1));

  // Below the kept half of triangle 0 (vtkPlaneSource: 0 = (-1,-1) (1,-1) (1,1)), and below
  // the clipped-away part (x > 0.3), where nothing casts.
  const double points[3][2] = { { 0.2, -0.6 }, { -0.5, -0.8 }, { 0.6, -0.2 } };
  const double down = 1e-3; // beyond the tie band (16 x 1e-5 x the scene diagonal)
  vtkNew<vtkPenumbraViewSamples> samples;
  samples->SetSize(3, 2);
  samples->SetOrigin(geometry->GetOrigin());
  samples->SetCameraPosition(0, 0, 100);
  const double up[3] = { 0, 0, 1 };
  for (int k = 0; k < 3; ++k)
  {
    const double p[3] = { points[k][0], points[k][1], -down };
    CHECK(FindTriangleXY(geometry, 0, p[0], p[1]) == 0);
    samples->SetSample(k, p, up, 0, 0);     // labelled with its own triangle
    samples->SetSample(3 + k, p, up, 0, 1); // labelled with the other one
  }
  vtkSmartPointer<vtkLight> sun = OverheadSun();
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(geometry);
  vtkNew<vtkFloatArray> vis;
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  CHECK(vis->GetValue(0) == 1.0f && vis->GetValue(1) == 1.0f); // own pieces never block
  CHECK(vis->GetValue(3) == 0.0f && vis->GetValue(4) == 0.0f); // another triangle's do
  CHECK(vis->GetValue(2) == 1.0f && vis->GetValue(5) == 1.0f); // clipped away: lit
  CHECK(reference->GetNumberOfTies() == 0);
  return EXIT_SUCCESS;
}
} // namespace

int TestReferenceCasters(int, char*[])
{
  RUN(Wireframe());
  RUN(OwnPieces());
  return EXIT_SUCCESS;
}
