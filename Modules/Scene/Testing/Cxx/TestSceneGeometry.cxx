// Scene extraction: world-space triangles in double precision with the props' full matrices,
// triangulation of polygons and strips in VTK's draw order, composite data, assemblies,
// visibility, shadow flags, MTime caching, rebasing of georeferenced coordinates, bad input,
// and the gl_PrimitiveID -> triangle mapping arithmetic.
#include "vtkActor.h"
#include "vtkAssembly.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkCompositePolyDataMapper.h"
#include "vtkDataSetMapper.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkPropCollection.h"
#include "vtkProperty.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkTestErrorObserver.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "PenumbraTestMacros.h"
#include "SceneGeometryTestUtilities.h"

namespace
{
using namespace penumbra_scene_test;

// Position + orientation + scale + origin + UserMatrix against hand-computed coordinates.
int TestTransform()
{
  auto poly = MakePolyData({ 1, 2, 3, 4, 0, -1, 0, 5, 2 });
  AddCell(poly->GetPolys(), { 0, 1, 2 });
  auto actor = MakeActor(poly);
  actor->SetPosition(10, 20, 30);
  actor->SetOrientation(0, 0, 90);
  actor->SetScale(2, 3, 4);
  actor->SetOrigin(1, 1, 1);
  vtkNew<vtkMatrix4x4> user; // rotate 90 degrees about z, then translate (100, -50, 7)
  const double u[16] = { 0, -1, 0, 100, 1, 0, 0, -50, 0, 0, 1, 7, 0, 0, 0, 1 };
  user->DeepCopy(u);
  actor->SetUserMatrix(user);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);

  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 1 && g->GetNumberOfProps() == 1);
  CHECK(g->GetProp(0) == actor.GetPointer());
  // world = U * T(origin + position) * Rz(90) * S * T(-origin) * p, Rz(90): (x, y) -> (-y, x)
  // p0 (1,2,3): (0,1,2) -> (0,3,8) -> (-3,0,8) -> (8,21,39) -> U: (79,-42,46)
  // p1 (4,0,-1): (3,-1,-2) -> (6,-3,-8) -> (3,6,-8) -> (14,27,23) -> U: (73,-36,30)
  // p2 (0,5,2): (-1,4,1) -> (-2,12,4) -> (-12,-2,4) -> (-1,19,35) -> U: (81,-51,42)
  double w[3];
  WorldVertex(g, 0, 0, w);
  CHECK(Near(w, 79, -42, 46, 1e-9));
  WorldVertex(g, 0, 1, w);
  CHECK(Near(w, 73, -36, 30, 1e-9));
  WorldVertex(g, 0, 2, w);
  CHECK(Near(w, 81, -51, 42, 1e-9));
  double b[6];
  g->GetBounds(b);
  CHECK(std::fabs(b[0] - 73) < 1e-9 && std::fabs(b[1] - 81) < 1e-9);
  CHECK(std::fabs(b[2] + 51) < 1e-9 && std::fabs(b[3] + 36) < 1e-9);
  CHECK(std::fabs(b[4] - 30) < 1e-9 && std::fabs(b[5] - 46) < 1e-9);
  // The origin is a power-of-two multiple near the centre (77, -43.5, 38): extent 16 -> 1 m.
  const double* o = g->GetOrigin();
  CHECK(o[0] == 77 && (o[1] == -43 || o[1] == -44) && o[2] == 38);
  CHECK(g->GetNumberOfDegenerateTriangles() == 0);
  return EXIT_SUCCESS;
}

