#include "vtkPenumbraVisibilityRules.h"

#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraSceneTriangles.h"

#include <algorithm>
#include <cmath>

namespace penumbra_rules
{
bool LightEmits(vtkLight* light)
{
  if (!light || !light->GetSwitch() || !(light->GetIntensity() > 0.0))
  {
    return false;
  }
  const double* c = light->GetDiffuseColor();
  const double* s = light->GetSpecularColor();
  return c[0] > 0 || c[1] > 0 || c[2] > 0 || s[0] > 0 || s[1] > 0 || s[2] > 0;
}

double SceneDiagonal(vtkPenumbraSceneGeometry* geometry)
{
  double bounds[6];
  geometry->GetBounds(bounds);
  double diagonal = 0.0;
  if (vtkMath::AreBoundsInitialized(bounds))
  {
    diagonal = std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) +
      (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) +
      (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
  }
  return std::isfinite(diagonal) && diagonal > 0.0 ? diagonal : 1.0;
}

RayBand SampleBand(const double p[3], double diagonal, double epsilon, double tieFactor)
{
  RayBand band;
  // max(|p|, D) without the square root where |p|^2 lies clearly below D^2 (the usual case:
  // the frame is rebased near the scene), the same value bit for bit: sqrt rounds
  // monotonically, and the margin covers the rounding of both squares.
  const double squared = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
  band.Scale = squared < diagonal * diagonal * (1.0 - 1e-12)
    ? diagonal
    : std::max(std::sqrt(squared), diagonal);
  band.TNear = epsilon * band.Scale;
  band.TieLimit = tieFactor * epsilon * band.Scale;
  return band;
}

bool MakeExactTriangle(const double* v9, vtkIdType id, ExactTriangle& c)
{
  for (int i = 0; i < 3; ++i)
  {
    for (int k = 0; k < 3; ++k)
    {
      c.V[i][k] = static_cast<double>(static_cast<float>(v9[3 * i + k]));
    }
  }
  double e1[3], e2[3];
  for (int k = 0; k < 3; ++k)
  {
    e1[k] = c.V[1][k] - c.V[0][k];
    e2[k] = c.V[2][k] - c.V[0][k];
  }
  vtkMath::Cross(e1, e2, c.N);
  const double area2 = vtkMath::Normalize(c.N);
  if (!(area2 > 0.0) || !std::isfinite(area2))
  {
    return false; // zero area after rounding: Embree cannot hit it either
  }
  for (int e = 0; e < 3; ++e)
  {
    const double* a = c.V[e];
    const double* b = c.V[(e + 1) % 3];
    const double ab[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    vtkMath::Cross(c.N, ab, c.M[e]); // points to the left of ab, i.e. inside for CCW
    if (!(vtkMath::Normalize(c.M[e]) > 0.0))
    {
      return false;
    }
    c.MD[e] = vtkMath::Dot(c.M[e], a);
  }
  c.Id = id;
  return true;
}

bool MakeOccluder(const penumbra::SceneTriangles& triangles, vtkIdType t, ExactTriangle& c)
{
  const penumbra::SceneTriangles::Block& b = triangles.BlockOf(t);
  const vtkIdType local = t - b.First;
  if (!triangles.IsOccluderLocal(b, local))
  {
    return false;
  }
  double v[9];
  triangles.GetLocal(b, local, v);
  return MakeExactTriangle(v, penumbra::SceneTriangles::GetOwnerLocal(b, local), c);
}

Hit SegmentTest(const double o[3], const double d[3], double tieLimit, double tmax,
  const ExactTriangle& tri, double errPos, int& edge)
{
  const double cosine = vtkMath::Dot(d, tri.N);
  if (!(std::fabs(cosine) > 1e-6))
  {
    return Hit::Unknown; // grazing: a float rounding of the direction moves the hit anywhere
  }
  const double height = tri.N[0] * (tri.V[0][0] - o[0]) + tri.N[1] * (tri.V[0][1] - o[1]) +
    tri.N[2] * (tri.V[0][2] - o[2]);
  const double slack = errPos * (1.0 + 1.0 / std::fabs(cosine));
  const double t = height / cosine;
  if (t < tieLimit - slack || t > tmax + slack)
  {
    return Hit::Miss;
  }
  const bool clearT = t > tieLimit + slack && t < tmax - slack;
  const double x[3] = { o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2] };
  int near = 0;
  for (int e = 0; e < 3; ++e)
  {
    const double distance = vtkMath::Dot(tri.M[e], x) - tri.MD[e];
    if (distance < -slack)
    {
      return Hit::Miss;
    }
    if (!(distance > slack))
    {
      ++near;
      edge = e;
    }
  }
  if (!clearT || near > 1)
  {
    return Hit::Unknown;
  }
  return near == 0 ? Hit::Clear : Hit::OnEdge;
}
}
