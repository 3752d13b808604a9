// The exact reference against closed forms for hard lights: a box under a point light and a
// square under a directional light cast footprints whose pixel-centre counts are known
// exactly (at the origin and at georeferenced coordinates); spot cones, the facing rule,
// lights that are off, background samples, tie reporting, scene caching and bad input.
#include "vtkCubeSource.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPlaneSource.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

using namespace penumbra_test;

namespace
{
constexpr int Res = 64;
constexpr double Lo = -4.0;
constexpr double Hi = 4.0;
constexpr double Margin = 1e-3; // no pixel centre may be closer than this to a boundary

// Is c strictly inside [x0, x1] x [y0, y1], and far enough from its edges?
bool InsideBox(const double c[2], double x0, double x1, double y0, double y1, bool& onEdge)
{
  const double d = std::min(std::min(std::fabs(c[0] - x0), std::fabs(c[0] - x1)),
    std::min(std::fabs(c[1] - y0), std::fabs(c[1] - y1)));
  onEdge = onEdge || d < Margin;
  return c[0] > x0 && c[0] < x1 && c[1] > y0 && c[1] < y1;
}

struct Scene
{
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkPlaneSource> Ground;
  vtkNew<vtkCubeSource> Box;
  vtkSmartPointer<vtkActor> GroundActor;
  vtkSmartPointer<vtkActor> BoxActor;
  vtkNew<vtkPenumbraSceneGeometry> Geometry;
  vtkNew<vtkPenumbraViewSamples> Samples;
  double Offset[3];

  // Ground [-4, 4]^2 at z = 0; box 2 x 2 x 0.5 centred at (bx, 0, 1): top face at z = 1.25.
  explicit Scene(const double offset[3])
  {
    for (int c = 0; c < 3; ++c)
    {
      this->Offset[c] = offset[c];
    }
    this->Ground->SetOrigin(-4, -4, 0);
    this->Ground->SetPoint1(4, -4, 0);
    this->Ground->SetPoint2(-4, 4, 0);
    this->Box->SetCenter(0, 0, 1);
    this->Box->SetXLength(2);
    this->Box->SetYLength(2);
    this->Box->SetZLength(0.5);
    this->GroundActor = AddActor(this->Renderer, this->Ground, offset);
    this->BoxActor = AddActor(this->Renderer, this->Box, offset);
  }