// Quad -> 2, pentagon -> 3 (fans), 6-point strip -> 4 triangles with alternating order.
int TestTriangulation()
{
  auto poly = MakePolyData({ 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, // quad 0-3
    3, 0, 0, 4, 0, 0, 5, 1, 0, 4, 2, 0, 3, 1, 0,                 // pentagon 4-8
    0, 5, 0, 0, 6, 0, 1, 5, 0, 1, 6, 0, 2, 5, 0, 2, 6, 0 });     // strip 9-14
  AddCell(poly->GetVerts(), { 0 });
  AddCell(poly->GetLines(), { 0, 1 });
  AddCell(poly->GetPolys(), { 0, 1, 2, 3 });
  AddCell(poly->GetPolys(), { 4, 5, 6, 7, 8 });
  AddCell(poly->GetStrips(), { 9, 10, 11, 12, 13, 14 });
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(MakeActor(poly));

  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 2 + 3 + 4);
  // Cell ids count verts and lines first: quad 2, pentagon 3, strip 4.
  const vtkIdType cells[9] = { 2, 2, 3, 3, 3, 4, 4, 4, 4 };
  for (vtkIdType t = 0; t < 9; ++t)
  {
    CHECK(g->GetTriangleCellId(t) == cells[t]);
    CHECK(g->GetTrianglePropIndex(t) == 0);
  }
  double w[3];
  // Pentagon fan: (4,5,6), (4,6,7), (4,7,8); check the last one.
  WorldVertex(g, 4, 0, w);
  CHECK(Near(w, 3, 0, 0, 1e-12));
  WorldVertex(g, 4, 1, w);
  CHECK(Near(w, 4, 2, 0, 1e-12));
  WorldVertex(g, 4, 2, w);
  CHECK(Near(w, 3, 1, 0, 1e-12));
  // Strip triangle 1 is (p1, p3, p2) = points 10, 12, 11; triangle 3 is (p3, p5, p4).
  WorldVertex(g, 6, 0, w);
  CHECK(Near(w, 0, 6, 0, 1e-12));
  WorldVertex(g, 6, 1, w);
  CHECK(Near(w, 1, 6, 0, 1e-12));
  WorldVertex(g, 6, 2, w);
  CHECK(Near(w, 1, 5, 0, 1e-12));
  WorldVertex(g, 8, 1, w);
  CHECK(Near(w, 2, 6, 0, 1e-12));
  // All strip triangles keep one winding: their normals all point the same way.
  for (vtkIdType t = 5; t < 9; ++t)
  {
    double a[3], bb[3], c[3], e1[3], e2[3], n[3];
    WorldVertex(g, t, 0, a);
    WorldVertex(g, t, 1, bb);
    WorldVertex(g, t, 2, c);
    vtkMath::Subtract(bb, a, e1);
    vtkMath::Subtract(c, a, e2);
    vtkMath::Cross(e1, e2, n);
    CHECK(n[2] < 0);
  }
  return EXIT_SUCCESS;
}

// Multiblock (nested) through a composite mapper: blocks in depth-first order, cell ids
// continuing from block to block; vtkDataSetMapper surface-extracts an unstructured grid.
int TestCompositeAndDataSet()
{
  auto a = MakePolyData({ 0, 0, 0, 1, 0, 0, 0, 1, 0 });
  AddCell(a->GetVerts(), { 0 });
  AddCell(a->GetPolys(), { 0, 1, 2 });
  auto b = MakePolyData({ 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1 });
  AddCell(b->GetPolys(), { 0, 1, 2, 3 });
  vtkNew<vtkMultiBlockDataSet> inner;
  inner->SetBlock(0, b);
  vtkNew<vtkMultiBlockDataSet> mb;
  mb->SetBlock(0, a);
  mb->SetBlock(1, inner);
  vtkNew<vtkCompositePolyDataMapper> compositeMapper;
  compositeMapper->SetInputDataObject(mb);
  vtkNew<vtkActor> compositeActor;
  compositeActor->SetMapper(compositeMapper);

  vtkNew<vtkUnstructuredGrid> hex;
  vtkNew<vtkPoints> hp;
  for (int i = 0; i < 8; ++i)
  {
    hp->InsertNextPoint(10 + (((i + 1) / 2) % 2), (i / 2) % 2, i / 4);
  }
  hex->SetPoints(hp);
  const vtkIdType hexIds[8] = { 0, 1, 2, 3, 4, 5, 6, 7 };
  hex->InsertNextCell(VTK_HEXAHEDRON, 8, hexIds);
  vtkNew<vtkDataSetMapper> dsMapper;
  dsMapper->SetInputData(hex);
  vtkNew<vtkActor> hexActor;
  hexActor->SetMapper(dsMapper);

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(compositeActor);
  renderer->AddActor(hexActor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfProps() == 2);
  CHECK(g->GetPropTriangleCount(0) == 3 && g->GetPropTriangleOffset(1) == 3);
  CHECK(g->GetTriangleCellId(0) == 1); // after block a's vertex cell
  CHECK(g->GetTriangleCellId(1) == 2); // block b's quad: a has 2 cells
  CHECK(g->GetTriangleCellId(2) == 2);
  double w[3];
  WorldVertex(g, 1, 0, w);
  CHECK(Near(w, 0, 0, 1, 1e-12));
  CHECK(g->MapPrimitiveId(0, 0) == -1);    // composite: mapping not supported
  CHECK(g->GetPropTriangleCount(1) == 12); // 6 quad faces
  double bounds[6];
  g->GetBounds(bounds);
  CHECK(bounds[0] == 0 && bounds[1] == 11 && bounds[5] == 1);
  CHECK(g->MapPrimitiveId(1, 0) == 3 && g->MapPrimitiveId(1, 11) == 14);
  return EXIT_SUCCESS;
}

