// Helpers shared by the Penumbra::Sources tests.
#ifndef SourcesTestUtilities_h
#define SourcesTestUtilities_h

#include "vtkCellArray.h"
#include "vtkCleanPolyData.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkExecutive.h"
#include "vtkFeatureEdges.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataAlgorithm.h"
#include "vtkTestErrorObserver.h"

#include "PenumbraTestMacros.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <iostream>

#include <string>

namespace sources_test
{
using Vec3 = glm::dvec3;
using glm::cross;
using glm::dot;

// Updates `source`, expecting it to fail with an error mentioning `expected` and to leave
// an empty output. Errors are caught on the algorithm and on its executive (which adds
// "returned failure for request"), so nothing reaches the output window.
inline bool ExpectFailure(vtkPolyDataAlgorithm* source, const std::string& expected)
{
  vtkNew<vtkTest::ErrorObserver> observer;
  const unsigned long t1 = source->AddObserver(vtkCommand::ErrorEvent, observer);
  const unsigned long t2 = source->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, observer);
  source->Update();
  source->RemoveObserver(t1);
  source->GetExecutive()->RemoveObserver(t2);

  bool ok = true;
  if (!observer->GetError())
  {
    std::cerr << "expected an error containing \"" << expected << "\", got none" << std::endl;
    ok = false;
  }
  else if (observer->GetErrorMessage().find(expected) == std::string::npos)
  {
    std::cerr << "expected an error containing \"" << expected << "\", got:\n"
              << observer->GetErrorMessage() << std::endl;
    ok = false;
  }
  vtkPolyData* out = source->GetOutput();
  if (out->GetNumberOfPoints() != 0 || out->GetNumberOfCells() != 0)
  {
    std::cerr << "expected an empty output after \"" << expected << "\", got "
              << out->GetNumberOfPoints() << " points, " << out->GetNumberOfCells() << " cells"
              << std::endl;
    ok = false;
  }
  return ok;
}

inline Vec3 Point(vtkPolyData* pd, vtkIdType id)
{
  double p[3];
  pd->GetPoint(id, p);
  return Vec3(p[0], p[1], p[2]);
}

// True when every polygon is a triangle and there are no other cells.
inline bool TrianglesOnly(vtkPolyData* pd)
{
  if (pd->GetNumberOfCells() != pd->GetNumberOfPolys())
  {
    return false;
  }
  vtkNew<vtkIdList> ids;
  auto* polys = pd->GetPolys();
  for (vtkIdType c = 0; c < polys->GetNumberOfCells(); ++c)
  {
    polys->GetCellAtId(c, ids);
    if (ids->GetNumberOfIds() != 3)
    {
      return false;
    }
  }
  return true;
}

// Triangle c's vertices (polys only; polydata cell ids equal poly ids when all cells are polys).
inline std::array<Vec3, 3> Triangle(vtkPolyData* pd, vtkIdType c)
{
  vtkNew<vtkIdList> ids;
  pd->GetPolys()->GetCellAtId(c, ids);
  return { Point(pd, ids->GetId(0)), Point(pd, ids->GetId(1)), Point(pd, ids->GetId(2)) };
}

// Area-weighted normal of triangle c from its winding.
inline Vec3 WindingNormal(vtkPolyData* pd, vtkIdType c)
{
  const auto t = Triangle(pd, c);
  return cross(t[1] - t[0], t[2] - t[0]);
}

inline Vec3 Centroid(vtkPolyData* pd, vtkIdType c)
{
  const auto t = Triangle(pd, c);
  return (t[0] + t[1] + t[2]) / 3.0;
}

// Number of triangles whose point normals disagree with their winding.
inline vtkIdType CountWindingMismatches(vtkPolyData* pd)
{
  vtkDataArray* normals = pd->GetPointData()->GetNormals();
  vtkIdType bad = 0;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < pd->GetNumberOfPolys(); ++c)
  {
    const Vec3 w = WindingNormal(pd, c);
    pd->GetPolys()->GetCellAtId(c, ids);
    Vec3 n = { 0, 0, 0 };
    for (vtkIdType k = 0; k < 3; ++k)
    {
      const double* nk = normals->GetTuple3(ids->GetId(k));
      n += Vec3(nk[0], nk[1], nk[2]);
    }
    bad += dot(w, n) > 0.0 ? 0 : 1;
  }
  return bad;
}

// Number of zero-area triangles.
inline vtkIdType CountDegenerate(vtkPolyData* pd)
{
  vtkIdType degenerate = 0;
  for (vtkIdType c = 0; c < pd->GetNumberOfPolys(); ++c)
  {
    const Vec3 w = WindingNormal(pd, c);
    degenerate += dot(w, w) == 0.0 ? 1 : 0;
  }
  return degenerate;
}

// Boundary plus non-manifold edges after merging coincident points: 0 for a closed surface.
inline vtkIdType CountOpenEdges(vtkPolyData* pd)
{
  vtkNew<vtkCleanPolyData> clean;
  clean->SetInputData(pd);
  clean->PointMergingOn();
  clean->SetTolerance(0.0);
  vtkNew<vtkFeatureEdges> edges;
  edges->SetInputConnection(clean->GetOutputPort());
  edges->BoundaryEdgesOn();
  edges->NonManifoldEdgesOn();
  edges->FeatureEdgesOff();
  edges->ManifoldEdgesOff();
  edges->Update();
  return edges->GetOutput()->GetNumberOfLines();
}

// Signed volume enclosed by the triangles (positive when wound counter-clockwise from outside).
inline double SignedVolume(vtkPolyData* pd)
{
  double v = 0.0;
  for (vtkIdType c = 0; c < pd->GetNumberOfPolys(); ++c)
  {
    const auto t = Triangle(pd, c);
    v += dot(t[0], cross(t[1], t[2])) / 6.0;
  }
  return v;
}

// $PENUMBRA_DATA_DIR, or an empty string (with a message) when the test was run without it.
inline std::string DataDir()
{
  const char* dir = std::getenv("PENUMBRA_DATA_DIR");
  if (!dir || !*dir)
  {
    std::cerr << "PENUMBRA_DATA_DIR is not set; CMake passes it to this test" << std::endl;
    return std::string();
  }
  return dir;
}
}

#endif
