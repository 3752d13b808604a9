// Small analytic scenes shared by the reference tests: actors in a renderer (no window),
// view samples placed analytically on a ground plane, and an error observer so tests can
// check failures without VTK printing "ERROR:" (which ctest counts as a failure).
#ifndef PenumbraReferenceScenes_h
#define PenumbraReferenceScenes_h

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkDoubleArray.h"
#include "vtkNew.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataAlgorithm.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"

#include <cmath>
#include <string>

#include <algorithm>

namespace penumbra_test
{

// Adds `source`'s output as an actor at `position` (the actor matrix carries any offset).
inline vtkSmartPointer<vtkActor> AddActor(
  vtkRenderer* renderer, vtkPolyDataAlgorithm* source, const double position[3])
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(source->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->SetPosition(position[0], position[1], position[2]);
  renderer->AddActor(actor);
  return actor;
}

// Looks straight down the z axis at the origin from z = 10, in parallel projection showing
// `halfHeight` either side of the x axis.
inline void LookFromAbove(vtkRenderer* renderer, double halfHeight)
{
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->ParallelProjectionOn();
  camera->SetPosition(0, 0, 10);
  camera->SetFocalPoint(0, 0, 0);
  camera->SetViewUp(0, 1, 0);
  camera->SetParallelScale(halfHeight);
}

// Adds the rectangle [x0, x1] x [y0, y1] at height z (normal +z) as an actor at `position`
// (default the origin).
inline vtkSmartPointer<vtkActor> AddRectangle(vtkRenderer* renderer, double x0, double x1,
  double y0, double y1, double z, const double* position = nullptr)
{
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(x0, y0, z);
  plane->SetPoint1(x1, y0, z);
  plane->SetPoint2(x0, y1, z);
  const double zero[3] = { 0, 0, 0 };
  return AddActor(renderer, plane, position ? position : zero);
}

// The straight-edge penumbra both soft references are checked against. Ground z = 0;
// occluder half-plane x < 0 at height h = 1; a light of extent W = 2 along x at height
// H = 5, parallel to the ground. A ground point at x sees light point xl past the edge iff
// xl > -x (H - h) / h = -4 x, so the unoccluded fraction is clamp(0.5 + 2 x, 0, 1): a linear
// ramp of width W h / (H - h) = 0.5 (Brabec 2003, ch. 10, Eq. 10.1).
namespace straight_edge
{
constexpr double H = 5.0;
constexpr double h = 1.0;
constexpr double W = 2.0;
constexpr int LineSamples = 101; // x = -0.5 .. 0.5, step 0.01

inline double Ramp(double x)
{
  return std::min(1.0, std::max(0.0, 0.5 + x * (H - h) / (h * W)));
}

inline double SampleX(int i)
{
  return -0.5 + 0.01 * i;
}
} // namespace straight_edge

// Global index of a triangle of prop `propIndex` containing (x, y) in the xy projection
// (world coordinates), or -1. Inclusive edges: a point on a shared edge takes the first.
inline vtkIdType FindTriangleXY(
  vtkPenumbraSceneGeometry* geometry, int propIndex, double x, double y)
{
  double origin[3];
  geometry->GetOrigin(origin);
  const double px = x - origin[0];
  const double py = y - origin[1];
  const vtkIdType first = geometry->GetPropTriangleOffset(propIndex);
  const vtkIdType count = geometry->GetPropTriangleCount(propIndex);
  for (vtkIdType t = first; t < first + count; ++t)
  {
    double v[9];
    geometry->GetTriangle(t, v);
    double sign = 0.0;
    bool inside = true;
    for (int e = 0; e < 3 && inside; ++e)
    {
      const double* a = v + 3 * e;
      const double* b = v + 3 * ((e + 1) % 3);
      const double cross = (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
      if (cross != 0.0)
      {
        if (sign == 0.0)
        {
          sign = cross;
        }
        else if ((cross > 0.0) != (sign > 0.0))
        {
          inside = false;
        }
      }
    }
    if (inside)
    {
      return t;
    }
  }
  return -1;
}

// res x res samples at the pixel centres of the square [lo, hi]^2 on the plane z = 0 of the
// (offset) frame, seen orthographically from above: normal +z, prop `propIndex`.
inline void FillGroundSamples(vtkPenumbraViewSamples* samples, vtkPenumbraSceneGeometry* geometry,
  int propIndex, const double offset[3], int res, double lo, double hi)
{
  samples->SetSize(res, res);
  samples->SetOrigin(geometry->GetOrigin());
  samples->SetCameraPosition(offset[0], offset[1], offset[2] + 100.0);
  const double pixel = (hi - lo) / res;
  const double up[3] = { 0, 0, 1 };
  for (int j = 0; j < res; ++j)
  {
    for (int i = 0; i < res; ++i)
    {
      const double world[3] = { offset[0] + lo + (i + 0.5) * pixel,
        offset[1] + lo + (j + 0.5) * pixel, offset[2] };
      const vtkIdType tri = FindTriangleXY(geometry, propIndex, world[0], world[1]);
      samples->SetSample(samples->GetSampleIndex(i, j), world, up, propIndex, tri);
    }
  }
}

// Pixel centre (local coordinates, offset removed) of sample (i, j) of FillGroundSamples.
inline void PixelCentre(int i, int j, int res, double lo, double hi, double c[2])
{
  const double pixel = (hi - lo) / res;
  c[0] = lo + (i + 0.5) * pixel;
  c[1] = lo + (j + 0.5) * pixel;
}

// Counts errors reported to an object instead of printing them.
class ErrorCounter : public vtkCommand
{
public:
  static ErrorCounter* New() { return new ErrorCounter; }
  void Execute(vtkObject*, unsigned long, void* data) override
  {
    ++this->Count;
    this->Last = data ? static_cast<const char*>(data) : "";
  }
  int Count = 0;
  std::string Last;
};

} // namespace penumbra_test

#endif