// Assembly parts with path matrices; a flag on the assembly applies to its parts.
int TestAssembly()
{
  auto poly = MakePolyData({ 0, 0, 0, 1, 0, 0, 0, 1, 0 });
  AddCell(poly->GetPolys(), { 0, 1, 2 });
  auto part = MakeActor(poly);
  part->SetPosition(0, 1, 0);
  vtkNew<vtkAssembly> assembly;
  assembly->AddPart(part);
  assembly->SetPosition(5, 0, 0);
  assembly->SetScale(2, 2, 2);
  vtkNew<vtkRenderer> renderer;
  renderer->AddViewProp(assembly);

  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfProps() == 1 && g->GetProp(0) == part.GetPointer());
  CHECK(g->GetPropIndex(part) == 0 && g->GetPropIndex(assembly) == -1);
  double w[3];
  WorldVertex(g, 0, 1, w); // (1,0,0) + (0,1,0) = (1,1,0), scaled by 2, + (5,0,0)
  CHECK(Near(w, 7, 2, 0, 1e-12));
  CHECK(g->GetTriangleFlags(0) == 3);
  vtkPenumbraShadowKeys::SetCastsShadows(assembly, false);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetTriangleFlags(0) == vtkPenumbraSceneGeometry::RECEIVES_SHADOWS);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 0);
  // Moving the assembly moves the part.
  assembly->SetPosition(6, 0, 0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  WorldVertex(g, 0, 1, w);
  CHECK(Near(w, 8, 2, 0, 1e-12));
  return EXIT_SUCCESS;
}

