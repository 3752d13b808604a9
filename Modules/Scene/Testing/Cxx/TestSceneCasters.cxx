// Every prop casts what VTK draws: wireframe squares cast tubes and no solid, the points
// representation casts one solid per point, tube and point widths follow the camera's pixel
// size (re-extracted on zoom, not on an orbit), clipping planes and alpha cut-outs leave
// exactly the analytic remainder (owned by the triangle it was cut from), glyph instances
// and splats are placed as VTK places them, and props that cast nothing say so.
#include "vtkBitArray.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkCubeSource.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkGlyph3DMapper.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkImageSlice.h"
#include "vtkImageSliceMapper.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPlane.h"
#include "vtkPlaneCollection.h"
#include "vtkPointData.h"
#include "vtkPointGaussianMapper.h"
#include "vtkProp3D.h"
#include "vtkPropCollection.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSkybox.h"
#include "vtkSphereSource.h"
#include "vtkTestErrorObserver.h"
#include "vtkTexture.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>

#include "PenumbraTestMacros.h"
#include "SceneGeometryTestUtilities.h"

namespace
{
using namespace penumbra_scene_test;
constexpr double Pi = 3.14159265358979323846;
using Flags = vtkPenumbraSceneGeometry::TriangleFlags;

// Triangle t's area (world), and whether its flags are exactly `flags`.
double Area(vtkPenumbraSceneGeometry* g, vtkIdType t)
{
  double a[3], b[3], c[3], e1[3], e2[3], n[3];
  WorldVertex(g, t, 0, a);
  WorldVertex(g, t, 1, b);
  WorldVertex(g, t, 2, c);
  vtkMath::Subtract(b, a, e1);
  vtkMath::Subtract(c, a, e2);
  vtkMath::Cross(e1, e2, n);
  return 0.5 * vtkMath::Norm(n);
}

// Counts the triangles of prop `p` with exactly `flags`, and sums their areas.
vtkIdType CountFlags(vtkPenumbraSceneGeometry* g, int p, int flags, double* area = nullptr)
{
  vtkIdType count = 0;
  double sum = 0.0;
  const vtkIdType first = g->GetPropTriangleOffset(p);
  for (vtkIdType t = first; t < first + g->GetPropTriangleCount(p); ++t)
  {
    if (g->GetTriangleFlags(t) == flags)
    {
      ++count;
      sum += Area(g, t);
    }
  }
  if (area)
  {
    *area = sum;
  }
  return count;
}

// Distance from x to the segment [a, b].
double SegmentDistance(const double x[3], const double a[3], const double b[3])
{
  double ab[3], ax[3];
  vtkMath::Subtract(b, a, ab);
  vtkMath::Subtract(x, a, ax);
  const double t = std::min(1.0, std::max(0.0, vtkMath::Dot(ax, ab) / vtkMath::Dot(ab, ab)));
  const double p[3] = { a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2] };
  return std::sqrt(vtkMath::Distance2BetweenPoints(x, p));
}

// The unit square [0, 1]^2 at z = 0 as one polygon.
vtkSmartPointer<vtkPolyData> UnitSquare()
{
  auto poly = MakePolyData({ 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 });
  AddCell(poly->GetPolys(), { 0, 1, 2, 3 });
  return poly;
}

