// vtkPenumbraRoomSource: inward shell, closed shell, and a point light at the centre casting
// shadows on all six faces (checked by casting rays against the furniture), for the
// default and a non-cubic room; errors for bad parameters.
#include "SourcesTestUtilities.h"

#include "vtkCellData.h"
#include "vtkCellLocator.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPenumbraRoomSource.h"

#include <limits>
#include <set>

using namespace sources_test;

namespace
{
// Index of the room face a shell cell lies on, from its inward normal:
// 0 floor, 1 ceiling, 2 -x wall, 3 +x wall, 4 -y wall, 5 +y wall.
int FaceOf(const Vec3& inward)
{
  if (std::abs(inward[2]) > std::abs(inward[0]) && std::abs(inward[2]) > std::abs(inward[1]))
  {
    return inward[2] > 0 ? 0 : 1;
  }
  if (std::abs(inward[0]) > std::abs(inward[1]))
  {
    return inward[0] > 0 ? 2 : 3;
  }
  return inward[1] > 0 ? 4 : 5;
}

int CheckRoom(const double size[3])
{
  vtkNew<vtkPenumbraRoomSource> room;
  room->SetSize(size[0], size[1], size[2]);
  room->Update();
  vtkPolyData* out = room->GetOutput();
  CHECK(TrianglesOnly(out));
  CHECK(out->GetPoints()->GetDataType() == VTK_DOUBLE);
  CHECK(out->GetPointData()->GetNormals() != nullptr);
  CHECK(CountWindingMismatches(out) == 0);

  double bounds[6];
  out->GetBounds(bounds);
  CHECK(bounds[0] == -0.5 * size[0] && bounds[1] == 0.5 * size[0]);
  CHECK(bounds[2] == -0.5 * size[1] && bounds[3] == 0.5 * size[1]);
  CHECK(bounds[4] == 0.0 && bounds[5] == size[2]);

  double light[3];
  room->GetLightPosition(light);
  CHECK(light[0] == 0.0 && light[1] == 0.0 && light[2] == 0.5 * size[2]);
  const Vec3 centre = { light[0], light[1], light[2] };

  auto* partIds = vtkIntArray::SafeDownCast(out->GetCellData()->GetArray("PartId"));
  CHECK(partIds != nullptr);
  std::set<int> parts;
  for (vtkIdType c = 0; c < out->GetNumberOfCells(); ++c)
  {
    parts.insert(partIds->GetValue(c));
  }
  CHECK(parts == std::set<int>({ 0, 1, 2, 3, 4, 5, 6 }));

  vtkNew<vtkCellLocator> locator;
  locator->SetDataSet(out);
  locator->BuildLocator();

  int shadowed[6] = { 0, 0, 0, 0, 0, 0 };
  int lit[6] = { 0, 0, 0, 0, 0, 0 };
  for (vtkIdType c = 0; c < out->GetNumberOfCells(); ++c)
  {
    if (partIds->GetValue(c) != 0)
    {
      continue;
    }
    const Vec3 normal = WindingNormal(out, c);
    const Vec3 p = Centroid(out, c);
    // Inward: toward the room centre.
    CHECK(dot(normal, (centre - p)) > 0.0);

    // Is the segment from the light to (just short of) this shell cell blocked? The shell
    // is convex, so anything hit is furniture.
    const double eps = 1e-6;
    double end[3] = { p[0] + eps * (centre[0] - p[0]), p[1] + eps * (centre[1] - p[1]),
      p[2] + eps * (centre[2] - p[2]) };
    double t, x[3], pcoords[3];
    int subId;
    vtkIdType hit = -1;
    const bool blocked =
      locator->IntersectWithLine(light, end, 0.0, t, x, pcoords, subId, hit) != 0;
    CHECK(!blocked || partIds->GetValue(hit) > 0);
    (blocked ? shadowed : lit)[FaceOf(normal)]++;
  }
  const char* names[6] = { "floor", "ceiling", "-x wall", "+x wall", "-y wall", "+y wall" };
  for (int f = 0; f < 6; ++f)
  {
    std::cout << names[f] << ": " << shadowed[f] << " shadowed, " << lit[f] << " lit cells\n";
    CHECK(shadowed[f] > 0);
    CHECK(lit[f] > shadowed[f]);
  }

  // The shell alone is closed; each piece of furniture is closed too.
  room->GenerateFurnitureOff();
  room->Update();
  CHECK(CountOpenEdges(room->GetOutput()) == 0);
  // Inward normals enclose a negative volume.
  CHECK(SignedVolume(room->GetOutput()) < 0.0);
  CHECK(std::abs(-SignedVolume(room->GetOutput()) - size[0] * size[1] * size[2]) <
    1e-9 * size[0] * size[1] * size[2]);
  return EXIT_SUCCESS;
}

int TestShellResolution()
{
  vtkNew<vtkPenumbraRoomSource> room;
  room->GenerateFurnitureOff();
  room->SetShellCellSize(1.0);
  room->Update();
  // 10x10 floor and ceiling, 10x4 walls: (2*100 + 4*40) quads.
  CHECK(room->GetOutput()->GetNumberOfCells() == 2 * (2 * 100 + 4 * 40));
  room->SetShellCellSize(0.5);
  room->Update();
  CHECK(room->GetOutput()->GetNumberOfCells() == 2 * (2 * 400 + 4 * 160));
  return EXIT_SUCCESS;
}

int TestBadParameters()
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  vtkNew<vtkPenumbraRoomSource> room;
  room->SetSize(10, -10, 4);
  CHECK(ExpectFailure(room, "Size must be finite and > 0"));
  room->SetSize(10, 10, 0);
  CHECK(ExpectFailure(room, "Size must be finite and > 0"));
  room->SetSize(nan, 10, 4);
  CHECK(ExpectFailure(room, "Size must be finite and > 0"));
  room->SetSize(10, 10, 4);
  room->SetShellCellSize(0.0);
  CHECK(ExpectFailure(room, "ShellCellSize"));
  room->SetShellCellSize(inf);
  CHECK(ExpectFailure(room, "ShellCellSize"));
  room->SetShellCellSize(0.5);
  room->Update();
  CHECK(room->GetOutput()->GetNumberOfCells() > 0);
  return EXIT_SUCCESS;
}
}

int TestRoomSource(int, char*[])
{
  const double defaults[3] = { 10.0, 10.0, 4.0 };
  const double oblong[3] = { 6.0, 14.0, 3.0 };
  vtkNew<vtkPenumbraRoomSource> room;
  CHECK(room->GetSize()[0] == 10.0 && room->GetSize()[1] == 10.0 && room->GetSize()[2] == 4.0);
  CHECK(room->GetShellCellSize() == 0.5 && room->GetGenerateFurniture());
  RUN(CheckRoom(defaults));
  RUN(CheckRoom(oblong));
  RUN(TestShellResolution());
  RUN(TestBadParameters());
  return EXIT_SUCCESS;
}