// Visibility, flags and the MTime cache.
int TestFlagsAndCache()
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(8);
  sphere->SetPhiResolution(6);
  vtkNew<vtkPolyDataMapper> sphereMapper;
  sphereMapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> a;
  a->SetMapper(sphereMapper);
  auto quad = MakePolyData({ 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 });
  AddCell(quad->GetPolys(), { 0, 1, 2, 3 });
  auto b = MakeActor(quad);
  b->SetPosition(3, 0, 0);
  auto hidden = MakeActor(quad);
  hidden->VisibilityOff();
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(a);
  renderer->AddActor(hidden);
  renderer->AddActor(b);

  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfProps() == 2); // the invisible prop is skipped
  CHECK(g->GetProp(1) == b.GetPointer() && g->GetPropIndex(hidden) == -1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 2);
  const vtkIdType sphereTris = g->GetPropTriangleCount(0);
  CHECK(sphereTris == 2 * 8 * (6 - 2)); // vtkSphereSource: 2 * theta * (phi - 2) triangles
  CHECK(g->GetNumberOfTriangles() == sphereTris + 2);
  vtkMTimeType geometryTime = g->GetGeometryTime();
  vtkMTimeType flagsTime = g->GetFlagsTime();
  // The casters' stamp: the later of the two, what the caches of the techniques remember.
  CHECK(g->GetCastersTime() == std::max(geometryTime, flagsTime));
  penumbra::CastersStamp stamp;
  CHECK(stamp.Changed(g)); // nothing remembered yet
  stamp.Remember(g);
  CHECK(!stamp.Changed(g));
  vtkNew<vtkPenumbraSceneGeometry> empty;
  CHECK(stamp.Changed(empty)); // another geometry

  // Nothing changed: nothing extracted, nothing republished.
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 0);
  CHECK(g->GetGeometryTime() == geometryTime && g->GetFlagsTime() == flagsTime);
  CHECK(!stamp.Changed(g));

  // A colour change is not a geometry change.
  b->GetProperty()->SetColor(1, 0, 0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 0);
  CHECK(g->GetGeometryTime() == geometryTime && g->GetFlagsTime() == flagsTime);

  // Flags: not extracted again, but the flags (and only them) are new.
  vtkPenumbraShadowKeys::SetCastsShadows(a, false);
  vtkPenumbraShadowKeys::SetReceivesShadows(b, false);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 0);
  CHECK(g->GetGeometryTime() == geometryTime && g->GetFlagsTime() > flagsTime);
  CHECK(g->GetCastersTime() == g->GetFlagsTime() && stamp.Changed(g));
  stamp.Remember(g);
  CHECK(g->GetTriangleFlags(0) == vtkPenumbraSceneGeometry::RECEIVES_SHADOWS);
  CHECK(g->GetTriangleFlags(sphereTris) == vtkPenumbraSceneGeometry::CASTS_SHADOWS);
  flagsTime = g->GetFlagsTime();

  // Moving one prop re-extracts that prop only and keeps the origin.
  const double origin[3] = { g->GetOrigin()[0], g->GetOrigin()[1], g->GetOrigin()[2] };
  b->SetPosition(3.5, 0, 0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  CHECK(g->GetGeometryTime() > geometryTime);
  CHECK(stamp.Changed(g) && g->GetCastersTime() > stamp.Time);
  stamp.Remember(g);
  stamp.Forget(); // a build that failed halfway
  CHECK(stamp.Changed(g));
  CHECK(g->GetOrigin()[0] == origin[0] && g->GetOrigin()[1] == origin[1]);
  double w[3];
  WorldVertex(g, sphereTris, 0, w);
  CHECK(Near(w, 3.5, 0, 0, 1e-12));
  geometryTime = g->GetGeometryTime();

  // An upstream change re-extracts through the pipeline.
  sphere->SetThetaResolution(10);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  CHECK(g->GetPropTriangleCount(0) == 2 * 10 * (6 - 2));
  CHECK(g->GetGeometryTime() > geometryTime);
  geometryTime = g->GetGeometryTime();

  // Showing a prop again costs no extraction but changes the triangle list; hiding too.
  hidden->VisibilityOn();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfProps() == 3 && g->GetProp(1) == hidden.GetPointer());
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1); // first time ever seen visible
  geometryTime = g->GetGeometryTime();
  hidden->VisibilityOff();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfProps() == 2 && g->GetGeometryTime() > geometryTime);
  geometryTime = g->GetGeometryTime();
  hidden->VisibilityOn();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 0);
  CHECK(g->GetNumberOfProps() == 3 && g->GetGeometryTime() > geometryTime);

  // Modified() without a real change re-extracts but does not bump the geometry time.
  geometryTime = g->GetGeometryTime();
  quad->Modified();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 2); // both quad actors share the data
  CHECK(g->GetGeometryTime() == geometryTime);
  return EXIT_SUCCESS;
}

