// vtkPenumbraTerrainSource on SainteHelens.dem from $PENUMBRA_DATA_DIR: full-resolution
// counts and ranges (true elevations, not offset by the image plane), subsampling that
// keeps the full extent, vertical scale, double-precision UTM coordinates, upward normals;
// errors for bad parameters and files.
#include "SourcesTestUtilities.h"

#include "vtkNew.h"
#include "vtkPenumbraTerrainSource.h"

#include <limits>
#include <string>

using namespace sources_test;

namespace
{
// SOURCES.md: 327 x 467 samples, spacing 30 m, origin (557945, 5107991.5), elevation
// 682..2543 m.
constexpr int NX = 327, NY = 467;
constexpr double X0 = 557945.0, Y0 = 5107991.5, DX = 30.0;
constexpr double ZMin = 682.0, ZMax = 2543.0;

int CheckSurface(vtkPolyData* out, int nx, int ny)
{
  CHECK(out->GetNumberOfPoints() == static_cast<vtkIdType>(nx) * ny);
  CHECK(out->GetNumberOfPolys() == 2 * static_cast<vtkIdType>(nx - 1) * (ny - 1));
  CHECK(TrianglesOnly(out));
  CHECK(out->GetPoints()->GetDataType() == VTK_DOUBLE);
  vtkDataArray* normals = out->GetPointData()->GetNormals();
  CHECK(normals != nullptr);
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    const double* n = normals->GetTuple3(i);
    CHECK(n[2] > 0.0);
    CHECK(std::abs(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0) < 1e-5);
  }
  for (vtkIdType c = 0; c < out->GetNumberOfPolys(); ++c)
  {
    CHECK(WindingNormal(out, c)[2] > 0.0);
  }
  // Central-difference normals may disagree with a facet across the sharpest ridges only
  // (138 of 303,832 triangles at full resolution).
  CHECK(CountWindingMismatches(out) <= out->GetNumberOfPolys() / 1000);
  // Full DEM extent whatever the sampling, to the last bit.
  double b[6];
  out->GetBounds(b);
  CHECK(b[0] == X0 && b[1] == X0 + (NX - 1) * DX);
  CHECK(b[2] == Y0 && b[3] == Y0 + (NY - 1) * DX);
  return EXIT_SUCCESS;
}

int TestFullResolution(const std::string& dem)
{
  vtkNew<vtkPenumbraTerrainSource> terrain;
  CHECK(terrain->GetVerticalScale() == 1.0 && terrain->GetSampleRate() == 1);
  terrain->SetFileName(dem.c_str());
  terrain->Update();
  vtkPolyData* out = terrain->GetOutput();
  RUN(CheckSurface(out, NX, NY));
  CHECK(out->GetNumberOfPolys() == 303832);
  double b[6];
  out->GetBounds(b);
  // True elevations: the reader's z = 682 image plane must not be added on top.
  CHECK(b[4] == ZMin && b[5] == ZMax);
  // Points are exactly on the 30 m UTM grid (float would round y to 0.5 m).
  const Vec3 p = Point(out, NX + 1);
  CHECK(p[0] == X0 + DX && p[1] == Y0 + DX);
  return EXIT_SUCCESS;
}

int TestSubsampled(const std::string& dem)
{
  vtkNew<vtkPenumbraTerrainSource> terrain;
  terrain->SetFileName(dem.c_str());
  terrain->SetSampleRate(4);
  terrain->Update();
  vtkPolyData* out = terrain->GetOutput();
  // 0, 4, ..., 324 and the last column 326; 0, 4, ..., 464 and the last row 466.
  RUN(CheckSurface(out, 83, 118));
  double b[6];
  out->GetBounds(b);
  std::cout << "SampleRate 4: z " << b[4] << " .. " << b[5] << std::endl;
  CHECK(b[4] >= ZMin && b[4] < ZMin + 20.0);
  CHECK(b[5] <= ZMax && b[5] > ZMax - 60.0);

  vtkNew<vtkPolyData> unscaled;
  unscaled->DeepCopy(out);
  terrain->SetVerticalScale(2.5);
  terrain->Update();
  out = terrain->GetOutput();
  RUN(CheckSurface(out, 83, 118));
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    const Vec3 s = Point(out, i), u = Point(unscaled, i);
    CHECK(s[0] == u[0] && s[1] == u[1]);
    CHECK(std::abs(s[2] - 2.5 * u[2]) <= 1e-9 * s[2]);
  }

  // A rate larger than the grid keeps just the corners.
  terrain->SetSampleRate(1000);
  terrain->Update();
  RUN(CheckSurface(terrain->GetOutput(), 2, 2));
  return EXIT_SUCCESS;
}

int TestBadParameters(const std::string& dataDir)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  vtkNew<vtkPenumbraTerrainSource> terrain;
  CHECK(ExpectFailure(terrain, "No FileName"));
  terrain->SetFileName((dataDir + "/volumes/missing.dem").c_str());
  CHECK(ExpectFailure(terrain, "does not exist"));
  terrain->SetFileName((dataDir + "/volumes/SainteHelens.dem").c_str());
  terrain->SetSampleRate(0);
  CHECK(ExpectFailure(terrain, "SampleRate must be >= 1"));
  terrain->SetSampleRate(-3);
  CHECK(ExpectFailure(terrain, "SampleRate must be >= 1"));
  terrain->SetSampleRate(8);
  terrain->SetVerticalScale(0.0);
  CHECK(ExpectFailure(terrain, "VerticalScale must be finite and > 0"));
  terrain->SetVerticalScale(-1.0);
  CHECK(ExpectFailure(terrain, "VerticalScale must be finite and > 0"));
  terrain->SetVerticalScale(nan);
  CHECK(ExpectFailure(terrain, "VerticalScale must be finite and > 0"));
  terrain->SetVerticalScale(1.0);
  terrain->Update();
  CHECK(terrain->GetOutput()->GetNumberOfCells() > 0);
  return EXIT_SUCCESS;
}
}

int TestTerrainSource(int, char*[])
{
  const std::string dataDir = DataDir();
  CHECK(!dataDir.empty());
  const std::string dem = dataDir + "/volumes/SainteHelens.dem";
  RUN(TestFullResolution(dem));
  RUN(TestSubsampled(dem));
  RUN(TestBadParameters(dataDir));
  return EXIT_SUCCESS;
}