  bool Update()
  {
    if (!this->Geometry->Update(this->Renderer))
    {
      return false;
    }
    FillGroundSamples(this->Samples, this->Geometry,
      this->Geometry->GetPropIndex(this->GroundActor), this->Offset, Res, Lo, Hi);
    return true;
  }
};

// Shadow of the box's top square [bx-1, bx+1] x [-1, 1] at z = 1.25 from a point light at
// local (lx, ly, lz) directly above the square: the scaled square about the light's foot.
bool InPointFootprint(const double c[2], const double l[3], double bx, bool& onEdge)
{
  const double s = l[2] / (l[2] - 1.25);
  return InsideBox(c, l[0] + s * (bx - 1 - l[0]), l[0] + s * (bx + 1 - l[0]),
    l[1] + s * (-1 - l[1]), l[1] + s * (1 - l[1]), onEdge);
}

// Counts zeros and checks each sample against `expectShadow`; returns the mismatches.
template <typename Predicate>
vtkIdType Mismatches(
  vtkFloatArray* vis, Predicate expectShadow, vtkIdType& shadowed, vtkIdType& expected)
{
  vtkIdType bad = 0;
  shadowed = 0;
  expected = 0;
  for (int j = 0; j < Res; ++j)
  {
    for (int i = 0; i < Res; ++i)
    {
      double c[2];
      PixelCentre(i, j, Res, Lo, Hi, c);
      const bool shadow = expectShadow(c);
      const float v = vis->GetValue(j * Res + i);
      expected += shadow ? 1 : 0;
      shadowed += v == 0.0f ? 1 : 0;
      bad += (shadow ? v != 0.0f : v != 1.0f) ? 1 : 0;
    }
  }
  return bad;
}

// Point light and directional light, analytic footprint counts; returns the shadowed counts
// so the caller can compare the georeferenced run with the one at the origin.
int AnalyticCounts(const double offset[3], vtkIdType counts[3])
{
  Scene scene(offset);
  CHECK(scene.Update());
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(scene.Geometry);
  vtkNew<vtkFloatArray> vis;

  // Point light above the box, off its centre so the footprint is not symmetric.
  const double l[3] = { 0.1, 0.05, 10.0 };
  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetConeAngle(180.0);
  point->SetPosition(offset[0] + l[0], offset[1] + l[1], offset[2] + l[2]);
  point->SetFocalPoint(offset[0], offset[1], offset[2]);
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(vis->GetNumberOfTuples() == Res * Res);
  bool onEdge = false;
  vtkIdType shadowed = 0, expected = 0;
  const vtkIdType bad = Mismatches(
    vis, [&](const double c[2]) { return InPointFootprint(c, l, 0.0, onEdge); }, shadowed,
    expected);
  CHECK(!onEdge);
  std::cout << "point light: shadowed " << shadowed << ", analytic " << expected << ", rays "
            << reference->GetNumberOfRays() << ", ties " << reference->GetNumberOfTies() << "\n";
  CHECK(expected > 200 && expected < Res * Res - 200);
  CHECK(bad == 0);
  CHECK(shadowed == expected);
  CHECK(reference->GetNumberOfTies() == 0);
  CHECK(reference->GetNumberOfRays() == Res * Res);
  counts[0] = shadowed;

  // Spot light straight down with a 23 degree cone (chosen so no pixel centre lies within
  // 1e-3 of the cone's circle on the ground): lit = inside the cone, outside the box
  // footprint; everything outside the cone is 0.
  vtkNew<vtkLight> spot;
  spot->SetPositional(true);
  spot->SetConeAngle(23.0);
  spot->SetPosition(offset[0] + l[0], offset[1] + l[1], offset[2] + l[2]);
  spot->SetFocalPoint(offset[0] + l[0], offset[1] + l[1], offset[2]);
  CHECK(reference->ComputeVisibility(scene.Samples, spot, vis));
  const double radius = l[2] * std::tan(vtkMath::RadiansFromDegrees(23.0));
  vtkIdType spotBad = 0, spotLit = 0, inCone = 0;
  for (int j = 0; j < Res; ++j)
  {
    for (int i = 0; i < Res; ++i)
    {
      double c[2];
      PixelCentre(i, j, Res, Lo, Hi, c);
      const double r = std::hypot(c[0] - l[0], c[1] - l[1]);
      onEdge = onEdge || std::fabs(r - radius) < Margin;
      const bool lit = r < radius && !InPointFootprint(c, l, 0.0, onEdge);
      inCone += r < radius ? 1 : 0;
      spotLit += lit ? 1 : 0;
      spotBad += vis->GetValue(j * Res + i) != (lit ? 1.0f : 0.0f) ? 1 : 0;
    }
  }
  CHECK(!onEdge);
  std::cout << "spot light: in cone " << inCone << ", lit " << spotLit << ", mismatches " << spotBad
            << ", rays " << reference->GetNumberOfRays() << "\n";
  CHECK(spotLit > 100 && inCone < Res * Res);
  CHECK(spotBad == 0);
  CHECK(reference->GetNumberOfRays() == inCone); // no rays outside the cone

  // Directional light from (0.3, -0.2, 1): the top square's shadow is the square shifted by
  // -1.25 * (0.3, -0.2); the box's lower parts project inside the hull of top and bottom.
  // The bottom (z = 0.75) shifts by -0.75 * (0.3, -0.2): the footprint is the convex hull of
  // the two squares, i.e. the union of the squares and the swept band between them.
  vtkNew<vtkLight> sun;
  sun->SetPositional(false);
  sun->SetPosition(offset[0] + 0.3, offset[1] - 0.2, offset[2] + 1.0);
  sun->SetFocalPoint(offset[0], offset[1], offset[2]);
  CHECK(reference->ComputeVisibility(scene.Samples, sun, vis));
  onEdge = false;
  auto sunShadow = [&](const double c[2])
  {
    // Ray from c toward the light crosses the box iff the slab intervals overlap.
    const double d[3] = { 0.3, -0.2, 1.0 };
    double t0 = 0.75 / d[2], t1 = 1.25 / d[2];
    const double lo[2] = { -1, -1 }, hi[2] = { 1, 1 };
    for (int a = 0; a < 2; ++a)
    {
      double ta = (lo[a] - c[a]) / d[a], tb = (hi[a] - c[a]) / d[a];
      if (ta > tb)
      {
        std::swap(ta, tb);
      }
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    onEdge = onEdge || std::fabs(t1 - t0) < Margin;
    return t0 < t1;
  };
  const vtkIdType sunBad = Mismatches(vis, sunShadow, shadowed, expected);
  CHECK(!onEdge);
  std::cout << "directional light: shadowed " << shadowed << ", analytic " << expected << "\n";
  CHECK(expected > 200);
  CHECK(sunBad == 0);
  CHECK(shadowed == expected);
  CHECK(reference->GetNumberOfTies() == 0);
  counts[1] = shadowed;

  // The same light with the box flattened to a 1 mm slab at z = 1.25: its footprint is the
  // top square's corners projected along the light direction (closed form, no slabs).
  scene.Box->SetZLength(1e-3);
  scene.Box->SetCenter(0, 0, 1.25);
  CHECK(scene.Update());
  CHECK(reference->ComputeVisibility(scene.Samples, sun, vis));
  const vtkIdType squareBad = Mismatches(
    vis,
    [&](const double c[2]) {
      return InsideBox(c, -1 - 1.25 * 0.3, 1 - 1.25 * 0.3, -1 + 1.25 * 0.2, 1 + 1.25 * 0.2, onEdge);
    },
    shadowed, expected);
  CHECK(!onEdge);
  CHECK(squareBad == 0);
  CHECK(shadowed == expected);
  counts[2] = shadowed;
  return EXIT_SUCCESS;
}

int Georeferenced()
{
  const double zero[3] = { 0, 0, 0 };
  const double far[3] = { 5.43e6, 5.43e6, 100.0 };
  vtkIdType atOrigin[3], atFar[3];
  RUN(AnalyticCounts(zero, atOrigin));
  RUN(AnalyticCounts(far, atFar));
  for (int i = 0; i < 3; ++i)
  {
    CHECK(atOrigin[i] == atFar[i]);
  }
  return EXIT_SUCCESS;
}

// Facing rule, lights off, background samples.
int Rules()
{
  const double zero[3] = { 0, 0, 0 };
  Scene scene(zero);
  CHECK(scene.Update());
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(scene.Geometry);
  vtkNew<vtkFloatArray> vis;
  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetConeAngle(180.0);
  point->SetPosition(0.1, 0.05, 10.0);

  // Background sample: -1, no ray.
  scene.Samples->GetPropIndices()->SetValue(0, -1);
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(vis->GetValue(0) == -1.0f);
  CHECK(reference->GetNumberOfRays() == Res * Res - 1);

  // Switched off or zero intensity: valid samples 1, background -1, no rays.
  point->SwitchOff();
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfRays() == 0);
  CHECK(vis->GetValue(0) == -1.0f);
  vtkIdType ones = 0;
  for (vtkIdType i = 0; i < Res * Res; ++i)
  {
    ones += vis->GetValue(i) == 1.0f ? 1 : 0;
  }
  CHECK(ones == Res * Res - 1);
  point->SwitchOn();
  point->SetIntensity(0.0);
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfRays() == 0);
  CHECK(vis->GetValue(5) == 1.0f);
  point->SetIntensity(1.0);

