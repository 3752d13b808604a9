// Helpers of the scene-geometry tests: small polydata built point by point, actors, and the
// world position of an extracted vertex.
#ifndef SceneGeometryTestUtilities_h
#define SceneGeometryTestUtilities_h

#include "vtkActor.h"
#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkNew.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkSmartPointer.h"

#include <cmath>
#include <initializer_list>
#include <vector>

namespace penumbra_scene_test
{
// A polydata with double-precision points (float would lose georeferenced detail).
inline vtkSmartPointer<vtkPolyData> MakePolyData(std::initializer_list<double> xyz)
{
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  const std::vector<double> v(xyz);
  for (size_t i = 0; i + 2 < v.size(); i += 3)
  {
    points->InsertNextPoint(v[i], v[i + 1], v[i + 2]);
  }
  poly->SetPoints(points);
  poly->SetVerts(vtkNew<vtkCellArray>());
  poly->SetLines(vtkNew<vtkCellArray>());
  poly->SetPolys(vtkNew<vtkCellArray>());
  poly->SetStrips(vtkNew<vtkCellArray>());
  return poly;
}

inline void AddCell(vtkCellArray* cells, std::initializer_list<vtkIdType> ids)
{
  const std::vector<vtkIdType> v(ids);
  cells->InsertNextCell(static_cast<vtkIdType>(v.size()), v.data());
}

inline vtkSmartPointer<vtkActor> MakeActor(vtkDataObject* data)
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputDataObject(data);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  return actor;
}

// World position of vertex `v` (0..2) of triangle `t`.
inline void WorldVertex(vtkPenumbraSceneGeometry* g, vtkIdType t, int v, double out[3])
{
  const double* o = g->GetOrigin();
  for (int c = 0; c < 3; ++c)
  {
    double corners[9];
    g->GetTriangle(t, corners);
    out[c] = corners[3 * v + c] + o[c];
  }
}

inline bool Near(const double a[3], double x, double y, double z, double tol)
{
  return std::fabs(a[0] - x) <= tol && std::fabs(a[1] - y) <= tol && std::fabs(a[2] - z) <= tol;
}

} // namespace penumbra_scene_test

#endif