// City coordinates: millimetres survive rebasing, and the positions are small.
int TestGeoreferenced()
{
  const double x0 = 3.45e6, y0 = 5.43e6;
  auto poly = MakePolyData({ x0, y0, 0, x0 + 20.001, y0, 0, x0, y0 + 30.002, 12.003, //
    x0 + 0.001, y0 + 0.001, 0.001 });
  AddCell(poly->GetPolys(), { 0, 1, 2 });
  AddCell(poly->GetPolys(), { 0, 1, 3 });
  auto actor = MakeActor(poly);
  auto other = MakeActor(poly);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  renderer->AddActor(other);

  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  const double* o = g->GetOrigin();
  CHECK(std::fabs(o[0] - x0) < 100 && std::fabs(o[1] - y0) < 100);
  vtkPoints* pts = poly->GetPoints();
  const vtkIdType ids[2][3] = { { 0, 1, 2 }, { 0, 1, 3 } };
  for (vtkIdType t = 0; t < 2; ++t)
  {
    for (int v = 0; v < 3; ++v)
    {
      double in[3], w[3];
      pts->GetPoint(ids[t][v], in);
      WorldVertex(g, t, v, w);
      CHECK(Near(w, in[0], in[1], in[2], 1e-9));
      for (int c = 0; c < 3; ++c)
      {
        double corners[9];
        g->GetTriangle(t, corners);
        const double rel = corners[3 * v + c];
        CHECK(std::fabs(rel) < 64);
        // float32 of the relative position still holds the millimetre.
        CHECK(std::fabs(static_cast<float>(rel) - rel) < 1e-5);
      }
    }
  }
  // The 1 mm triangle is not degenerate.
  CHECK(g->GetNumberOfDegenerateTriangles() == 0);
  // Moving one prop by 10 m does not move the origin (no jitter for the others).
  const double before[3] = { o[0], o[1], o[2] };
  other->SetPosition(10, 0, 0);
  CHECK(g->Update(renderer) == 1);
  CHECK(o[0] == before[0] && o[1] == before[1] && o[2] == before[2]);
  // Moving the whole scene far away does, and a new origin is new geometry for the casters.
  const vtkMTimeType castersTime = g->GetCastersTime();
  actor->SetPosition(5000, 0, 0);
  other->SetPosition(5000, 0, 0);
  CHECK(g->Update(renderer) == 1);
  CHECK(std::fabs(o[0] - (x0 + 5000)) < 100);
  CHECK(g->GetCastersTime() > castersTime);
  return EXIT_SUCCESS;
}

// Shadow-only props (another rank's casters) are extracted after the renderer's props, with
// their keys; the casters' world triangles are exactly what was extracted, the receivers-only
// prop left out, whatever the rebasing origin.
int TestShadowOnlyAndCasterTriangles()
{
  const double x0 = 3.45e6 + 0.1, y0 = 5.43e6 + 0.3;
  auto local = MakePolyData({ x0, y0, 0.1, x0 + 20.001, y0, 0, x0, y0 + 30.002, 12.003 });
  AddCell(local->GetPolys(), { 0, 1, 2 });
  auto remote = MakePolyData({ x0 + 1e-3, y0, 5.7, x0 + 3, y0 + 0.01, 5, x0, y0 + 3.3, 6 });
  AddCell(remote->GetPolys(), { 0, 1, 2 });
  auto ground = MakePolyData({ x0 - 50, y0 - 50, -1, x0 + 50, y0 - 50, -1, x0, y0 + 50, -1 });
  AddCell(ground->GetPolys(), { 0, 1, 2 });
  auto localActor = MakeActor(local);
  auto remoteActor = MakeActor(remote);
  auto groundActor = MakeActor(ground);
  vtkPenumbraShadowKeys::SetCastsShadows(groundActor, false);
  vtkPenumbraShadowKeys::SetReceivesShadows(remoteActor, false);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(groundActor);
  renderer->AddActor(localActor);
  vtkNew<vtkPropCollection> shadowOnly;
  shadowOnly->AddItem(remoteActor);

  vtkNew<vtkPenumbraSceneGeometry> g;
  g->SetShadowOnlyProps(shadowOnly);
  CHECK(g->GetShadowOnlyProps() == shadowOnly.GetPointer());
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfProps() == 3 && g->GetProp(2) == remoteActor.GetPointer());
  CHECK(g->GetTriangleFlags(2) == vtkPenumbraSceneGeometry::CASTS_SHADOWS);
  CHECK(renderer->GetViewProps()->GetNumberOfItems() == 2);

  vtkNew<vtkDoubleArray> world;
  g->GetCasterWorldTriangles(world);
  CHECK(world->GetNumberOfComponents() == 9 && world->GetNumberOfTuples() == 2);
  for (int t = 0; t < 2; ++t)
  {
    vtkPoints* pts = (t == 0 ? local : remote)->GetPoints();
    for (int k = 0; k < 9; ++k)
    {
      // Bit for bit: a round trip through the rebasing origin would round these.
      CHECK(world->GetComponent(t, k) == pts->GetPoint(k / 3)[k % 3]);
    }
  }
  // Without the shadow-only props the remote triangle is gone.
  g->SetShadowOnlyProps(nullptr);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfProps() == 2);
  g->GetCasterWorldTriangles(world);
  CHECK(world->GetNumberOfTuples() == 1);
  return EXIT_SUCCESS;
}