  // Normals facing away from the light: shadowed without rays.
  vtkFloatArray* normals = scene.Samples->GetNormals();
  for (vtkIdType i = 0; i < Res * Res; ++i)
  {
    normals->SetComponent(i, 2, -1.0f);
  }
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfRays() == 0);
  vtkIdType zeros = 0;
  for (vtkIdType i = 1; i < Res * Res; ++i)
  {
    zeros += vis->GetValue(i) == 0.0f ? 1 : 0;
  }
  CHECK(zeros == Res * Res - 1);
  return EXIT_SUCCESS;
}

// Unchanged geometry is not rebuilt; a moved prop or changed flags are.
int Caching()
{
  const double zero[3] = { 0, 0, 0 };
  Scene scene(zero);
  CHECK(scene.Update());
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(scene.Geometry);
  vtkNew<vtkFloatArray> vis;
  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetConeAngle(180.0);
  const double l[3] = { 0.1, 0.05, 10.0 };
  point->SetPosition(l[0], l[1], l[2]);
  CHECK(reference->GetNumberOfBuilds() == 0);
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfBuilds() == 1);
  CHECK(reference->GetNumberOfCasterTriangles() == 2 + 12);

  // Update() without changes, SetGeometry() again: same scene.
  CHECK(scene.Update());
  reference->SetGeometry(scene.Geometry);
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfBuilds() == 1);

  // Moving the box rebuilds, and the shadow follows it (analytic count again).
  scene.BoxActor->SetPosition(0.5, 0, 0);
  CHECK(scene.Update());
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfBuilds() == 2);
  bool onEdge = false;
  vtkIdType shadowed = 0, expected = 0;
  CHECK(Mismatches(
          vis, [&](const double c[2]) { return InPointFootprint(c, l, 0.5, onEdge); }, shadowed,
          expected) == 0);
  CHECK(!onEdge && expected > 200);

  // The box's data modified without a change: extracted again, the same triangles, and the
  // scene (which reads the geometry's own float32 points and owners) is kept and still right.
  scene.Box->Modified();
  CHECK(scene.Update());
  CHECK(scene.Geometry->GetNumberOfPropsExtractedLastUpdate() == 1);
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfBuilds() == 2);
  CHECK(Mismatches(
          vis, [&](const double c[2]) { return InPointFootprint(c, l, 0.5, onEdge); }, shadowed,
          expected) == 0);

  // The box stops casting: rebuilt without it, nothing is shadowed.
  vtkPenumbraShadowKeys::SetCastsShadows(scene.BoxActor, false);
  CHECK(scene.Update());
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(reference->GetNumberOfBuilds() == 3);
  CHECK(reference->GetNumberOfCasterTriangles() == 2);
  CHECK(Mismatches(
          vis, [](const double*) { return false; }, shadowed, expected) == 0);
  return EXIT_SUCCESS;
}

