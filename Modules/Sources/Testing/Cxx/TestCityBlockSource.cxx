// vtkPenumbraCityBlockSource: layout, determinism, offsets in double precision, closed
// outward-facing buildings, PartId, and errors for bad parameters.
#include "SourcesTestUtilities.h"

#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPenumbraCityBlockSource.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <map>
#include <vector>

using namespace sources_test;

namespace
{
struct PartStats
{
  vtkIdType Cells = 0;
  double Bounds[6] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MIN, VTK_DOUBLE_MAX, VTK_DOUBLE_MIN,
    VTK_DOUBLE_MAX, VTK_DOUBLE_MIN };
};

std::map<int, PartStats> StatsByPart(vtkPolyData* pd)
{
  std::map<int, PartStats> stats;
  auto* partIds = vtkIntArray::SafeDownCast(pd->GetCellData()->GetArray("PartId"));
  for (vtkIdType c = 0; c < pd->GetNumberOfPolys(); ++c)
  {
    PartStats& s = stats[partIds->GetValue(c)];
    ++s.Cells;
    for (const Vec3& p : Triangle(pd, c))
    {
      for (int a = 0; a < 3; ++a)
      {
        s.Bounds[2 * a] = std::min(s.Bounds[2 * a], p[a]);
        s.Bounds[2 * a + 1] = std::max(s.Bounds[2 * a + 1], p[a]);
      }
    }
  }
  return stats;
}

bool SamePoints(vtkPolyData* a, vtkPolyData* b)
{
  auto* pa = vtkDoubleArray::SafeDownCast(a->GetPoints()->GetData());
  auto* pb = vtkDoubleArray::SafeDownCast(b->GetPoints()->GetData());
  return pa && pb && pa->GetNumberOfTuples() == pb->GetNumberOfTuples() &&
    std::memcmp(pa->GetPointer(0), pb->GetPointer(0),
      sizeof(double) * 3 * static_cast<size_t>(pa->GetNumberOfTuples())) == 0;
}

int TestDefaults()
{
  vtkNew<vtkPenumbraCityBlockSource> city;
  CHECK(city->GetRows() == 4 && city->GetColumns() == 4);
  CHECK(city->GetSpacing() == 30.0);
  CHECK(city->GetFootprintMin() == 0.4 && city->GetFootprintMax() == 0.8);
  CHECK(city->GetMinHeight() == 8.0 && city->GetMaxHeight() == 40.0);
  CHECK(city->GetSeed() == 1 && city->GetGenerateGround() && city->GetGroundMargin() == 20.0);
  city->Update();
  vtkPolyData* out = city->GetOutput();

  CHECK(out->GetPoints()->GetDataType() == VTK_DOUBLE);
  CHECK(TrianglesOnly(out));
  CHECK(out->GetPointData()->GetNormals() != nullptr);
  CHECK(CountWindingMismatches(out) == 0);
  CHECK(vtkIntArray::SafeDownCast(out->GetCellData()->GetArray("PartId")) != nullptr);

  const auto stats = StatsByPart(out);
  // Ground plus one part per lot, numbered 1..Rows*Columns.
  CHECK(stats.size() == 17);
  CHECK(stats.begin()->first == 0 && stats.rbegin()->first == 16);
  // Ground: (4*30 + 2*20) / 30 -> 6 x 6 lot-sized quads.
  const PartStats& ground = stats.at(0);
  CHECK(ground.Cells == 2 * 6 * 6);
  CHECK(ground.Bounds[0] == -20.0 && ground.Bounds[1] == 140.0);
  CHECK(ground.Bounds[2] == -20.0 && ground.Bounds[3] == 140.0);
  CHECK(ground.Bounds[4] == 0.0 && ground.Bounds[5] == 0.0);

  int gables = 0;
  double lowest = VTK_DOUBLE_MAX, highest = VTK_DOUBLE_MIN;
  for (int part = 1; part <= 16; ++part)
  {
    const PartStats& b = stats.at(part);
    // A closed box is 12 triangles, a gable-roofed prism 16.
    CHECK(b.Cells == 12 || b.Cells == 16);
    gables += b.Cells == 16 ? 1 : 0;
    CHECK(b.Bounds[4] == 0.0);
    CHECK(b.Bounds[5] >= 8.0 && b.Bounds[5] <= 40.0);
    lowest = std::min(lowest, b.Bounds[5]);
    highest = std::max(highest, b.Bounds[5]);
    // Inside its own lot, with a footprint fraction in [0.4, 0.8] along x and y.
    const int row = (part - 1) / 4, col = (part - 1) % 4;
    CHECK(b.Bounds[0] >= col * 30.0 && b.Bounds[1] <= (col + 1) * 30.0);
    CHECK(b.Bounds[2] >= row * 30.0 && b.Bounds[3] <= (row + 1) * 30.0);
    const double fx = (b.Bounds[1] - b.Bounds[0]) / 30.0, fy = (b.Bounds[3] - b.Bounds[2]) / 30.0;
    CHECK(fx >= 0.4 - 1e-12 && fx <= 0.8 + 1e-12);
    CHECK(fy >= 0.4 - 1e-12 && fy <= 0.8 + 1e-12);
  }
  // Heights are random, not constant: the 16 draws should span a good part of [8, 40].
  CHECK(highest - lowest > 10.0);
  // With a 25% gable probability, seed 1 has some gables and some flat roofs.
  CHECK(gables > 0 && gables < 16);
  return EXIT_SUCCESS;
}

