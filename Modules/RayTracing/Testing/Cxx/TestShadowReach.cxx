// The casters that can shadow a piece of the receivers (penumbra_reach), as a rank of a
// distributed render sends them to a peer. A ground of four quadrants and 64 boxes of
// different heights; "this rank" draws the quadrant x, y < 0, the other quadrants and every box
// belong to "the others". For a low sun, a point light, a rectangle, a line and a sphere light
// the tracer's answers on this rank's samples over its quadrant plus the selected casters
// equal, bit for bit (ties too), those over the whole scene; the selection is a minority of
// the others' triangles, and without it the answers differ (so the test can fail).
#include "vtkCubeSource.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowReach.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPropCollection.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <iostream>

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

using namespace penumbra_test;

namespace
{
constexpr int Res = 48; // samples over this rank's quadrant [-4, 0]^2

// Where the whole scene stands: the origin, then georeferenced (UTM-like) coordinates, where
// the samples' and the tracer's float32 rounding is largest against the scene.
double Offset[3] = { 0, 0, 0 };

// Moves a light's position and focal point by Offset.
void Place(vtkLight* light, double x, double y, double z, double fx, double fy, double fz)
{
  light->SetPosition(x + Offset[0], y + Offset[1], z + Offset[2]);
  light->SetFocalPoint(fx + Offset[0], fy + Offset[1], fz + Offset[2]);
}

// The quadrants other than [-4, 0]^2 and 64 boxes over [-4, 4]^2, 0.3 to 1.7 high.
void AddOthers(vtkRenderer* renderer)
{
  AddRectangle(renderer, 0, 4, -4, 0, 0, Offset);
  AddRectangle(renderer, -4, 0, 0, 4, 0, Offset);
  AddRectangle(renderer, 0, 4, 0, 4, 0, Offset);
  for (int i = 0; i < 8; ++i)
  {
    for (int j = 0; j < 8; ++j)
    {
      const double height = 0.3 + 0.2 * ((3 * i + 5 * j) % 8);
      vtkNew<vtkCubeSource> box;
      box->SetBounds(-3.8 + i, -3.4 + i, -3.8 + j, -3.4 + j, 0.0, height);
      AddActor(renderer, box, Offset);
    }
  }
}

// This rank's quadrant [-4, 0]^2 at z = 0, 8 x 8 squares.
void AddOwn(vtkRenderer* renderer)
{
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-4, -4, 0);
  plane->SetPoint1(0, -4, 0);
  plane->SetPoint2(-4, 0, 0);
  plane->SetResolution(8, 8);
  AddActor(renderer, plane, Offset);
}

// `world` (9 coordinates a triangle) as one polydata actor.
vtkSmartPointer<vtkActor> TrianglesActor(vtkDoubleArray* world, const std::vector<vtkIdType>& ids)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> polys;
  for (vtkIdType t : ids)
  {
    vtkIdType cell[3];
    for (int k = 0; k < 3; ++k)
    {
      cell[k] = points->InsertNextPoint(world->GetPointer(9 * t + 3 * k));
    }
    polys->InsertNextCell(3, cell);
  }
  vtkNew<vtkPolyData> data;
  data->SetPoints(points);
  data->SetPolys(polys);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(data);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  return actor;
}

struct Case
{
  const char* Name;
  vtkSmartPointer<vtkLight> Described; // what the reach is computed from
  vtkSmartPointer<vtkLight> Traced;    // what the tracer shadows (a sphere light's disc)
};