// The compact Embree scene (leaves indexing the geometry's float32 points, used above
// CompactAbove occluders) answers every ray as the default one, ties included.
int CompactScene()
{
  const double far[3] = { 3.4e6, 5.4e6, 120.0 };
  Scene scene(far);
  scene.BoxActor->SetOrientation(10, 20, 30); // no edge along an axis
  CHECK(scene.Update());
  vtkNew<vtkLight> point, sun;
  point->SetPositional(true);
  point->SetConeAngle(180.0);
  point->SetPosition(far[0] + 0.7, far[1] - 0.3, far[2] + 6.0);
  sun->SetPosition(far[0] + 1, far[1] + 2, far[2] + 5);
  sun->SetFocalPoint(far[0], far[1], far[2]);
  for (vtkLight* light : { point.GetPointer(), sun.GetPointer() })
  {
    vtkNew<vtkPenumbraReference> plain, compact;
    compact->SetCompactAbove(0);
    vtkNew<vtkFloatArray> a, b;
    for (vtkPenumbraReference* r : { plain.GetPointer(), compact.GetPointer() })
    {
      r->SetGeometry(scene.Geometry);
      CHECK(r->ComputeVisibility(scene.Samples, light, r == plain ? a : b));
    }
    CHECK(!plain->GetCompact() && compact->GetCompact());
    CHECK(plain->GetNumberOfCasterTriangles() == compact->GetNumberOfCasterTriangles());
    vtkIdType shadowed = 0;
    for (vtkIdType i = 0; i < a->GetNumberOfTuples(); ++i)
    {
      CHECK(a->GetValue(i) == b->GetValue(i));
      CHECK(plain->GetTies()->GetValue(i) == compact->GetTies()->GetValue(i));
      shadowed += a->GetValue(i) == 0.0f ? 1 : 0;
    }
    CHECK(shadowed > 100);
  }
  return EXIT_SUCCESS;
}