// NaN points fail with the prop named; the geometry is emptied. Empty scenes are fine.
int TestBadInputAndEmpty()
{
  vtkNew<vtkPenumbraSceneGeometry> g;
  vtkNew<vtkRenderer> empty;
  CHECK(g->Update(empty) == 1);
  CHECK(g->GetNumberOfTriangles() == 0 && g->GetNumberOfProps() == 0);
  CHECK(std::string(g->GetErrorMessage()).empty());
  double b[6];
  g->GetBounds(b);
  CHECK(!vtkMath::AreBoundsInitialized(b));

  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  auto good = MakePolyData({ 0, 0, 0, 1, 0, 0, 0, 1, 0 });
  AddCell(good->GetPolys(), { 0, 1, 2 });
  auto bad = MakePolyData({ 0, 0, 0, nan, 0, 0, 0, inf, 0, 7, 7, nan });
  AddCell(bad->GetPolys(), { 0, 1, 2 });
  AddCell(bad->GetVerts(), { 3 }); // drawn as a point: counted too
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(MakeActor(good));
  auto badActor = MakeActor(bad);
  vtkPenumbraSceneGeometry::SetPropName(badActor, "tower");
  renderer->AddActor(badActor);
  CHECK(std::string(vtkPenumbraSceneGeometry::GetPropName(badActor)) == "tower");

  vtkNew<vtkTest::ErrorObserver> observer;
  g->AddObserver(vtkCommand::ErrorEvent, observer);
  CHECK(g->Update(renderer) == 0);
  const std::string message = g->GetErrorMessage();
  CHECK(message == "vtkActor 'tower' (prop 1): 3 points with NaN/inf coordinates");
  CHECK(observer->GetError());
  CHECK(observer->GetErrorMessage().find("'tower' (prop 1)") != std::string::npos);
  CHECK(g->GetNumberOfTriangles() == 0 && g->GetNumberOfProps() == 0);

  // Fixed: success again, and the message is cleared.
  bad->GetPoints()->SetPoint(1, 1, 0, 0);
  bad->GetPoints()->SetPoint(2, 0, 1, 0);
  bad->GetPoints()->SetPoint(3, 7, 7, 0);
  bad->GetPoints()->Modified();
  CHECK(g->Update(renderer) == 1);
  CHECK(std::string(g->GetErrorMessage()).empty());
  CHECK(g->GetNumberOfTriangles() == 2);

  // An unnamed prop is still identified by class and index.
  bad->GetPoints()->SetPoint(0, inf, 0, 0);
  bad->GetPoints()->Modified();
  vtkPenumbraSceneGeometry::SetPropName(badActor, nullptr);
  observer->Clear();
  CHECK(g->Update(renderer) == 0);
  CHECK(std::string(g->GetErrorMessage()) ==
    "unnamed vtkActor (prop 1): 1 point with NaN/inf coordinates");
  return EXIT_SUCCESS;
}