// Wireframe: the square's four edges as tubes (8 caster-only triangles each, owned by no
// drawn triangle) whose triangles have circumradius pi d / (3 sqrt 3); no solid triangle.
int TestWireframeSquare()
{
  auto actor = MakeActor(UnitSquare());
  actor->GetProperty()->SetRepresentationToWireframe();
  actor->GetProperty()->SetLineWidth(2.0);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  g->SetPixelSize(0.01);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfCastingNotes() == 0);
  CHECK(g->GetNumberOfTriangles() == 4 * 8);
  CHECK(CountFlags(g, 0, Flags::CASTS_SHADOWS) == 32);
  CHECK(g->MapPrimitiveId(0, 0) == -1);
  CHECK(g->GetFirstSurfacePrimitive(0) == VTK_ID_MAX); // lines only: no surface fragment
  // Each tube lies on one edge: its vertices at r from the edge, within the edge's length.
  const double r = Pi * 0.02 / (3.0 * std::sqrt(3.0));
  const double corners[4][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } };
  int edgesMet = 0;
  for (vtkIdType tube = 0; tube < 4; ++tube)
  {
    for (int edge = 0; edge < 4; ++edge)
    {
      bool onEdge = true;
      for (vtkIdType t = 8 * tube; t < 8 * (tube + 1); ++t)
      {
        for (int v = 0; v < 3; ++v)
        {
          double x[3];
          WorldVertex(g, t, v, x);
          const double d = SegmentDistance(x, corners[edge], corners[(edge + 1) % 4]);
          onEdge = onEdge && std::fabs(d - r) < 1e-12;
        }
      }
      edgesMet |= onEdge ? 1 << edge : 0;
    }
  }
  CHECK(edgesMet == 15);
  for (vtkIdType t = 0; t < g->GetNumberOfTriangles(); ++t)
  {
    CHECK(g->GetTriangleOwner(t) == -1);
    CHECK(g->GetTriangleCellId(t) == 0);
  }
  // The same square as a surface: its two triangles, no tube.
  actor->GetProperty()->SetRepresentationToSurface();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 2 && CountFlags(g, 0, 3) == 2);
  CHECK(g->GetTriangleOwner(0) == 0 && g->GetTriangleOwner(1) == 1);
  CHECK(g->MapPrimitiveId(0, 1) == 1);
  CHECK(g->GetFirstSurfacePrimitive(0) == 0);
  // Surface with edges: each real edge gains a flat strip half the line width wide (VTK
  // draws at least 1.1 pixels), in the square's plane, owned by the fan triangle drawing it.
  actor->GetProperty()->EdgeVisibilityOn();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 2 + 4 * 2);
  double stripArea = 0.0;
  CHECK(CountFlags(g, 0, Flags::CASTS_SHADOWS, &stripArea) == 8);
  CHECK(std::fabs(stripArea - 4 * 0.01) < 1e-12); // 4 edges x 1 long x 0.01 wide
  for (vtkIdType t = 2; t < 10; ++t)
  {
    const vtkIdType owner = g->GetTriangleOwner(t);
    CHECK(owner == 0 || owner == 1);
  }
  return EXIT_SUCCESS;
}

// Points representation: one octahedron per point used by a cell, none for the surface;
// vertex and line cells in the surface representation cast points and tubes.
int TestPointsAndLineCells()
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(8);
  sphere->SetPhiResolution(6);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetRepresentationToPoints();
  actor->GetProperty()->SetPointSize(4.0);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  g->SetPixelSize(0.01);
  CHECK(g->Update(renderer) == 1);
  const vtkIdType points = 8 * (6 - 2) + 2;
  CHECK(g->GetNumberOfTriangles() == 8 * points);
  CHECK(CountFlags(g, 0, Flags::CASTS_SHADOWS) == 8 * points);
  // Octahedron vertices at d sqrt(pi / (4 sqrt 3)) from the point.
  double x[3];
  WorldVertex(g, 0, 0, x);
  const double r = 0.04 * std::sqrt(Pi / (4.0 * std::sqrt(3.0)));
  double c[3];
  sphere->GetOutput()->GetPoint(0, c);
  CHECK(std::fabs(std::sqrt(vtkMath::Distance2BetweenPoints(x, c)) - r) < 1e-7);

  auto poly = MakePolyData({ 0, 0, 0, 1, 0, 0, 1, 1, 0, 5, 5, 5, 6, 6, 6, 7, 7, 7 });
  AddCell(poly->GetVerts(), { 3 });
  AddCell(poly->GetVerts(), { 4, 5 });
  AddCell(poly->GetLines(), { 0, 1, 2 });
  AddCell(poly->GetLines(), { 2, 2 }); // zero length: no tube
  auto cells = MakeActor(poly);
  vtkNew<vtkRenderer> second;
  second->AddActor(cells);
  CHECK(g->Update(second) == 1);
  CHECK(g->GetNumberOfTriangles() == 2 * 8 + 3 * 8);
  CHECK(g->GetTriangleCellId(0) == 2 && g->GetTriangleCellId(16) == 0);
  // No pixel size: lines and points cast nothing, and the prop says so.
  g->SetPixelSize(0.0);
  CHECK(g->Update(second) == 1);
  CHECK(g->GetNumberOfTriangles() == 0 && g->GetNumberOfCastingNotes() == 1);
  CHECK(g->GetCastingNoteProp(0) == cells.GetPointer());
  return EXIT_SUCCESS;
}