// SetOccluderSubset: the Embree scene of the listed occluders alone. Every triangle listed
// answers as the default scene; none listed blocks nothing; the same ids again reuse the
// scene; null goes back to every occluder.
int OccluderSubset()
{
  const double far[3] = { 3.4e6, 5.4e6, 120.0 };
  Scene scene(far);
  scene.BoxActor->SetOrientation(10, 20, 30);
  CHECK(scene.Update());
  vtkNew<vtkLight> sun;
  sun->SetPosition(far[0] + 1, far[1] + 2, far[2] + 5);
  sun->SetFocalPoint(far[0], far[1], far[2]);
  vtkNew<vtkPenumbraReference> full, part;
  vtkNew<vtkFloatArray> expected, vis;
  full->SetGeometry(scene.Geometry);
  part->SetGeometry(scene.Geometry);
  CHECK(full->ComputeVisibility(scene.Samples, sun, expected));
  const vtkIdType occluders = full->GetNumberOfCasterTriangles();
  vtkNew<vtkIdTypeArray> all, none;
  for (vtkIdType t = 0; t < scene.Geometry->GetNumberOfTriangles(); ++t)
  {
    all->InsertNextValue(t);
  }
  auto shadowedBy = [&](vtkIdTypeArray* subset, vtkIdType& shadowed)
  {
    part->SetOccluderSubset(subset);
    shadowed = 0;
    if (!part->ComputeVisibility(scene.Samples, sun, vis))
    {
      return false;
    }
    for (vtkIdType i = 0; i < vis->GetNumberOfTuples(); ++i)
    {
      shadowed += vis->GetValue(i) == 0.0f ? 1 : 0;
    }
    return true;
  };
  vtkIdType shadowed = 0;
  CHECK(shadowedBy(all, shadowed));
  CHECK(part->GetNumberOfCasterTriangles() == occluders && part->GetNumberOfBuilds() == 1);
  for (vtkIdType i = 0; i < vis->GetNumberOfTuples(); ++i)
  {
    CHECK(vis->GetValue(i) == expected->GetValue(i));
  }
  CHECK(shadowed > 100);
  CHECK(shadowedBy(all, shadowed)); // the same ids: the same scene
  CHECK(part->GetNumberOfBuilds() == 1);
  const vtkIdType withAll = shadowed;
  CHECK(shadowedBy(none, shadowed));
  CHECK(part->GetNumberOfCasterTriangles() == 0 && part->GetNumberOfBuilds() == 2);
  CHECK(shadowed < withAll);
  CHECK(shadowedBy(nullptr, shadowed));
  CHECK(shadowed == withAll && part->GetNumberOfBuilds() == 3);
  // Ids out of order (or repeated) are refused with a message, never traced as a wrong scene.
  vtkNew<vtkIdTypeArray> unsorted;
  for (vtkIdType t : { 3, 1, 2 })
  {
    unsorted->InsertNextValue(t);
  }
  vtkNew<ErrorCounter> errors;
  part->AddObserver(vtkCommand::ErrorEvent, errors);
  CHECK(!shadowedBy(unsorted, shadowed));
  CHECK(std::string(part->GetErrorMessage()).find("ascending") != std::string::npos);
  CHECK(errors->Count > 0);
  CHECK(shadowedBy(all, shadowed) && shadowed == withAll);
  return EXIT_SUCCESS;
}