// gl_PrimitiveID + PrimitiveIDOffset -> global triangle, for a mesh with verts, lines, polys
// (one fan triangle with two coincident points, which VTK does not draw) and strips.
int TestPrimitiveMapping()
{
  auto first = MakePolyData({ 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 });
  AddCell(first->GetPolys(), { 0, 1, 2, 3 }); // 2 triangles before the mixed prop

  auto mixed = MakePolyData({ 0, 0, 0, 1, 0, 0, 1, 1, 0, 1, 1, 0, // 2 and 3 coincide
    2, 0, 0, 3, 0, 0, 3, 1, 0, 2, 2, 0, 1.5, 1, 0,                // 4-8
    0, 5, 0, 0, 6, 0, 1, 5, 0, 1, 6, 0, 2, 5, 0 });               // 9-13
  AddCell(mixed->GetVerts(), { 0 });                              // 1 point primitive
  AddCell(mixed->GetVerts(), { 4, 5, 6 });                        // 3 point primitives
  AddCell(mixed->GetLines(), { 0, 1 });                           // 1 segment
  AddCell(mixed->GetLines(), { 4, 5, 6, 7 });                     // 3 segments
  AddCell(mixed->GetPolys(), { 9, 10, 11 });                      // local triangle 0, cell 4
  AddCell(mixed->GetPolys(), { 0, 1, 2, 3 });         // local 1, 2 (2 not drawn), cell 5
  AddCell(mixed->GetPolys(), { 4, 5, 6, 7, 8 });      // local 3, 4, 5, cell 6
  AddCell(mixed->GetStrips(), { 9, 10, 11, 12, 13 }); // local 6, 7, 8, cell 7
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(mixed);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(MakeActor(first));
  renderer->AddActor(actor);

  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetPropTriangleOffset(1) == 2 && g->GetPropTriangleCount(1) == 9);
  CHECK(g->GetNumberOfDegenerateTriangles() == 1); // kept, and counted
  const vtkIdType cells[9] = { 4, 5, 5, 6, 6, 6, 7, 7, 7 };
  for (vtkIdType t = 0; t < 9; ++t)
  {
    CHECK(g->GetTriangleCellId(2 + t) == cells[t]);
  }
  // Offsets: 4 vertex points, 4 line segments -> triangles start at 8. Polygons draw 5 of
  // their 6 fan triangles; without a cell map the strips start at 8 + (12 - 2 * 3) = 14.
  const vtkIdType expected[18] = { -1, -1, -1, -1, -1, -1, -1, -1, // points, lines
    2 + 0, 2 + 1, 2 + 3, 2 + 4, 2 + 5,                             // drawn fan triangles
    -1,                                                            // never produced
    2 + 6, 2 + 7, 2 + 8,                                           // strip triangles
    -1 };
  for (vtkIdType id = 0; id < 18; ++id)
  {
    if (g->MapPrimitiveId(1, id) != expected[id])
    {
      std::cerr << "MapPrimitiveId(1, " << id << ") = " << g->MapPrimitiveId(1, id) << ", expected "
                << expected[id] << "\n";
      return EXIT_FAILURE;
    }
  }
  CHECK(g->MapPrimitiveId(0, 0) == 0 && g->MapPrimitiveId(0, 1) == 1);
  CHECK(g->MapPrimitiveId(0, 2) == -1 && g->MapPrimitiveId(0, -1) == -1);
  CHECK(g->MapPrimitiveId(2, 0) == -1 && g->MapPrimitiveId(-1, 0) == -1);

  // With cell scalars the mapper builds its exact cell map: strips follow the drawn count.
  vtkNew<vtkFloatArray> scalars;
  scalars->SetNumberOfTuples(mixed->GetNumberOfCells());
  scalars->FillValue(1.0f);
  mixed->GetCellData()->SetScalars(scalars);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->MapPrimitiveId(1, 12) == 2 + 5 && g->MapPrimitiveId(1, 13) == 2 + 6);
  CHECK(g->MapPrimitiveId(1, 15) == 2 + 8 && g->MapPrimitiveId(1, 16) == -1);
  // ... unless the scalars are not shown: back to the map-less numbering.
  mapper->ScalarVisibilityOff();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->MapPrimitiveId(1, 13) == -1 && g->MapPrimitiveId(1, 14) == 2 + 6);

  // Wireframe draws lines, not triangles: no mapping.
  actor->GetProperty()->SetRepresentationToWireframe();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->MapPrimitiveId(1, 8) == -1);
  return EXIT_SUCCESS;
}
} // namespace