// The pixel size at the focal point: 2 ParallelScale / height for a parallel camera and
// 2 d tan(angle / 2) / height for a perspective one. Tubes follow it; an orbit about the
// focal point re-extracts nothing, a zoom only the prop that draws lines.
int TestPixelSize()
{
  vtkNew<vtkCamera> perspective;
  perspective->SetPosition(0, 0, 10);
  perspective->SetFocalPoint(0, 0, 0);
  perspective->SetViewAngle(30);
  CHECK(std::fabs(vtkPenumbraSceneGeometry::ComputePixelSize(perspective, 200, 100) -
          2 * 10 * std::tan(vtkMath::RadiansFromDegrees(15.0)) / 100) < 1e-15);
  CHECK(vtkPenumbraSceneGeometry::ComputePixelSize(perspective, 200, 0) == 0.0);

  auto lines = MakeActor(UnitSquare());
  lines->GetProperty()->SetRepresentationToWireframe();
  lines->GetProperty()->SetLineWidth(3.0);
  auto surface = MakeActor(UnitSquare());
  surface->SetPosition(3, 0, 0);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(lines);
  renderer->AddActor(surface);
  vtkNew<vtkRenderWindow> window;
  window->SetSize(200, 100);
  window->AddRenderer(renderer);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->ParallelProjectionOn();
  camera->SetParallelScale(5.0);
  camera->SetPosition(0.5, 0.5, 10);
  camera->SetFocalPoint(0.5, 0.5, 0);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(std::fabs(g->GetPixelSize() - 0.1) < 1e-15);
  double x[3];
  WorldVertex(g, 0, 0, x);
  const double start[3] = { 0, 0, 0 }, end[3] = { 1, 0, 0 };
  const double tube = Pi / (3.0 * std::sqrt(3.0)); // circumradius per unit of width
  CHECK(std::fabs(SegmentDistance(x, start, end) - 0.3 * tube) < 1e-12); // 3 px x 0.1
  const vtkMTimeType geometryTime = g->GetGeometryTime();

  camera->Azimuth(30);
  camera->Elevation(20);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 0);
  CHECK(g->GetGeometryTime() == geometryTime);

  camera->SetParallelScale(2.5);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  CHECK(g->GetGeometryTime() > geometryTime);
  WorldVertex(g, 0, 0, x);
  CHECK(std::fabs(SegmentDistance(x, start, end) - 0.15 * tube) < 1e-12);

  window->SetSize(200, 50); // half the pixels: twice the pixel size
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  CHECK(std::fabs(g->GetPixelSize() - 0.1) < 1e-15);

  // Perspective: orbiting keeps the distance to the focal point (up to rounding), dollying
  // halves it and the pixel size with it.
  camera->ParallelProjectionOff();
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  const double perspectiveSize = g->GetPixelSize();
  for (int step = 0; step < 5; ++step)
  {
    camera->Azimuth(37);
    camera->Elevation(13);
    camera->OrthogonalizeViewUp();
    CHECK(g->Update(renderer) == 1);
    CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 0);
  }
  camera->Dolly(2.0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfPropsExtractedLastUpdate() == 1);
  CHECK(std::fabs(g->GetPixelSize() - 0.5 * perspectiveSize) < 1e-12 * perspectiveSize);
  return EXIT_SUCCESS;
}