// Blockers inside the tie band [tnear, TieFactor * tnear) are reported, never decided
// silently; a real blocker farther away still decides.
int Ties()
{
  // Ground [-1, 1]^2; tie squares at z = 5e-5 (tnear = 1e-5 * diagonal ~ 2.9e-5, band up to
  // ~4.6e-4); blocker squares at z = 0.5.
  vtkNew<vtkRenderer> renderer;
  auto groundActor = AddRectangle(renderer, -1, 1, -1, 1, 0);
  auto square = [&](double x0, double y0, double z)
  { AddRectangle(renderer, x0, x0 + 0.2, y0, y0 + 0.2, z); };
  square(0.2, 0.2, 5e-5);  // over sample A: tie, nothing else -> lit + tie
  square(-0.4, -0.4, 0.5); // over sample B: real blocker -> shadowed, no tie
  square(0.5, -0.7, 5e-5); // over sample C: tie band ...
  square(0.5, -0.7, 0.5);  // ... and a real blocker -> shadowed, no tie
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  CHECK(geometry->Update(renderer));
  vtkNew<vtkPenumbraViewSamples> samples;
  samples->SetSize(4, 1);
  samples->SetOrigin(geometry->GetOrigin());
  samples->SetCameraPosition(0, 0, 10);
  const int groundIndex = geometry->GetPropIndex(groundActor);
  const double at[4][3] = { { 0.3, 0.3, 0 }, { -0.3, -0.3, 0 }, { 0.6, -0.6, 0 },
    { -0.6, 0.6, 0 } };
  const double up[3] = { 0, 0, 1 };
  for (int i = 0; i < 4; ++i)
  {
    samples->SetSample(
      i, at[i], up, groundIndex, FindTriangleXY(geometry, groundIndex, at[i][0], at[i][1]));
  }
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(geometry);
  vtkNew<vtkLight> sun;
  sun->SetPositional(false);
  sun->SetPosition(0, 0, 1);
  sun->SetFocalPoint(0, 0, 0);
  vtkNew<vtkFloatArray> vis;
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  vtkUnsignedCharArray* ties = reference->GetTies();
  CHECK(ties->GetNumberOfTuples() == 4);
  CHECK(vis->GetValue(0) == 1.0f && ties->GetValue(0) == 1);
  CHECK(vis->GetValue(1) == 0.0f && ties->GetValue(1) == 0);
  CHECK(vis->GetValue(2) == 0.0f && ties->GetValue(2) == 0);
  CHECK(vis->GetValue(3) == 1.0f && ties->GetValue(3) == 0);
  CHECK(reference->GetNumberOfTies() == 1);

  // The compact scene, asked for after a build: built again, the same answers, the tie too.
  CHECK(!reference->GetCompact() && reference->GetNumberOfBuilds() == 1);
  reference->SetCompactAbove(0);
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  CHECK(reference->GetCompact() && reference->GetNumberOfBuilds() == 2);
  ties = reference->GetTies();
  CHECK(vis->GetValue(0) == 1.0f && ties->GetValue(0) == 1);
  CHECK(vis->GetValue(1) == 0.0f && ties->GetValue(1) == 0);
  CHECK(vis->GetValue(2) == 0.0f && ties->GetValue(2) == 0);
  CHECK(vis->GetValue(3) == 1.0f && ties->GetValue(3) == 0);
  CHECK(reference->GetNumberOfTies() == 1);

  // TieFactor 1 empties the band: the near square lies beyond tnear, so it now blocks and
  // the sample is decided as shadowed without a tie.
  reference->SetTieFactor(1.0);
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  CHECK(vis->GetValue(0) == 0.0f && reference->GetNumberOfTies() == 0);
  return EXIT_SUCCESS;
}