int TestBuildingsAreClosedAndOutward()
{
  for (const double gable : { 0.0, 1.0 })
  {
    vtkNew<vtkPenumbraCityBlockSource> city;
    city->GenerateGroundOff();
    city->SetGableRoofFraction(gable);
    city->SetRows(3);
    city->SetColumns(5);
    city->Update();
    vtkPolyData* out = city->GetOutput();
    const auto stats = StatsByPart(out);
    CHECK(stats.size() == 15 && stats.begin()->first == 1);
    for (const auto& entry : stats)
    {
      CHECK(entry.second.Cells == (gable == 1.0 ? 16 : 12));
    }
    CHECK(CountOpenEdges(out) == 0);
    CHECK(CountWindingMismatches(out) == 0);
    // Buildings are convex, so outward faces point away from the building's centre.
    auto* partIds = vtkIntArray::SafeDownCast(out->GetCellData()->GetArray("PartId"));
    for (vtkIdType c = 0; c < out->GetNumberOfPolys(); ++c)
    {
      const double* b = stats.at(partIds->GetValue(c)).Bounds;
      const Vec3 centre = { 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]) };
      CHECK(dot(WindingNormal(out, c), (Centroid(out, c) - centre)) > 0.0);
    }
    CHECK(SignedVolume(out) > 0.0);
  }
  return EXIT_SUCCESS;
}

int TestSeed()
{
  vtkNew<vtkPenumbraCityBlockSource> a;
  vtkNew<vtkPenumbraCityBlockSource> b;
  a->SetSeed(7);
  b->SetSeed(7);
  a->Update();
  b->Update();
  CHECK(a->GetOutput()->GetNumberOfPoints() > 0);
  CHECK(SamePoints(a->GetOutput(), b->GetOutput()));
  CHECK(a->GetOutput()->GetNumberOfCells() == b->GetOutput()->GetNumberOfCells());

  // Re-executing the same source is deterministic too (no hidden generator state).
  vtkNew<vtkPolyData> first;
  first->DeepCopy(a->GetOutput());
  a->Modified();
  a->Update();
  CHECK(SamePoints(first, a->GetOutput()));

  b->SetSeed(8);
  b->Update();
  CHECK(!SamePoints(a->GetOutput(), b->GetOutput()));
  return EXIT_SUCCESS;
}

int TestGeoreferencedOrigin()
{
  vtkNew<vtkPenumbraCityBlockSource> local;
  local->Update();
  vtkNew<vtkPenumbraCityBlockSource> geo;
  const double origin[3] = { 3.45e6, 5.43e6, 112.0 };
  geo->SetOrigin(origin);
  geo->Update();
  vtkPolyData* l = local->GetOutput();
  vtkPolyData* g = geo->GetOutput();
  CHECK(g->GetPoints()->GetDataType() == VTK_DOUBLE);
  CHECK(l->GetNumberOfPoints() == g->GetNumberOfPoints());

  double lb[6], gb[6];
  l->GetBounds(lb);
  g->GetBounds(gb);
  for (int i = 0; i < 6; ++i)
  {
    const double shifted = gb[i] - origin[i / 2];
    CHECK(std::abs(shifted - lb[i]) <= 1e-9 * std::max(1.0, std::abs(lb[i])));
  }
  // Point by point, to within double rounding at 5e6 m (float would be off by ~0.5 m).
  for (vtkIdType i = 0; i < l->GetNumberOfPoints(); ++i)
  {
    const Vec3 pl = Point(l, i), pg = Point(g, i);
    for (int a = 0; a < 3; ++a)
    {
      CHECK(std::abs((pg[a] - origin[a]) - pl[a]) < 1e-8);
    }
  }
  return EXIT_SUCCESS;
}

