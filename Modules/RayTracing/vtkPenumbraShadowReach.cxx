#include "vtkPenumbraShadowReach.h"

#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace penumbra_reach
{
namespace
{
bool Finite(const double* v, size_t n)
{
  return std::all_of(v, v + n, [](double x) { return std::isfinite(x); });
}

// The 8 corners of `b`.
std::array<std::array<double, 3>, 8> Corners(const double b[6])
{
  std::array<std::array<double, 3>, 8> corners;
  for (int i = 0; i < 8; ++i)
  {
    corners[i] = { b[(i & 1) ? 1 : 0], b[(i & 2) ? 3 : 2], b[(i & 4) ? 5 : 4] };
  }
  return corners;
}

double Diagonal(const double b[6])
{
  return std::sqrt(
    (b[1] - b[0]) * (b[1] - b[0]) + (b[3] - b[2]) * (b[3] - b[2]) + (b[5] - b[4]) * (b[5] - b[4]));
}

void AddPoint(std::vector<double>& points, const double p[3], const double offset[3], double s)
{
  for (int c = 0; c < 3; ++c)
  {
    points.push_back(p[c] + s * offset[c]);
  }
}
}

bool LightReach::operator==(const LightReach& other) const
{
  return this->Directional == other.Directional &&
    std::equal(this->Direction, this->Direction + 3, other.Direction) &&
    this->Points == other.Points;
}

bool DescribeLight(vtkLight* light, LightReach& reach, std::string& error)
{
  reach = LightReach();
  double position[3], focal[3];
  light->GetTransformedPosition(position);
  light->GetTransformedFocalPoint(focal);
  if (!Finite(position, 3) || !Finite(focal, 3))
  {
    error = "light position or focal point is not finite";
    return false;
  }
  if (auto* area = vtkPenumbraAreaLight::SafeDownCast(light))
  {
    // Every sample lies in the rectangle (a disc's bounding square, a line's segment).
    double u[3], v[3], n[3];
    const double w = 0.5 * area->GetWidth(), h = 0.5 * area->GetExtentV();
    if (!area->GetAxes(u, v, n) || !std::isfinite(w) || !std::isfinite(h))
    {
      error = "area light has no frame or a non-finite size";
      return false;
    }
    for (int i = 0; i < 4; ++i)
    {
      double corner[3];
      for (int c = 0; c < 3; ++c)
      {
        corner[c] = ((i & 1) ? w : -w) * u[c] + ((i & 2) ? h : -h) * v[c];
      }
      AddPoint(reach.Points, position, corner, 1.0);
    }
    return true;
  }
  if (!light->GetPositional())
  {
    for (int c = 0; c < 3; ++c)
    {
      reach.Direction[c] = position[c] - focal[c];
    }
    if (!(vtkMath::Normalize(reach.Direction) > 0.0))
    {
      error = "directional light has no direction (position equals focal point)";
      return false;
    }
    reach.Directional = true;
    return true;
  }
  // A sphere light is shadowed as a disc through its centre (vtkPenumbraAreaLight::
  // SetFromLightRadius): inside the cube around the sphere. Any other radius (none, or one
  // the pass refuses) leaves the point.
  const double r = vtkPenumbraShadowKeys::GetLightRadius(light);
  if (std::isfinite(r) && r > 0.0)
  {
    for (int i = 0; i < 8; ++i)
    {
      const double corner[3] = { (i & 1) ? r : -r, (i & 2) ? r : -r, (i & 4) ? r : -r };
      AddPoint(reach.Points, position, corner, 1.0);
    }
  }
  else
  {
    reach.Points.assign(position, position + 3);
  }
  return true;
}

std::vector<LightReach> DescribeLights(vtkRenderer* renderer, std::vector<std::string>* errors)
{
  std::vector<LightReach> reaches;
  vtkCollectionSimpleIterator it;
  vtkLightCollection* lights = renderer->GetLights();
  lights->InitTraversal(it);
  while (vtkLight* light = lights->GetNextLight(it))
  {
    if (!penumbra_rules::LightEmits(light))
    {
      continue;
    }
    LightReach reach;
    std::string error;
    if (DescribeLight(light, reach, error))
    {
      reaches.push_back(std::move(reach));
    }
    else if (errors)
    {
      errors->push_back(error);
    }
  }
  return reaches;
}

double Margin(const double bounds[6])
{
  double largest = 0.0;
  for (int i = 0; i < 6; ++i)
  {
    largest = std::max(largest, std::fabs(bounds[i]));
  }
  return std::max(1e-4 * Diagonal(bounds), 1e-9 * largest);
}

Region::Region(const double receivers[6], const LightReach& light, const double casters[6])
{
  // The points whose convex hull is the region, and the directions of its edges.
  std::vector<std::array<double, 3>> hull, edges;
  const auto box = Corners(receivers);
  hull.assign(box.begin(), box.end());
  if (light.Directional)
  {
    double all[6];
    for (int c = 0; c < 3; ++c)
    {
      all[2 * c] = std::min(receivers[2 * c], casters[2 * c]);
      all[2 * c + 1] = std::max(receivers[2 * c + 1], casters[2 * c + 1]);
    }
    const double length = Diagonal(all);
    for (const auto& p : box)
    {
      hull.push_back({ p[0] + length * light.Direction[0], p[1] + length * light.Direction[1],
        p[2] + length * light.Direction[2] });
    }
    edges.push_back({ light.Direction[0], light.Direction[1], light.Direction[2] });
  }
  else
  {
    const size_t n = light.Points.size() / 3;
    for (size_t k = 0; k < n; ++k)
    {
      const double* q = &light.Points[3 * k];
      hull.push_back({ q[0], q[1], q[2] });
      for (const auto& p : box)
      {
        edges.push_back({ q[0] - p[0], q[1] - p[1], q[2] - p[2] });
      }
      for (size_t l = k + 1; l < n; ++l)
      {
        const double* o = &light.Points[3 * l];
        edges.push_back({ o[0] - q[0], o[1] - q[1], o[2] - q[2] });
      }
    }
  }
  auto add = [&](const double a[3])
  {
    Axis axis{ { a[0], a[1], a[2] }, vtkMath::Inf(), -vtkMath::Inf() };
    for (const auto& p : hull)
    {
      const double x = a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
      axis.Min = std::min(axis.Min, x);
      axis.Max = std::max(axis.Max, x);
    }
    this->Axes.push_back(axis);
  };
  for (int c = 0; c < 3; ++c)
  {
    double e[3] = { 0.0, 0.0, 0.0 };
    e[c] = 1.0;
    add(e);
  }
  // The cross products of the coordinate axes with the region's other edges (the box's own
  // edges are the coordinate axes): with the axes above, every candidate separating axis of
  // the box-shaped hull and a box, and a subset for hulls of more points (still never
  // separating sets that meet).
  for (const auto& d : edges)
  {
    for (int c = 0; c < 3; ++c)
    {
      double e[3] = { 0.0, 0.0, 0.0 }, a[3];
      e[c] = 1.0;
      vtkMath::Cross(e, d.data(), a);
      if (vtkMath::Normalize(a) > 1e-12 * std::max(1.0, vtkMath::Norm(d.data())))
      {
        add(a);
      }
    }
  }
}

bool Region::MayBlock(const double bounds[6]) const
{
  const double centre[3] = { 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
    0.5 * (bounds[4] + bounds[5]) };
  const double half[3] = { 0.5 * (bounds[1] - bounds[0]), 0.5 * (bounds[3] - bounds[2]),
    0.5 * (bounds[5] - bounds[4]) };
  for (const Axis& axis : this->Axes)
  {
    const double* a = axis.A;
    const double mid = a[0] * centre[0] + a[1] * centre[1] + a[2] * centre[2];
    const double radius =
      std::fabs(a[0]) * half[0] + std::fabs(a[1]) * half[1] + std::fabs(a[2]) * half[2];
    if (mid + radius < axis.Min || mid - radius > axis.Max)
    {
      return false;
    }
  }
  return true;
}

void SelectTriangles(const double* xyz, vtkIdType count, const std::vector<Region>& regions,
  std::vector<vtkIdType>& selected)
{
  constexpr vtkIdType block = 64;
  auto bounds = [&](vtkIdType first, vtkIdType last, double b[6])
  {
    b[0] = b[2] = b[4] = vtkMath::Inf();
    b[1] = b[3] = b[5] = -vtkMath::Inf();
    for (const double* p = xyz + 9 * first; p < xyz + 9 * last; p += 3)
    {
      for (int c = 0; c < 3; ++c)
      {
        b[2 * c] = std::min(b[2 * c], p[c]);
        b[2 * c + 1] = std::max(b[2 * c + 1], p[c]);
      }
    }
  };
  std::vector<const Region*> near;
  for (vtkIdType first = 0; first < count; first += block)
  {
    const vtkIdType last = std::min(count, first + block);
    double b[6];
    bounds(first, last, b);
    near.clear();
    for (const Region& region : regions)
    {
      if (region.MayBlock(b))
      {
        near.push_back(&region);
      }
    }
    for (vtkIdType t = first; !near.empty() && t < last; ++t)
    {
      bounds(t, t + 1, b);
      if (std::any_of(near.begin(), near.end(), [&](const Region* r) { return r->MayBlock(b); }))
      {
        selected.push_back(t);
      }
    }
  }
}

std::vector<std::array<double, 6>> TriangleBoxes(
  vtkPenumbraSceneGeometry* geometry, unsigned char flags, int maxBoxes)
{
  std::vector<std::array<double, 6>> boxes;
  const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
  const vtkIdType n = triangles.Size();
  if (n == 0)
  {
    return boxes;
  }
  const double* origin = geometry->GetOrigin();
  std::vector<vtkIdType> chosen;
  for (vtkIdType t = 0; t < n; ++t)
  {
    if (triangles.GetFlags(t) & flags)
    {
      chosen.push_back(t);
    }
  }
  double all[6];
  geometry->GetBounds(all);
  const double margin = vtkMath::AreBoundsInitialized(all) ? Margin(all) : 0.0;
  auto centroid = [&](vtkIdType t, int c)
  {
    double v[9];
    triangles.Get(t, v);
    return v[c] + v[3 + c] + v[6 + c];
  };
  auto boundsOf = [&](const vtkIdType* first, const vtkIdType* last)
  {
    std::array<double, 6> b = { vtkMath::Inf(), -vtkMath::Inf(), vtkMath::Inf(), -vtkMath::Inf(),
      vtkMath::Inf(), -vtkMath::Inf() };
    for (const vtkIdType* t = first; t < last; ++t)
    {
      double v[9];
      triangles.Get(*t, v);
      for (int k = 0; k < 9; ++k)
      {
        const int c = k % 3;
        b[2 * c] = std::min(b[2 * c], v[k]);
        b[2 * c + 1] = std::max(b[2 * c + 1], v[k]);
      }
    }
    return b;
  };
  // Median splits of ranges of `chosen`, the range of the most triangles first.
  std::vector<std::pair<size_t, size_t>> ranges;
  if (!chosen.empty())
  {
    ranges.emplace_back(0, chosen.size());
  }
  while (static_cast<int>(ranges.size()) < maxBoxes)
  {
    auto fullest = std::max_element(ranges.begin(), ranges.end(),
      [](const auto& a, const auto& b) { return a.second - a.first < b.second - b.first; });
    if (fullest == ranges.end() || fullest->second - fullest->first < 2)
    {
      break;
    }
    const auto [first, last] = *fullest;
    const auto b = boundsOf(&chosen[first], &chosen[0] + last);
    int axis = 0;
    for (int c = 1; c < 3; ++c)
    {
      if (b[2 * c + 1] - b[2 * c] > b[2 * axis + 1] - b[2 * axis])
      {
        axis = c;
      }
    }
    const size_t middle = first + (last - first) / 2;
    std::nth_element(chosen.begin() + static_cast<std::ptrdiff_t>(first),
      chosen.begin() + static_cast<std::ptrdiff_t>(middle),
      chosen.begin() + static_cast<std::ptrdiff_t>(last),
      [&](vtkIdType a, vtkIdType c) { return centroid(a, axis) < centroid(c, axis); });
    *fullest = { first, middle };
    ranges.emplace_back(middle, last);
  }
  for (const auto& [first, last] : ranges)
  {
    auto b = boundsOf(&chosen[first], &chosen[0] + last);
    for (int c = 0; c < 3; ++c)
    {
      b[2 * c] += origin[c] - margin;
      b[2 * c + 1] += origin[c] + margin;
    }
    boxes.push_back(b);
  }
  return boxes;
}

bool SegmentMeetsBox(const double o[3], const double d[3], double tmax, const double box[6])
{
  double t0 = 0.0, t1 = tmax;
  for (int c = 0; c < 3; ++c)
  {
    if (d[c] == 0.0)
    {
      if (o[c] < box[2 * c] || o[c] > box[2 * c + 1])
      {
        return false;
      }
      continue;
    }
    double a = (box[2 * c] - o[c]) / d[c], b = (box[2 * c + 1] - o[c]) / d[c];
    if (a > b)
    {
      std::swap(a, b);
    }
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1)
    {
      return false;
    }
  }
  return true;
}
}