// A plane keeping x <= 1 cuts the triangle (0,0) (2,0) (0,2): the drawn triangle keeps
// receiving but no longer casts; its pieces (owned by it) cover the remainder, area 1.5.
int TestClippingPlanes()
{
  auto poly = MakePolyData({ 0, 0, 0, 2, 0, 0, 0, 2, 0, 5, 0, 0, 6, 0, 0 });
  AddCell(poly->GetPolys(), { 0, 1, 2 });
  AddCell(poly->GetLines(), { 3, 4 }); // wholly clipped away
  auto actor = MakeActor(poly);
  vtkNew<vtkPlane> plane;
  plane->SetOrigin(1, 0, 0);
  plane->SetNormal(-1, 0, 0);
  actor->GetMapper()->AddClippingPlane(plane);
  auto other = MakeActor(UnitSquare());
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(other);
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  g->SetPixelSize(0.01);
  CHECK(g->Update(renderer) == 1);
  const vtkIdType first = g->GetPropTriangleOffset(1);
  CHECK(first == 2);
  CHECK(g->GetTriangleFlags(first) == Flags::RECEIVES_SHADOWS);
  CHECK(!g->IsOccluder(first));
  double area = 0.0;
  const vtkIdType pieces = CountFlags(g, 1, Flags::CASTS_SHADOWS, &area);
  CHECK(pieces >= 1 && pieces == g->GetPropTriangleCount(1) - 1);
  CHECK(std::fabs(area - 1.5) < 1e-12);
  for (vtkIdType t = first + 1; t < first + 1 + pieces; ++t)
  {
    CHECK(g->GetTriangleOwner(t) == first);
    for (int v = 0; v < 3; ++v)
    {
      double x[3];
      WorldVertex(g, t, v, x);
      CHECK(x[0] <= 1.0 + 1e-12);
    }
  }
  // The drawn triangle is still where VTK draws it, after the line's one segment primitive.
  CHECK(g->MapPrimitiveId(1, 1) == first && g->MapPrimitiveId(1, 0) == -1);
  CHECK(g->GetFirstSurfacePrimitive(1) == 1 && g->GetFirstSurfacePrimitive(2) == -1);
  vtkNew<vtkDoubleArray> casters;
  g->GetCasterWorldTriangles(casters);
  CHECK(casters->GetNumberOfTuples() == 2 + pieces);
  // A plane keeping everything changes nothing; one keeping nothing leaves nothing cast.
  plane->SetOrigin(10, 0, 0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetPropTriangleCount(1) == 1 + 8 && g->GetTriangleFlags(first) == 3);
  plane->SetOrigin(-10, 0, 0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetPropTriangleCount(1) == 1 && !g->IsOccluder(first));
  return EXIT_SUCCESS;
}

// A unit square with texture coordinates = its xy, textured by a width x 1 RGBA image whose
// texel k has alpha alphas[k].
vtkSmartPointer<vtkActor> TexturedSquare(
  std::initializer_list<int> alphas, bool linear, int wrap, int tcoordComponents = 2)
{
  auto poly = UnitSquare();
  vtkNew<vtkFloatArray> tcoords;
  tcoords->SetNumberOfComponents(tcoordComponents);
  for (vtkIdType i = 0; i < 4; ++i)
  {
    const double* p = poly->GetPoint(i);
    const float st[2] = { static_cast<float>(p[0]), static_cast<float>(p[1]) };
    tcoords->InsertNextTypedTuple(st);
  }
  poly->GetPointData()->SetTCoords(tcoords);
  vtkNew<vtkImageData> image;
  image->SetDimensions(static_cast<int>(alphas.size()), 1, 1);
  vtkNew<vtkUnsignedCharArray> rgba;
  rgba->SetNumberOfComponents(4);
  for (int a : alphas)
  {
    const unsigned char texel[4] = { 200, 100, 50, static_cast<unsigned char>(a) };
    rgba->InsertNextTypedTuple(texel);
  }
  image->GetPointData()->SetScalars(rgba);
  vtkNew<vtkTexture> texture;
  texture->SetInputData(image);
  texture->SetInterpolate(linear);
  texture->SetWrap(wrap);
  auto actor = MakeActor(poly);
  actor->SetTexture(texture);
  return actor;
}