std::vector<Case> Lights()
{
  std::vector<Case> cases;
  auto add = [&](const char* name, vtkLight* light, vtkLight* traced) {
    cases.push_back({ name, light, traced ? traced : light });
  };
  vtkNew<vtkLight> sun; // 25 degrees above the horizon, from +x +y
  sun->SetPositional(false);
  Place(sun, 1.5, 1.0, 1.2, 0, 0, 0);
  add("low sun", sun, nullptr);
  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetConeAngle(180.0);
  Place(point, 1.0, 1.5, 2.5, 1.0, 1.5, 0.0);
  add("point light", point, nullptr);
  vtkNew<vtkPenumbraAreaLight> rectangle;
  Place(rectangle, 2.5, 0.5, 3.0, 2.5, 0.5, 0.0);
  rectangle->SetWidth(1.5);
  rectangle->SetHeight(0.8);
  rectangle->SetSamplesPerAxis(4);
  add("rectangle light", rectangle, nullptr);
  vtkNew<vtkPenumbraAreaLight> line;
  line->SetShapeToLine();
  Place(line, 0.5, 2.5, 2.0, 0.5, 2.5, 0.0);
  line->SetWidth(2.0);
  line->SetSamplesPerAxis(6);
  add("line light", line, nullptr);
  vtkNew<vtkLight> sphere;
  sphere->SetPositional(true);
  sphere->SetConeAngle(180.0);
  Place(sphere, 2.0, 2.0, 2.0, 0.0, 0.0, 0.0);
  vtkPenumbraShadowKeys::SetLightRadius(sphere, 0.6);
  vtkNew<vtkPenumbraAreaLight> disc;
  disc->SetSamplesPerAxis(4);
  if (!disc->SetFromLightRadius(sphere, 0.6))
  {
    return {};
  }
  add("sphere light", sphere, disc);
  return cases;
}

int CheckRegionTests()
{
  const double receivers[6] = { 0, 1, 0, 1, 0, 1 };
  const double casters[6] = { -10, 10, -10, 10, -10, 10 };
  penumbra_reach::LightReach up;
  up.Directional = true;
  up.Direction[2] = 1.0;
  penumbra_reach::Region column(receivers, up, casters);
  const double above[6] = { 0.2, 0.4, 0.2, 0.4, 5, 6 };
  const double beside[6] = { 2, 3, 0, 1, 5, 6 };
  const double below[6] = { 0, 1, 0, 1, -3, -2 };
  const double touching[6] = { 1, 2, 1, 2, 1, 2 }; // shares the corner (1, 1, 1)
  CHECK(column.MayBlock(above));
  CHECK(!column.MayBlock(beside));
  CHECK(!column.MayBlock(below));
  CHECK(column.MayBlock(touching));
  // A point light above the box's corner: the cone towards it, not its bounding box.
  penumbra_reach::LightReach lamp;
  lamp.Points = { 5, 5, 5 };
  penumbra_reach::Region cone(receivers, lamp, casters);
  const double onAxis[6] = { 2.9, 3.1, 2.9, 3.1, 2.9, 3.1 };
  const double offAxis[6] = { 4.0, 4.5, 0.0, 0.5, 0.0, 0.5 }; // inside the hull's bounds only
  CHECK(cone.MayBlock(onAxis));
  CHECK(!cone.MayBlock(offAxis));
  // Rays and boxes (the routing of distributed shadow rays).
  const double o[3] = { 0, 0, 0 }, d[3] = { 1, 1, 0 };
  const double ahead[6] = { 2, 3, 2, 3, -1, 1 }, behind[6] = { -3, -2, -3, -2, -1, 1 };
  CHECK(penumbra_reach::SegmentMeetsBox(o, d, vtkMath::Inf(), ahead));
  CHECK(!penumbra_reach::SegmentMeetsBox(o, d, 1.5, ahead));
  CHECK(!penumbra_reach::SegmentMeetsBox(o, d, vtkMath::Inf(), behind));
  const double flat[3] = { 1, 0, 0 }, slab[6] = { 1, 2, 0.5, 1, -1, 1 };
  CHECK(!penumbra_reach::SegmentMeetsBox(o, flat, vtkMath::Inf(), slab));
  return EXIT_SUCCESS;
}