int TestParameters()
{
  vtkNew<vtkPenumbraCityBlockSource> city;
  city->SetRows(2);
  city->SetColumns(3);
  city->SetSpacing(50.0);
  city->SetMinHeight(12.5);
  city->SetMaxHeight(12.5);
  city->SetFootprintMin(0.5);
  city->SetFootprintMax(0.5);
  city->SetGroundMargin(0.0);
  city->SetGableRoofFraction(0.0);
  city->Update();
  const auto stats = StatsByPart(city->GetOutput());
  CHECK(stats.size() == 7);
  CHECK(stats.at(0).Cells == 2 * 3 * 2); // no margin: exactly one quad per lot
  for (int part = 1; part <= 6; ++part)
  {
    const double* b = stats.at(part).Bounds;
    CHECK(b[5] == 12.5);
    CHECK(std::abs((b[1] - b[0]) - 25.0) < 1e-12 && std::abs((b[3] - b[2]) - 25.0) < 1e-12);
  }
  // Gable roofs keep the requested top height (ridge) and stay within the range.
  city->SetGableRoofFraction(1.0);
  city->SetMinHeight(9.0);
  city->SetMaxHeight(11.0);
  city->Update();
  for (const auto& entry : StatsByPart(city->GetOutput()))
  {
    if (entry.first > 0)
    {
      CHECK(entry.second.Cells == 16);
      CHECK(entry.second.Bounds[5] >= 9.0 && entry.second.Bounds[5] <= 11.0);
    }
  }
  return EXIT_SUCCESS;
}

int TestBadParameters()
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  vtkNew<vtkPenumbraCityBlockSource> city;

  city->SetRows(0);
  CHECK(ExpectFailure(city, "Rows and Columns must be >= 1"));
  city->SetRows(4);
  city->SetColumns(-2);
  CHECK(ExpectFailure(city, "Rows and Columns must be >= 1"));
  city->SetColumns(100000);
  city->SetRows(100000);
  CHECK(ExpectFailure(city, "Rows*Columns must be <="));
  city->SetRows(4);
  city->SetColumns(4);

  // Recovers once the parameters are valid again.
  city->Update();
  CHECK(city->GetOutput()->GetNumberOfCells() > 0);

  city->SetSpacing(-30.0);
  CHECK(ExpectFailure(city, "Spacing must be"));
  city->SetSpacing(nan);
  CHECK(ExpectFailure(city, "Spacing must be"));
  city->SetSpacing(30.0);

  city->SetFootprintMin(0.9); // > FootprintMax
  CHECK(ExpectFailure(city, "Footprint fractions"));
  city->SetFootprintMin(0.0);
  CHECK(ExpectFailure(city, "Footprint fractions"));
  city->SetFootprintMin(0.4);
  city->SetFootprintMax(1.5);
  CHECK(ExpectFailure(city, "Footprint fractions"));
  city->SetFootprintMax(nan);
  CHECK(ExpectFailure(city, "Footprint fractions"));
  city->SetFootprintMax(0.8);

  city->SetMinHeight(-1.0);
  CHECK(ExpectFailure(city, "MinHeight"));
  city->SetMinHeight(50.0); // > MaxHeight
  CHECK(ExpectFailure(city, "MinHeight"));
  city->SetMinHeight(8.0);
  city->SetMaxHeight(inf);
  CHECK(ExpectFailure(city, "MaxHeight"));
  city->SetMaxHeight(40.0);

  city->SetGableRoofFraction(1.5);
  CHECK(ExpectFailure(city, "GableRoofFraction"));
  city->SetGableRoofFraction(nan);
  CHECK(ExpectFailure(city, "GableRoofFraction"));
  city->SetGableRoofFraction(0.25);
  city->SetGableRoofPitch(90.0);
  CHECK(ExpectFailure(city, "GableRoofPitch"));
  city->SetGableRoofPitch(30.0);

  city->SetGroundMargin(-5.0);
  CHECK(ExpectFailure(city, "GroundMargin"));
  city->SetGroundMargin(inf);
  CHECK(ExpectFailure(city, "GroundMargin"));
  city->SetGroundMargin(20.0);

  city->SetOrigin(3.45e6, nan, 0.0);
  CHECK(ExpectFailure(city, "Origin must be finite"));
  city->SetOrigin(0.0, 0.0, 0.0);

  city->Update();
  CHECK(city->GetOutput()->GetNumberOfCells() > 0);
  return EXIT_SUCCESS;
}
}

int TestCityBlockSource(int, char*[])
{
  RUN(TestDefaults());
  RUN(TestBuildingsAreClosedAndOutward());
  RUN(TestSeed());
  RUN(TestGeoreferencedOrigin());
  RUN(TestParameters());
  RUN(TestBadParameters());
  return EXIT_SUCCESS;
}