// Cast area of the textured square, and a check that every piece is owned by a drawn
// triangle that no longer casts.
int CutArea(vtkActor* actor, double& area)
{
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfCastingNotes() == 0);
  CountFlags(g, 0, Flags::CASTS_SHADOWS, &area);
  double whole = 0.0;
  CountFlags(g, 0, 3, &whole);
  area += whole;
  for (vtkIdType t = 2; t < g->GetNumberOfTriangles(); ++t)
  {
    const vtkIdType owner = g->GetTriangleOwner(t);
    CHECK(owner == 0 || owner == 1);
    CHECK(g->GetTriangleFlags(owner) == Flags::RECEIVES_SHADOWS);
  }
  return EXIT_SUCCESS;
}

// Alpha cut-outs: nearest keeps the texel squares with alpha > 0, linear the texel-centre
// cells with an opaque corner; the wrap mode decides the cells past the last texel centre.
int TestTextureCutouts()
{
  double area = 0.0;
  // One alpha-0 half: exactly half the square casts.
  RUN(CutArea(TexturedSquare({ 255, 0 }, false, vtkTexture::Repeat), area));
  CHECK(std::fabs(area - 0.5) < 1e-12);
  // Four texels, only the first opaque. Nearest: s in [0, 1/4].
  RUN(CutArea(TexturedSquare({ 255, 0, 0, 0 }, false, vtkTexture::Repeat), area));
  CHECK(std::fabs(area - 0.25) < 1e-12);
  // Linear, clamped: the cells between centres 1/8 and 3/8 and below 1/8: s in [0, 3/8].
  RUN(CutArea(TexturedSquare({ 255, 0, 0, 0 }, true, vtkTexture::ClampToEdge), area));
  CHECK(std::fabs(area - 0.375) < 1e-12);
  // Linear, repeated: the cell across the seam (texels 3 and 0) too: s in [7/8, 1] more.
  RUN(CutArea(TexturedSquare({ 255, 0, 0, 0 }, true, vtkTexture::Repeat), area));
  CHECK(std::fabs(area - 0.5) < 1e-12);
  // One-component texture coordinates (t = 0) give the same cut.
  RUN(CutArea(TexturedSquare({ 255, 0, 0, 0 }, false, vtkTexture::Repeat, 1), area));
  CHECK(std::fabs(area - 0.25) < 1e-12);
  // Alpha never 0: nothing cut, the drawn triangles cast.
  auto opaque = TexturedSquare({ 255, 1 }, false, vtkTexture::Repeat);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(opaque);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 2 && CountFlags(g, 0, 3) == 2);
  // Non-finite texture coordinates are bad input, named.
  auto bad = TexturedSquare({ 255, 0 }, false, vtkTexture::Repeat);
  vtkPenumbraSceneGeometry::SetPropName(bad, "card");
  vtkDataArray* tc = vtkPolyData::SafeDownCast(bad->GetMapper()->GetInputDataObject(0, 0))
                       ->GetPointData()
                       ->GetTCoords();
  tc->SetComponent(2, 0, std::numeric_limits<double>::quiet_NaN());
  vtkNew<vtkRenderer> badRenderer;
  badRenderer->AddActor(bad);
  vtkNew<vtkTest::ErrorObserver> observer;
  g->AddObserver(vtkCommand::ErrorEvent, observer);
  CHECK(g->Update(badRenderer) == 0);
  CHECK(observer->GetError());
  CHECK(std::string(g->GetErrorMessage()).find("'card' (prop 0)") != std::string::npos);
  return EXIT_SUCCESS;
}

