// vtkPenumbraMeshFileCheck: the hostile files that crashed or fooled VTK 9.1's readers are
// refused with a sentence that says what is wrong, and valid files pass.

#include "vtkCellArray.h"
#include "vtkNew.h"
#include "vtkPenumbraMeshFileCheck.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include "PenumbraTestMacros.h"

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

namespace
{
std::string Dir;

std::string Write(const std::string& name, const std::string& text)
{
  const std::string path = Dir + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// Empty string if the file passes, else the checker's message.
std::string Problem(const std::string& path)
{
  vtkNew<vtkPenumbraMeshFileCheck> check;
  check->SetFileName(path.c_str());
  const int ok = check->Check();
  return ok                                         ? std::string()
    : std::string(check->GetErrorMessage()).empty() ? "?"
                                                    : check->GetErrorMessage();
}

bool Contains(const std::string& s, const std::string& part)
{
  if (s.find(part) == std::string::npos)
  {
    std::cerr << "expected \"" << part << "\" in \"" << s << "\"\n";
    return false;
  }
  return true;
}

std::string PlyHeader(const char* format, int vertices, int faces)
{
  return std::string("ply\nformat ") + format + " 1.0\nelement vertex " + std::to_string(vertices) +
    "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
    std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

std::string LittleEndianTriangle()
{
  std::string body;
  const float v[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
  body.append(reinterpret_cast<const char*>(v), sizeof(v));
  body.push_back('\x03');
  const std::int32_t f[3] = { 0, 1, 2 };
  body.append(reinterpret_cast<const char*>(f), sizeof(f));
  return body;
}

int TestPly()
{
  const std::string good = PlyHeader("binary_little_endian", 3, 1) + LittleEndianTriangle();
  CHECK(Problem(Write("good.ply", good)).empty());
  CHECK(Problem(Write("ascii.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"))
          .empty());

  // A binary PLY cut short right after its header.
  CHECK(Contains(Problem(Write("cut.ply", PlyHeader("binary_little_endian", 3, 1))),
    "binary PLY ends inside element \"vertex\": the header promises 3 records of 12 bytes (36 "
    "bytes), only 0 bytes are left"));
  CHECK(Contains(Problem(Write("cutface.ply", good.substr(0, good.size() - 2))),
    "binary PLY ends inside \"face\" record 1 of 1"));
  CHECK(Contains(Problem(Write("huge.ply",
                   PlyHeader("binary_little_endian", 2000000000, 1) + LittleEndianTriangle())),
    "the header promises 2000000000 records"));
  std::string tooBig = PlyHeader("binary_little_endian", 3, 1);
  tooBig.replace(tooBig.find("vertex 3"), 8, "vertex 99999999999");
  CHECK(Contains(
    Problem(Write("toobig.ply", tooBig + LittleEndianTriangle())), "allowed: 0 to 2147483647"));
  CHECK(Contains(
    Problem(Write("index.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")),
    "vertex index 3 is outside the 3 vertices"));
  CHECK(
    Contains(Problem(Write("short.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n")),
      "\"vertex\" record 2 of 3 has too few values on its line (\"z\" is missing)"));
  CHECK(Contains(
    Problem(Write("list.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n9 0 1 2\n")),
    "list \"vertex_indices\" promises 9 items"));
  CHECK(Contains(
    Problem(Write("neg.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n")),
    "has the length -3"));
  CHECK(Contains(
    Problem(Write("nanidx.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 nan 2\n")),
    "vertex index nan is outside"));
  CHECK(Contains(Problem(Write("ended.ply", PlyHeader("ascii", 3, 1) + "0 0 0\n1 0 0\n")),
    "ASCII PLY ends before \"vertex\" record 3 of 3"));
  CHECK(Contains(
    Problem(Write("long.ply", PlyHeader("ascii", 3, 1) + "0 0 0" + std::string(5000, ' ') + "\n")),
    "longer than 4094 characters"));
  CHECK(Contains(Problem(Write("type.ply",
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n")),
    "unknown type \"float128\""));
  CHECK(Contains(
    Problem(Write("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n")), "no \"end_header\""));
  CHECK(Contains(Problem(Write("nover.ply", "ply\nformat ascii 1.0\nelement face 0\nend_header\n")),
    "no \"vertex\" element"));
  CHECK(Contains(Problem(Write("magic.ply", "plx\n")), "not a PLY file"));
  // Found by the fuzz run: a face element whose index list is misnamed crashed vtkPLYReader.
  std::string misnamed = PlyHeader("ascii", 3, 1);
  misnamed.replace(misnamed.find("vertex_indices"), 14, "vertex_indicec");
  CHECK(Contains(Problem(Write("misnamed.ply", misnamed + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")),
    "needs exactly one list property \"vertex_indices\""));
  return EXIT_SUCCESS;
}

int TestObj()
{
  CHECK(Problem(Write("good.obj",
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf -3 -2 -1\n"))
          .empty());
  // A face that indexes a missing vertex, which VTK's reader renders without a word.
  CHECK(Contains(Problem(Write("missing.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n")),
    "OBJ line 4: vertex 4 does not exist (the file has 3)"));
  CHECK(Contains(Problem(Write("vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/2 2/1 3/1\n")),
    "texture coordinate 2 does not exist (the file has 1)"));
  CHECK(Contains(Problem(Write("vn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n")),
    "normal 1 does not exist (the file has 0)"));
  CHECK(Contains(Problem(Write("rel.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n")),
    "relative vertex index -3 reaches before the first one (2 defined so far)"));
  CHECK(
    Contains(Problem(Write("zero.obj", "v 0 0 0\nf 0 1 1\n")), "index 0 (OBJ indices start at 1)"));
  CHECK(Contains(Problem(Write("word.obj", "v 0 0 0\nf 1 x 1\n")), "\"x\" is not a vertex index"));
  CHECK(Contains(Problem(Write("v.obj", "v 0 zero 0\n")), "a \"v\" needs 3 numbers"));
  return EXIT_SUCCESS;
}

// Found by the fuzz run: each of these crashed VTK 9.1's legacy reader or the surface filter.
int TestLegacy()
{
  const std::string head =
    "# vtk DataFile Version 3.0\nfuzz\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
    "0 0 0 1 0 0 0 1 0 0 0 1\n";
  CHECK(Problem(Write("good.vtk", head + "POLYGONS 2 8\n3 0 1 2\n3 0 1 3\n")).empty());
  CHECK(Contains(Problem(Write("count.vtk", head + "POLYGONS 2 8\n3 0 1 2\n3007 0 1 3\n")),
    "POLYGONS: cell 2 has the point count 3007"));
  CHECK(Contains(Problem(Write("negzero.vtk", head + "POLYGONS 2 8\n3 0 -0.0 2\n3 0 1 3\n")),
    "POLYGONS: cell 1 of 2: a point id is missing, not an integer"));
  CHECK(Contains(Problem(Write("id.vtk", head + "POLYGONS 1 4\n3 0 1 4\n")),
    "POLYGONS: cell 1 uses point 4 but there are only 4 points"));
  CHECK(Contains(Problem(Write("keyword.vtk",
                   head.substr(0, 61) + "x" + head.substr(61) + "POLYGONS 1 4\n3 0 1 2\n")),
    "unknown keyword \"POINTSx\""));
  CHECK(Contains(Problem(Write("size.vtk", head + "POLYGONS 1 5\n3 0 1 2\n")),
    "1 cells use 4 values, the header declares 5"));
  CHECK(Contains(
    Problem(Write("cut.vtk", head.substr(0, head.size() - 8))), "coordinate 9 of 12 is missing"));
  CHECK(Contains(Problem(Write("offsets.vtk",
                   "# vtk DataFile Version 5.1\nfuzz\nASCII\nDATASET POLYDATA\n"
                   "POINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 2 3\nOFFSETS vtktypeint64\n0 4\n"
                   "CONNECTIVITY vtktypeint64\n0 1 2\n")),
    "OFFSETS value 2 of 2 is missing or outside [0, 4)"));
  // Found by the fuzz run under AddressSanitizer: 2147483647 scalar components for 4 points
  // made vtkDataReader allocate and clear tens of gigabytes (49 s, then no surface).
  const std::string withPolys = head + "POLYGONS 1 4\n3 0 1 2\n";
  CHECK(Problem(Write("attrs.vtk",
                  withPolys +
                    "POINT_DATA 4\nSCALARS s float 1\nLOOKUP_TABLE default\n0 1 2 3\n"
                    "CELL_DATA 1\nFIELD f 1\nc 2 1 float\n5 6\nNORMALS n float\n0 0 1\n"))
          .empty());
  CHECK(Contains(
    Problem(Write("comps.vtk",
      withPolys + "POINT_DATA 4\nSCALARS s float 2147483647\nLOOKUP_TABLE default\n0 1 2 3\n")),
    "SCALARS components: 2147483647 is outside 1..4"));
  CHECK(Contains(Problem(Write("pdata.vtk",
                   withPolys + "POINT_DATA 5\nSCALARS s float\nLOOKUP_TABLE default\n0 1 2 3 4\n")),
    "POINT_DATA 5 does not match the 4 points"));
  CHECK(Contains(
    Problem(Write("field.vtk", withPolys + "CELL_DATA 1\nFIELD f 1\nc 1000 1000000 float\n1\n")),
    "FIELD array declares 1000000000 values, more than the file can hold"));
  const std::string grid =
    "# vtk DataFile Version 3.0\nfuzz\nASCII\nDATASET UNSTRUCTURED_GRID\n"
    "POINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n";
  CHECK(Problem(Write("tet.vtk", grid + "10\n")).empty());
  // A tetrahedron's four points typed as a voxel: the surface filter reads eight.
  vtkNew<vtkPenumbraSceneReader> reader;
  reader->GlobalWarningDisplayOff();
  Write("voxel.vtk", grid + "11\n");
  reader->SetFileName(Write("voxel.json", R"({"objects": [{"file": "voxel.vtk"}],
    "lights": [{"type": "point", "position": [0, 0, 1]}]})")
                        .c_str());
  CHECK(reader->Read() == 0);
  CHECK(Contains(reader->GetErrorMessage(), "cell 0 of type 11 has 4 points, the type needs 8"));
  return EXIT_SUCCESS;
}

int TestConnectivity()
{
  vtkNew<vtkPolyData> pd;
  vtkNew<vtkPoints> pts;
  pts->InsertNextPoint(0, 0, 0);
  pts->InsertNextPoint(1, 0, 0);
  pts->InsertNextPoint(0, 1, 0);
  pd->SetPoints(pts);
  vtkNew<vtkCellArray> polys;
  const vtkIdType good[3] = { 0, 1, 2 };
  const vtkIdType bad[3] = { 0, 1, 5 };
  polys->InsertNextCell(3, good);
  pd->SetPolys(polys);
  CHECK(vtkPenumbraMeshFileCheck::CheckConnectivity(pd).empty());
  polys->InsertNextCell(3, bad);
  CHECK(Contains(vtkPenumbraMeshFileCheck::CheckConnectivity(pd),
    "polygon 1 uses point 5 but there are only 3 points"));
  return EXIT_SUCCESS;
}

// Through the scene reader: the truncated PLY is a clear error, not an abort inside VTK.
int TestSceneReader()
{
  Write("cut.ply", PlyHeader("binary_little_endian", 3, 1));
  const std::string scene = Write("scene.json",
    R"({"objects": [{"file": "cut.ply"}], "lights": [{"type": "point", "position": [0, 0, 1]}]})");
  vtkNew<vtkPenumbraSceneReader> reader;
  reader->GlobalWarningDisplayOff();
  reader->SetFileName(scene.c_str());
  CHECK(reader->Read() == 0);
  CHECK(Contains(
    reader->GetErrorMessage(), "objects[0].file: " + Dir + "/cut.ply: binary PLY ends inside"));
  return EXIT_SUCCESS;
}
}

int TestMeshFileCheck(int, char*[])
{
  char dirTemplate[] = "/tmp/penumbra-meshcheck-XXXXXX";
  CHECK(mkdtemp(dirTemplate) != nullptr);
  Dir = dirTemplate;
  RUN(TestPly());
  RUN(TestObj());
  RUN(TestLegacy());
  RUN(TestConnectivity());
  RUN(TestSceneReader());
  CHECK(std::system(("rm -rf '" + Dir + "'").c_str()) == 0);
  return EXIT_SUCCESS;
}
