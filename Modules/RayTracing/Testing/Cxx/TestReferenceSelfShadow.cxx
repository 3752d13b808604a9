// Samples lying exactly on a tessellated sphere's own triangles (centres, near corners, on
// shared edges) under a directional light: no false shadow on the lit side, at the origin and
// at georeferenced coordinates. Own-triangle exclusion alone (epsilon 0) is enough for
// interior samples, and without it epsilon 0 shows acne, so both mechanisms are exercised.
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkPenumbraReference.h"
#include "vtkSphereSource.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

using namespace penumbra_test;

namespace
{
const double Barycentric[4][3] = { { 1.0 / 3, 1.0 / 3, 1.0 / 3 }, { 0.98, 0.01, 0.01 },
  { 0.5, 0.5, 0.0 }, { 0.01, 0.495, 0.495 } };

// One sample per (triangle, barycentric point), exactly on the triangle (up to float32),
// with the outward geometric normal; `points` = how many of Barycentric to use.
void SphereSamples(vtkPenumbraSceneGeometry* geometry, int prop, int points,
  vtkPenumbraViewSamples* samples, bool withIds)
{
  const vtkIdType first = geometry->GetPropTriangleOffset(prop);
  const vtkIdType count = geometry->GetPropTriangleCount(prop);
  samples->SetSize(static_cast<int>(count * points), 1);
  samples->SetOrigin(geometry->GetOrigin());
  double centre[3];
  double bounds[6];
  geometry->GetBounds(bounds);
  double origin[3];
  geometry->GetOrigin(origin);
  for (int c = 0; c < 3; ++c)
  {
    centre[c] = 0.5 * (bounds[2 * c] + bounds[2 * c + 1]) - origin[c];
  }
  for (vtkIdType t = 0; t < count; ++t)
  {
    double v[9];
    geometry->GetTriangle(first + t, v);
    const double e1[3] = { v[3] - v[0], v[4] - v[1], v[5] - v[2] };
    const double e2[3] = { v[6] - v[0], v[7] - v[1], v[8] - v[2] };
    double n[3];
    vtkMath::Cross(e1, e2, n);
    vtkMath::Normalize(n);
    const double out[3] = { v[0] - centre[0], v[1] - centre[1], v[2] - centre[2] };
    if (vtkMath::Dot(n, out) < 0)
    {
      n[0] = -n[0];
      n[1] = -n[1];
      n[2] = -n[2];
    }
    for (int b = 0; b < points; ++b)
    {
      const vtkIdType s = t * points + b;
      for (int c = 0; c < 3; ++c)
      {
        const double p =
          Barycentric[b][0] * v[c] + Barycentric[b][1] * v[3 + c] + Barycentric[b][2] * v[6 + c];
        samples->GetPositions()->SetComponent(s, c, static_cast<float>(p));
        samples->GetNormals()->SetComponent(s, c, static_cast<float>(n[c]));
      }
      samples->GetPropIndices()->SetValue(s, prop);
      samples->GetTriangleIds()->SetValue(s, withIds ? first + t : -1);
    }
  }
}

// Lit-side samples (N.L > 0.05) reported shadowed; also checks the facing rule on the rest.
vtkIdType FalseShadows(vtkPenumbraViewSamples* samples, vtkFloatArray* vis, const double l[3],
  vtkIdType& litSide, vtkIdType& badBackSide)
{
  vtkIdType bad = 0;
  litSide = 0;
  badBackSide = 0;
  for (vtkIdType s = 0; s < samples->GetNumberOfSamples(); ++s)
  {
    double n[3];
    for (int c = 0; c < 3; ++c)
    {
      n[c] = samples->GetNormals()->GetComponent(s, c);
    }
    const double d = vtkMath::Dot(n, l);
    if (d > 0.05)
    {
      ++litSide;
      bad += vis->GetValue(s) != 1.0f ? 1 : 0;
    }
    else if (d <= 0.0)
    {
      badBackSide += vis->GetValue(s) != 0.0f ? 1 : 0;
    }
  }
  return bad;
}

int Sphere(const double offset[3])
{
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(1.0);
  sphere->SetThetaResolution(48);
  sphere->SetPhiResolution(32);
  auto actor = AddActor(renderer, sphere, offset);
  vtkNew<vtkPenumbraSceneGeometry> geometry;
  CHECK(geometry->Update(renderer));
  const int prop = geometry->GetPropIndex(actor);
  CHECK(geometry->GetPropTriangleCount(prop) > 2000);

  double l[3] = { 0.3, 0.5, 0.8 };
  vtkMath::Normalize(l);
  vtkNew<vtkLight> sun;
  sun->SetPositional(false);
  sun->SetPosition(offset[0] + l[0], offset[1] + l[1], offset[2] + l[2]);
  sun->SetFocalPoint(offset[0], offset[1], offset[2]);

  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(geometry);
  vtkNew<vtkPenumbraViewSamples> samples;
  vtkNew<vtkFloatArray> vis;
  vtkIdType litSide = 0, badBack = 0;

  // Default epsilon and own-triangle exclusion, all four kinds of points.
  SphereSamples(geometry, prop, 4, samples, true);
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  const vtkIdType bad = FalseShadows(samples, vis, l, litSide, badBack);
  std::cout << "sphere at offset " << offset[0] << ": " << samples->GetNumberOfSamples()
            << " samples, " << litSide << " lit-side, false shadows " << bad << ", ties "
            << reference->GetNumberOfTies() << "\n";
  CHECK(litSide > 1000);
  CHECK(bad == 0);
  CHECK(badBack == 0);
  CHECK(reference->GetNumberOfTies() == 0);

  // Own-triangle exclusion alone (no epsilon, no tie band), interior points.
  reference->SetRelativeEpsilon(0.0);
  reference->SetTieFactor(1.0);
  SphereSamples(geometry, prop, 1, samples, true);
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  CHECK(FalseShadows(samples, vis, l, litSide, badBack) == 0);

  // Without the triangle ids and without epsilon the receiver shadows itself: the two rules
  // above are what keeps the first checks acne-free.
  SphereSamples(geometry, prop, 1, samples, false);
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  const vtkIdType acne = FalseShadows(samples, vis, l, litSide, badBack);
  std::cout << "  no ids, epsilon 0: " << acne << " of " << litSide << " lit-side samples "
            << "self-shadowed\n";
  CHECK(acne > 0);

  // Epsilon alone (no ids) is also enough for interior points.
  reference->SetRelativeEpsilon(1e-5);
  CHECK(reference->ComputeVisibility(samples, sun, vis));
  CHECK(FalseShadows(samples, vis, l, litSide, badBack) == 0);
  return EXIT_SUCCESS;
}
}

int TestReferenceSelfShadow(int, char*[])
{
  const double zero[3] = { 0, 0, 0 };
  const double far[3] = { 5.43e6, -2.1e6, 310.0 };
  RUN(Sphere(zero));
  RUN(Sphere(far));
  return EXIT_SUCCESS;
}