// Opacity 0 casts nothing; scalar colours with alpha 0 at every corner cast nothing.
int TestScalarAlpha()
{
  auto poly = MakePolyData({ 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0 });
  AddCell(poly->GetPolys(), { 0, 1, 2 });
  AddCell(poly->GetPolys(), { 0, 2, 3 });
  AddCell(poly->GetPolys(), { 1, 4, 2 });
  vtkNew<vtkUnsignedCharArray> colours;
  colours->SetNumberOfComponents(4);
  const unsigned char alphas[5] = { 0, 0, 0, 0, 255 };
  for (unsigned char a : alphas)
  {
    const unsigned char c[4] = { 255, 255, 255, a };
    colours->InsertNextTypedTuple(c);
  }
  poly->GetPointData()->SetScalars(colours);
  auto actor = MakeActor(poly);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 3);
  CHECK(g->GetTriangleFlags(0) == Flags::RECEIVES_SHADOWS);
  CHECK(g->GetTriangleFlags(1) == Flags::RECEIVES_SHADOWS);
  CHECK(g->GetTriangleFlags(2) == 3); // one opaque corner: drawn inside
  actor->GetMapper()->ScalarVisibilityOff();
  CHECK(g->Update(renderer) == 1);
  CHECK(CountFlags(g, 0, 3) == 3);
  actor->GetProperty()->SetOpacity(0.0);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 0);
  return EXIT_SUCCESS;
}

// Glyph instances: a 2 x 1 x 1 box scaled by the scale array's magnitude times ScaleFactor,
// turned by DIRECTION, the masked point left out; cast and receive; a NaN scale is named.
int TestGlyphs()
{
  vtkNew<vtkCubeSource> box;
  box->SetXLength(2);
  box->SetYLength(1);
  box->SetZLength(1);
  auto points = MakePolyData({ 0, 0, 0, 5, 0, 0, 9, 9, 9 });
  vtkNew<vtkDoubleArray> scale;
  scale->SetName("scale");
  scale->InsertNextValue(1.0);
  scale->InsertNextValue(2.0);
  scale->InsertNextValue(1.0);
  vtkNew<vtkDoubleArray> direction;
  direction->SetName("direction");
  direction->SetNumberOfComponents(3);
  direction->InsertNextTuple3(1, 0, 0);
  direction->InsertNextTuple3(0, 3, 0);
  direction->InsertNextTuple3(1, 0, 0);
  vtkNew<vtkBitArray> mask;
  mask->SetName("mask");
  mask->InsertNextValue(1);
  mask->InsertNextValue(1);
  mask->InsertNextValue(0);
  points->GetPointData()->AddArray(scale);
  points->GetPointData()->AddArray(direction);
  points->GetPointData()->AddArray(mask);
  vtkNew<vtkGlyph3DMapper> glyphs;
  glyphs->SetInputData(points);
  glyphs->SetSourceConnection(box->GetOutputPort());
  glyphs->SetScaleArray("scale");
  glyphs->SetScaleModeToScaleByMagnitude();
  glyphs->SetScaleFactor(0.5);
  glyphs->SetOrientationArray("direction");
  glyphs->SetOrientationModeToDirection();
  glyphs->SetMaskArray("mask");
  glyphs->MaskingOn();
  vtkNew<vtkActor> actor;
  actor->SetMapper(glyphs);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 2 * 12);
  CHECK(CountFlags(g, 0, 3) == 24);
  CHECK(g->MapPrimitiveId(0, 0) == -1);
  CHECK(g->GetFirstSurfacePrimitive(0) == 0); // a box source: triangles only
  double lo[2][3], hi[2][3];
  for (int k = 0; k < 2; ++k)
  {
    for (int c = 0; c < 3; ++c)
    {
      lo[k][c] = VTK_DOUBLE_MAX;
      hi[k][c] = VTK_DOUBLE_MIN;
    }
    for (vtkIdType t = 12 * k; t < 12 * (k + 1); ++t)
    {
      CHECK(g->GetTriangleCellId(t) == k); // the input point
      for (int v = 0; v < 3; ++v)
      {
        double x[3];
        WorldVertex(g, t, v, x);
        for (int c = 0; c < 3; ++c)
        {
          lo[k][c] = std::min(lo[k][c], x[c]);
          hi[k][c] = std::max(hi[k][c], x[c]);
        }
      }
    }
  }
  // Point 0: scale 0.5, along x: 1 x 0.5 x 0.5. Point 1: scale 1, turned to y: 1 x 2 x 1.
  CHECK(Near(lo[0], -0.5, -0.25, -0.25, 1e-12) && Near(hi[0], 0.5, 0.25, 0.25, 1e-12));
  CHECK(Near(lo[1], 4.5, -1, -0.5, 1e-12) && Near(hi[1], 5.5, 1, 0.5, 1e-12));
  scale->SetValue(1, std::numeric_limits<double>::quiet_NaN());
  scale->Modified();
  vtkNew<vtkTest::ErrorObserver> observer;
  g->AddObserver(vtkCommand::ErrorEvent, observer);
  CHECK(g->Update(renderer) == 0);
  CHECK(observer->GetError());
  CHECK(std::string(g->GetErrorMessage()).find("vtkActor (prop 0)") != std::string::npos);
  return EXIT_SUCCESS;
}