// Bad input: 0, a message, no crash, outputs untouched.
int BadInput()
{
  const double zero[3] = { 0, 0, 0 };
  Scene scene(zero);
  CHECK(scene.Update());
  vtkNew<vtkPenumbraReference> reference;
  vtkNew<ErrorCounter> errors;
  reference->AddObserver(vtkCommand::ErrorEvent, errors);
  vtkNew<vtkFloatArray> vis;
  vis->SetNumberOfTuples(3);
  vtkNew<vtkLight> point;
  point->SetPositional(true);
  point->SetPosition(0, 0, 10);

  CHECK(!reference->ComputeVisibility(scene.Samples, point, vis)); // no geometry
  CHECK(std::string(reference->GetErrorMessage()).find("SetGeometry") != std::string::npos);
  reference->SetGeometry(scene.Geometry);
  CHECK(!reference->ComputeVisibility(nullptr, point, vis));
  CHECK(std::string(reference->GetErrorMessage()).find("no view samples") != std::string::npos);
  CHECK(!reference->ComputeVisibility(scene.Samples, nullptr, vis));
  CHECK(!reference->ComputeVisibility(scene.Samples, point, nullptr));

  vtkNew<vtkLight> noDirection;
  noDirection->SetPositional(false);
  noDirection->SetPosition(1, 1, 1);
  noDirection->SetFocalPoint(1, 1, 1);
  CHECK(!reference->ComputeVisibility(scene.Samples, noDirection, vis));
  CHECK(std::string(reference->GetErrorMessage()).find("direction") != std::string::npos);

  vtkNew<vtkPenumbraAreaLight> flat;
  flat->SetPosition(0, 0, 10);
  flat->SetFocalPoint(0, 0, 0);
  flat->SetWidth(0.0);
  CHECK(!reference->ComputeVisibility(scene.Samples, flat, vis));
  CHECK(std::string(reference->GetErrorMessage()).find("invalid area light") != std::string::npos);
  flat->SetWidth(1.0);
  CHECK(!reference->ComputeConvergedVisibility(scene.Samples, flat, 0, vis));
  CHECK(!reference->ComputeConvergedVisibility(scene.Samples, flat, 257, vis));
  CHECK(!reference->ComputeAreaMasks(scene.Samples, flat, nullptr));

  scene.Samples->GetNormals()->SetNumberOfTuples(7);
  CHECK(!reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(std::string(reference->GetErrorMessage()).find("do not match") != std::string::npos);
  CHECK(vis->GetNumberOfTuples() == 3); // untouched
  CHECK(errors->Count == 10);
  CHECK(errors->Last.find("vtkPenumbraReference") != std::string::npos);

  // A good call clears the message.
  scene.Samples->SetSize(2, 2);
  CHECK(reference->ComputeVisibility(scene.Samples, point, vis));
  CHECK(std::string(reference->GetErrorMessage()).empty());
  CHECK(vis->GetNumberOfTuples() == 4 && vis->GetValue(0) == -1.0f);

  // Empty geometry: a renderer without props; every valid, light-facing sample is lit.
  vtkNew<vtkRenderer> empty;
  vtkNew<vtkPenumbraSceneGeometry> none;
  CHECK(none->Update(empty));
  reference->SetGeometry(none);
  vtkNew<vtkPenumbraViewSamples> samples;
  samples->SetSize(3, 1);
  samples->SetCameraPosition(0, 0, 10);
  const double up[3] = { 0, 0, 1 };
  for (int i = 0; i < 3; ++i)
  {
    const double p[3] = { double(i), 0, 0 };
    samples->SetSample(i, p, up, 0, -1);
  }
  CHECK(reference->ComputeVisibility(samples, point, vis));
  CHECK(vis->GetValue(0) == 1.0f && vis->GetValue(1) == 1.0f && vis->GetValue(2) == 1.0f);
  CHECK(reference->GetNumberOfCasterTriangles() == 0);
  return EXIT_SUCCESS;
}
}

int TestReferenceHard(int, char*[])
{
  RUN(Georeferenced());
  RUN(Rules());
  RUN(Caching());
  RUN(CompactScene());
  RUN(OccluderSubset());
  RUN(Ties());
  RUN(BadInput());
  return EXIT_SUCCESS;
}