// The storage: one copy of a mesh, indexed. A closed mesh's shared points are stored once,
// its cell ids and owners cost nothing (affine), and an update that extracts the same
// triangles again keeps the stored ones (their float32 copy is read in place by Embree and GL).
int TestIndexedStorage()
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(64);
  sphere->SetPhiResolution(32);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  const vtkIdType n = g->GetNumberOfTriangles();
  CHECK(n == 2 * 64 * (32 - 2));
  const penumbra::SceneTriangles& triangles = g->GetTriangles();
  CHECK(triangles.GetBlocks().size() == 1);
  const penumbra::TriangleList& list = *triangles.GetBlocks()[0].List;
  mapper->Update();
  CHECK(list.NumberOfPoints() == mapper->GetInput()->GetNumberOfPoints()); // each point once
  // Points 24 and float32 copy 12 per point (about half a point a triangle), corners 12 and
  // the role 1 per triangle: about 31 bytes a triangle; a soup of corners would take 110.
  const double perTriangle = static_cast<double>(g->GetTriangleBytes()) / static_cast<double>(n);
  std::cout << "  stored bytes per triangle: " << perTriangle << "\n";
  CHECK(perTriangle > 25.0 && perTriangle < 36.0);
  for (vtkIdType t = 0; t < n; t += 97)
  {
    CHECK(g->GetTriangleOwner(t) == t && g->GetTriangleCellId(t) == t);
    CHECK(g->GetTrianglePropIndex(t) == 0);
    // The accessors agree: the float32 corners are the rounded double ones.
    double v[9];
    float f[9];
    triangles.Get(t, v);
    triangles.GetFloat(t, f);
    for (int k = 0; k < 9; ++k)
    {
      CHECK(f[k] == static_cast<float>(v[k]));
    }
  }
  double v[9];
  CHECK(!g->GetTriangle(n, v) && g->GetTriangleOwner(-1) == -1 && g->GetTriangleFlags(n) == 0);

  // The same triangles extracted again: same stored list, same float32 array, same time.
  const float* rebased = list.Rebased.data();
  const std::uint32_t* corners = list.Corners.data();
  const vtkMTimeType time = g->GetGeometryTime();
  sphere->Modified();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  CHECK(g->GetGeometryTime() == time);
  CHECK(g->GetTriangles().GetBlocks()[0].List->Rebased.data() == rebased);
  CHECK(g->GetTriangles().GetBlocks()[0].List->Corners.data() == corners);
  // Other triangles: published anew.
  sphere->SetRadius(2.0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetGeometryTime() > time);
  return EXIT_SUCCESS;
}

// The per-triangle columns: an affine prefix (nothing stored) and an explicit tail.
int TestAffineColumn()
{
  penumbra::AffineColumn c;
  for (vtkIdType v : { 5, 6, 7 })
  {
    c.Append(v);
  }
  CHECK(c.Size() == 3 && c[0] == 5 && c[2] == 7 && c.HeapBytes() == 0);
  c.Append(7); // breaks the run
  c.Append(8);
  CHECK(c.Size() == 5 && c[3] == 7 && c[4] == 8 && c.HeapBytes() > 0);
  penumbra::AffineColumn d;
  for (vtkIdType v : { 5, 6, 7, 7, 8 })
  {
    d.Append(v);
  }
  CHECK(c == d);
  d.Fill(1, -1); // a glyph's instance ids over part of the prefix
  CHECK(d[0] == 5 && d[1] == -1 && d[4] == -1 && !(c == d));
  penumbra::AffineColumn e;
  e.Append(0);
  e.Append(-1);
  e.Append(c, 10); // owners shifted, -1 kept
  d.Clear();
  d.Append(-1);
  d.Append(e, 100);
  CHECK(e.Size() == 7 && e[2] == 15 && e[6] == 18 && d[1] == 100 && d[2] == -1 && d[7] == 118);
  return EXIT_SUCCESS;
}

int TestSceneGeometry(int, char*[])
{
  RUN(TestTransform());
  RUN(TestTriangulation());
  RUN(TestCompositeAndDataSet());
  RUN(TestAssembly());
  RUN(TestFlagsAndCache());
  RUN(TestGeoreferenced());
  RUN(TestBadInputAndEmpty());
  RUN(TestPrimitiveMapping());
  RUN(TestShadowOnlyAndCasterTriangles());
  RUN(TestIndexedStorage());
  RUN(TestAffineColumn());
  return EXIT_SUCCESS;
}