// Splats: a solid per splat covering the disc of radius s * ScaleFactor * TriangleScale the
// drawn triangle always covers; caster-only, receive nothing. ScaleFactor 0: plain points.
int TestSplats()
{
  auto points = MakePolyData({ 0, 0, 0, 10, 0, 0 });
  vtkNew<vtkDoubleArray> size;
  size->SetName("size");
  size->InsertNextValue(1.0);
  size->InsertNextValue(2.0);
  points->GetPointData()->AddArray(size);
  vtkNew<vtkPointGaussianMapper> splats;
  splats->SetInputData(points);
  splats->SetScaleArray("size");
  splats->SetScaleFactor(0.5);
  vtkNew<vtkActor> actor;
  actor->SetMapper(splats);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> g;
  g->SetPixelSize(0.01);
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfTriangles() == 16);
  CHECK(CountFlags(g, 0, Flags::CASTS_SHADOWS) == 16);
  CHECK(g->GetFirstSurfacePrimitive(0) == VTK_ID_MAX);
  const double k = std::sqrt(Pi / (4.0 * std::sqrt(3.0)));
  const double scale = splats->GetTriangleScale();
  for (int s = 0; s < 2; ++s)
  {
    double x[3];
    WorldVertex(g, 8 * s, 0, x);
    const double centre[3] = { 10.0 * s, 0, 0 };
    const double radius = std::sqrt(vtkMath::Distance2BetweenPoints(x, centre));
    CHECK(std::fabs(radius - 2.0 * (1.0 + s) * 0.5 * scale * k) < 1e-12);
    CHECK(g->GetTriangleOwner(8 * s) == -1);
  }
  splats->SetScaleFactor(0.0);
  actor->GetProperty()->SetPointSize(5.0);
  CHECK(g->Update(renderer) == 1);
  double x[3];
  WorldVertex(g, 0, 0, x);
  CHECK(std::fabs(vtkMath::Norm(x) - 0.05 * k) < 1e-12);
  return EXIT_SUCCESS;
}