int CheckSelection(const Case& c)
{
  // The whole scene: this rank's quadrant first (prop 0), then the others.
  vtkNew<vtkRenderer> whole;
  AddOwn(whole);
  AddOthers(whole);
  vtkNew<vtkPenumbraSceneGeometry> all;
  CHECK(all->Update(whole));

  // This rank's receivers and the others' casters, as a rank holds them.
  vtkNew<vtkRenderer> mine;
  AddOwn(mine);
  vtkNew<vtkPenumbraSceneGeometry> own;
  CHECK(own->Update(mine));
  vtkNew<vtkRenderer> theirs;
  AddOthers(theirs);
  vtkNew<vtkPenumbraSceneGeometry> others;
  CHECK(others->Update(theirs));
  vtkNew<vtkDoubleArray> world;
  others->GetCasterWorldTriangles(world);

  penumbra_reach::LightReach reach;
  std::string error;
  CHECK(penumbra_reach::DescribeLight(c.Described, reach, error));
  double bounds[6];
  all->GetBounds(bounds);
  std::vector<penumbra_reach::Region> regions;
  for (const auto& box :
    penumbra_reach::TriangleBoxes(own, vtkPenumbraSceneGeometry::RECEIVES_SHADOWS, 4))
  {
    regions.emplace_back(box.data(), reach, bounds);
  }
  CHECK(regions.size() == 4);
  std::vector<vtkIdType> selected;
  penumbra_reach::SelectTriangles(
    world->GetPointer(0), world->GetNumberOfTuples(), regions, selected);
  std::cout << c.Name << ": " << selected.size() << " of " << world->GetNumberOfTuples()
            << " other triangles selected" << std::endl;
  CHECK(!selected.empty());
  CHECK(2 * static_cast<vtkIdType>(selected.size()) < world->GetNumberOfTuples());

  vtkNew<vtkPropCollection> shadowOnly;
  shadowOnly->AddItem(TrianglesActor(world, selected));
  vtkNew<vtkPenumbraSceneGeometry> held;
  held->SetShadowOnlyProps(shadowOnly);
  CHECK(held->Update(mine));

  // The same samples (this rank's quadrant) against the three sets of casters.
  vtkNew<vtkPenumbraViewSamples> samples;
  FillGroundSamples(samples, all, 0, Offset, Res, -4.0, 0.0);
  vtkNew<vtkFloatArray> exact, near, alone;
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(all);
  CHECK(reference->ComputeVisibility(samples, c.Traced, exact));
  vtkNew<vtkIdTypeArray> exactTies;
  exactTies->DeepCopy(reference->GetTies());
  reference->SetGeometry(held);
  CHECK(reference->ComputeVisibility(samples, c.Traced, near));
  vtkNew<vtkPenumbraReference> local;
  local->SetGeometry(own);
  CHECK(local->ComputeVisibility(samples, c.Traced, alone));
  vtkIdType differ = 0, needed = 0, shadowed = 0;
  for (vtkIdType i = 0; i < exact->GetNumberOfTuples(); ++i)
  {
    differ += exact->GetValue(i) != near->GetValue(i) ? 1 : 0;
    needed += exact->GetValue(i) != alone->GetValue(i) ? 1 : 0;
    shadowed += exact->GetValue(i) < 1.0f ? 1 : 0;
  }
  std::cout << "  " << shadowed << " samples shadowed, " << needed << " by the others' casters, "
            << differ << " differ" << std::endl;
  CHECK(differ == 0);
  CHECK(needed > 0);
  CHECK(reference->GetTies()->GetNumberOfValues() == exactTies->GetNumberOfValues());
  for (vtkIdType i = 0; i < exactTies->GetNumberOfValues(); ++i)
  {
    CHECK(reference->GetTies()->GetValue(i) == exactTies->GetValue(i));
  }
  return EXIT_SUCCESS;
}

// Lights that cast nothing are left out; a light without a direction is refused.
int CheckDescribeLights()
{
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkLight> on, off, dark;
  off->SwitchOff();
  dark->SetIntensity(0.0);
  renderer->AddLight(on);
  renderer->AddLight(off);
  renderer->AddLight(dark);
  CHECK(penumbra_reach::DescribeLights(renderer).size() == 1);
  vtkNew<vtkLight> pointless;
  pointless->SetPositional(false);
  pointless->SetPosition(1, 1, 1);
  pointless->SetFocalPoint(1, 1, 1);
  penumbra_reach::LightReach reach;
  std::string error;
  CHECK(!penumbra_reach::DescribeLight(pointless, reach, error));
  CHECK(error.find("no direction") != std::string::npos);
  return EXIT_SUCCESS;
}
}

int TestShadowReach(int, char*[])
{
  RUN(CheckRegionTests());
  RUN(CheckDescribeLights());
  const std::array<double, 3> offsets[] = { { 0, 0, 0 }, { 652000, 4305000, 180 } };
  for (const auto& offset : offsets)
  {
    std::copy(offset.begin(), offset.end(), Offset);
    std::cout << "scene at (" << Offset[0] << ", " << Offset[1] << ", " << Offset[2] << ")"
              << std::endl;
    const auto cases = Lights();
    CHECK(cases.size() == 5);
    for (const Case& c : cases)
    {
      RUN(CheckSelection(c));
    }
  }
  return EXIT_SUCCESS;
}