// A composite 3D prop (like vtkAxesActor): it draws its part actors with their own matrices
// and lists them with GetActors(); without parts it draws nothing we know of.
class CompositeProp : public vtkProp3D
{
public:
  static CompositeProp* New() { VTK_STANDARD_NEW_BODY(CompositeProp); }
  vtkTypeMacro(CompositeProp, vtkProp3D);
  void GetActors(vtkPropCollection* collection) override
  {
    if (this->Part)
    {
      collection->AddItem(this->Part);
    }
  }
  double* GetBounds() override { return this->Part ? this->Part->GetBounds() : nullptr; }
  vtkSmartPointer<vtkActor> Part;
};

// Volumes cast nothing and say so; skyboxes and 2D props are passed over silently; an image
// slice casts its slice quad and says its transparent pixels are not cut out; a composite
// prop casts its parts, and one without parts says it casts nothing.
int TestNotes()
{
  vtkNew<vtkVolume> volume;
  vtkPenumbraSceneGeometry::SetPropName(volume, "ct");
  vtkNew<vtkVolume> hiddenVolume;
  hiddenVolume->VisibilityOff();
  vtkNew<vtkSkybox> skybox;
  vtkNew<vtkImageData> image;
  image->SetDimensions(4, 3, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 4);
  vtkNew<vtkImageSliceMapper> sliceMapper;
  sliceMapper->SetInputData(image);
  vtkNew<vtkImageSlice> slice;
  slice->SetMapper(sliceMapper);
  slice->SetPosition(0, 0, 2);
  vtkNew<vtkRenderer> renderer;
  renderer->AddViewProp(volume);
  renderer->AddViewProp(hiddenVolume);
  renderer->AddViewProp(skybox);
  renderer->AddViewProp(slice);
  vtkNew<CompositeProp> composite;
  composite->Part = MakeActor(UnitSquare());
  composite->Part->SetPosition(0, 0, 7);
  vtkNew<CompositeProp> empty;
  renderer->AddViewProp(composite);
  renderer->AddViewProp(empty);
  vtkNew<vtkPenumbraSceneGeometry> g;
  CHECK(g->Update(renderer) == 1);
  CHECK(g->GetNumberOfCastingNotes() == 3);
  CHECK(g->GetCastingNoteProp(0) == volume.GetPointer());
  CHECK(g->GetCastingNoteProp(2) == empty.GetPointer());
  CHECK(std::string(g->GetCastingNote(0)) == "vtkVolume 'ct' (prop 0): volumes cast no shadows");
  CHECK(g->GetCastingNoteProp(1) == slice.GetPointer());
  CHECK(g->GetCastingNote(3) == nullptr && g->GetCastingNoteProp(-1) == nullptr);
  CHECK(g->GetNumberOfProps() == 2 && g->GetProp(0) == slice.GetPointer());
  CHECK(g->GetProp(1) == composite->Part.GetPointer());
  CHECK(g->GetNumberOfTriangles() == 4 && CountFlags(g, 0, 3) == 2 && CountFlags(g, 1, 3) == 2);
  double w[3];
  WorldVertex(g, 2, 0, w);
  CHECK(w[2] == 7.0); // the part's own matrix
  CHECK(g->GetFirstSurfacePrimitive(0) == 0);
  double bounds[6];
  g->GetBounds(bounds);
  CHECK(bounds[0] == 0 && bounds[1] == 3 && bounds[2] == 0 && bounds[3] == 2);
  CHECK(bounds[4] == 2 && bounds[5] == 7);
  return EXIT_SUCCESS;
}
} // namespace

int TestSceneCasters(int, char*[])
{
  RUN(TestWireframeSquare());
  RUN(TestPointsAndLineCells());
  RUN(TestPixelSize());
  RUN(TestClippingPlanes());
  RUN(TestTextureCutouts());
  RUN(TestScalarAlpha());
  RUN(TestGlyphs());
  RUN(TestSplats());
  RUN(TestNotes());
  return EXIT_SUCCESS;
}
