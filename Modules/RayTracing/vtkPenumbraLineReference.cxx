#include "vtkPenumbraLineReference.h"

#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkSMPTools.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkPenumbraLineReference);
vtkCxxSetObjectMacro(vtkPenumbraLineReference, Geometry, vtkPenumbraSceneGeometry);

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;
using penumbra_rules::ExactTriangle;

constexpr int LeafSize = 4;

struct Node
{
  double Lo[3], Hi[3];
  int Left = -1; // inner node: children Left and Left + 1; leaf: -1
  int First = 0; // leaf: first index into the triangle order
  int Count = 0; // leaf: number of triangles
};

// Separating-axis overlap of a triangle and an axis-aligned box (centre c, half sizes h):
// Akenine-Moller, "Fast 3D Triangle-Box Overlap Testing", JGT 2001. Degenerate axes pass,
// so the test is conservative (the interval clip decides exactly afterwards).
bool TriangleMeetsBox(const double c[3], const double h[3], const double t[3][3])
{
  double v[3][3];
  for (int i = 0; i < 3; ++i)
  {
    for (int k = 0; k < 3; ++k)
    {
      v[i][k] = t[i][k] - c[k];
    }
  }
  for (int k = 0; k < 3; ++k)
  {
    const double lo = std::min({ v[0][k], v[1][k], v[2][k] });
    const double hi = std::max({ v[0][k], v[1][k], v[2][k] });
    if (lo > h[k] || hi < -h[k])
    {
      return false;
    }
  }
  auto separates = [&](const double a[3])
  {
    const double p0 = vtkMath::Dot(a, v[0]), p1 = vtkMath::Dot(a, v[1]), p2 = vtkMath::Dot(a, v[2]);
    const double r = h[0] * std::fabs(a[0]) + h[1] * std::fabs(a[1]) + h[2] * std::fabs(a[2]);
    return std::min({ p0, p1, p2 }) > r || std::max({ p0, p1, p2 }) < -r;
  };
  double e[3][3];
  for (int i = 0; i < 3; ++i)
  {
    for (int k = 0; k < 3; ++k)
    {
      e[i][k] = v[(i + 1) % 3][k] - v[i][k];
    }
  }
  for (int i = 0; i < 3; ++i)
  {
    const double axes[3][3] = { { 0, e[i][2], -e[i][1] }, { -e[i][2], 0, e[i][0] },
      { e[i][1], -e[i][0], 0 } };
    for (const auto& a : axes)
    {
      if (separates(a))
      {
        return false;
      }
    }
  }
  double n[3];
  vtkMath::Cross(e[0], e[1], n);
  return !separates(n);
}

// Keeps the t in [lo, hi] with a + b t >= 0; false when nothing is left.
bool Clip(double a, double b, double& lo, double& hi)
{
  if (b > 0.0)
  {
    lo = std::max(lo, -a / b);
  }
  else if (b < 0.0)
  {
    hi = std::min(hi, -a / b);
  }
  else if (a < 0.0)
  {
    return false;
  }
  return lo < hi;
}

// The segment's light points x(t) = A + t (B - A), t in [lo, hi], that `tri` hides from p:
// inside the three planes through p and an edge, and beyond the triangle's plane by more
// than the ray's end shortening. Returns false for an empty interval. `planeDistance`
// receives |N.(p - V0)|.
bool BlockedInterval(const double p[3], const double a[3], const double ab[3],
  const ExactTriangle& tri, double endFraction, double& lo, double& hi, double& planeDistance)
{
  const double pv[3] = { p[0] - tri.V[0][0], p[1] - tri.V[0][1], p[2] - tri.V[0][2] };
  const double dp = vtkMath::Dot(tri.N, pv);
  planeDistance = std::fabs(dp);
  if (dp == 0.0)
  {
    return false; // segments from a point in the plane only touch it at that point
  }
  const double s = dp > 0.0 ? 1.0 : -1.0;
  const double av[3] = { a[0] - tri.V[0][0], a[1] - tri.V[0][1], a[2] - tri.V[0][2] };
  // Beyond the plane: s N.(x(t) - V0) < -c, with c chosen so that the crossing is before
  // the ray's shortened end: d_p / (d_p - d_x) < 1 - eps  <=>  d_x < -eps / (1 - eps) d_p.
  const double c = endFraction * planeDistance;
  if (!Clip(-c - s * vtkMath::Dot(tri.N, av), -s * vtkMath::Dot(tri.N, ab), lo, hi))
  {
    return false;
  }
  const double ap[3] = { a[0] - p[0], a[1] - p[1], a[2] - p[2] };
  for (int e = 0; e < 3; ++e)
  {
    const double* v0 = tri.V[e];
    const double* v1 = tri.V[(e + 1) % 3];
    const double* v2 = tri.V[(e + 2) % 3];
    const double r0[3] = { v0[0] - p[0], v0[1] - p[1], v0[2] - p[2] };
    const double r1[3] = { v1[0] - p[0], v1[1] - p[1], v1[2] - p[2] };
    const double r2[3] = { v2[0] - p[0], v2[1] - p[1], v2[2] - p[2] };
    double n[3];
    vtkMath::Cross(r0, r1, n);
    if (vtkMath::Dot(n, r2) < 0.0)
    {
      n[0] = -n[0];
      n[1] = -n[1];
      n[2] = -n[2];
    }
    if (!Clip(vtkMath::Dot(n, ap), vtkMath::Dot(n, ab), lo, hi))
    {
      return false;
    }
  }
  return true;
}

// Sorts `intervals` (all starting at or after `lo`) and returns the length of their union.
double CoveredLength(std::vector<std::pair<double, double>>& intervals, double lo)
{
  std::sort(intervals.begin(), intervals.end());
  double covered = 0.0, runLo = lo, runHi = lo;
  for (const auto& interval : intervals)
  {
    if (interval.first > runHi)
    {
      covered += runHi - runLo;
      runLo = interval.first;
      runHi = interval.second;
    }
    else
    {
      runHi = std::max(runHi, interval.second);
    }
  }
  covered += runHi - runLo;
  return covered;
}
}

struct vtkPenumbraLineReference::Internals
{
  std::string Error;
  std::vector<ExactTriangle> Triangles; // casters, rounded as the tracer's copy
  std::vector<int> Order;               // leaf ranges index this
  std::vector<Node> Nodes;
  double Diagonal = 1.0;
  penumbra::CastersStamp Built; // what the hierarchy was built from
  vtkNew<vtkUnsignedCharArray> Ties;

  void Bounds(int first, int count, double lo[3], double hi[3]) const
  {
    for (int k = 0; k < 3; ++k)
    {
      lo[k] = std::numeric_limits<double>::infinity();
      hi[k] = -std::numeric_limits<double>::infinity();
    }
    for (int i = first; i < first + count; ++i)
    {
      const ExactTriangle& t = this->Triangles[static_cast<size_t>(this->Order[i])];
      for (int v = 0; v < 3; ++v)
      {
        for (int k = 0; k < 3; ++k)
        {
          lo[k] = std::min(lo[k], t.V[v][k]);
          hi[k] = std::max(hi[k], t.V[v][k]);
        }
      }
    }
  }

  // Median split on the longest axis of the node's box; children stored next to each other.
  void Build()
  {
    this->Nodes.clear();
    this->Order.resize(this->Triangles.size());
    for (size_t i = 0; i < this->Order.size(); ++i)
    {
      this->Order[i] = static_cast<int>(i);
    }
    if (this->Triangles.empty())
    {
      return;
    }
    this->Nodes.reserve(2 * this->Triangles.size() / LeafSize + 2);
    this->Nodes.emplace_back();
    std::vector<std::pair<int, std::pair<int, int>>> todo = { { 0,
      { 0, static_cast<int>(this->Triangles.size()) } } };
    while (!todo.empty())
    {
      const int index = todo.back().first;
      const int first = todo.back().second.first;
      const int count = todo.back().second.second;
      todo.pop_back();
      Node node;
      this->Bounds(first, count, node.Lo, node.Hi);
      if (count <= LeafSize)
      {
        node.First = first;
        node.Count = count;
        this->Nodes[static_cast<size_t>(index)] = node;
        continue;
      }
      int axis = 0;
      for (int k = 1; k < 3; ++k)
      {
        axis = node.Hi[k] - node.Lo[k] > node.Hi[axis] - node.Lo[axis] ? k : axis;
      }
      const int half = count / 2;
      auto centre = [&](int t)
      {
        const ExactTriangle& tri = this->Triangles[static_cast<size_t>(t)];
        return tri.V[0][axis] + tri.V[1][axis] + tri.V[2][axis];
      };
      std::nth_element(this->Order.begin() + first, this->Order.begin() + first + half,
        this->Order.begin() + first + count, [&](int x, int y) { return centre(x) < centre(y); });
      node.Left = static_cast<int>(this->Nodes.size());
      this->Nodes[static_cast<size_t>(index)] = node;
      this->Nodes.emplace_back();
      this->Nodes.emplace_back();
      todo.push_back({ node.Left, { first, half } });
      todo.push_back({ node.Left + 1, { first + half, count - half } });
    }
  }

  // Calls visit(triangle) for every caster whose node boxes meet the triangle `query`.
  template <typename Visit>
  void Query(const double query[3][3], double margin, Visit&& visit) const
  {
    if (this->Nodes.empty())
    {
      return;
    }
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0)
    {
      const Node& node = this->Nodes[static_cast<size_t>(stack[--top])];
      double c[3], h[3];
      for (int k = 0; k < 3; ++k)
      {
        c[k] = 0.5 * (node.Lo[k] + node.Hi[k]);
        h[k] = 0.5 * (node.Hi[k] - node.Lo[k]) + margin;
      }
      if (!TriangleMeetsBox(c, h, query))
      {
        continue;
      }
      if (node.Left < 0)
      {
        for (int i = node.First; i < node.First + node.Count; ++i)
        {
          visit(this->Triangles[static_cast<size_t>(this->Order[static_cast<size_t>(i)])]);
        }
      }
      else if (top + 2 <= 128)
      {
        stack[top++] = node.Left;
        stack[top++] = node.Left + 1;
      }
    }
  }

  // One sample's visible length of the light segment a + t ab, t in [0, 1], in [0, 1]: the
  // part above its tangent plane less the union of the intervals the triangles block.
  // `blocked` is scratch; `tie` is set when a hit may lie in the tracer's tie band.
  float SampleVisibility(const double p[3], const double normal[3], vtkIdType own,
    const double a[3], const double ab[3], double epsilon, double endFraction, double tieFactor,
    std::vector<std::pair<double, double>>& blocked, bool& tie, vtkIdType& candidates) const
  {
    // Tangent plane: only light points with N.(x(t) - p) > 0 can count.
    double lo = 0.0, hi = 1.0;
    const double ap[3] = { a[0] - p[0], a[1] - p[1], a[2] - p[2] };
    const double f0 = vtkMath::Dot(normal, ap), f1 = vtkMath::Dot(normal, ab);
    if (!Clip(f0, f1, lo, hi) || (f1 == 0.0 && f0 == 0.0))
    {
      return 0.0f;
    }
    const double query[3][3] = { { p[0], p[1], p[2] },
      { a[0] + lo * ab[0], a[1] + lo * ab[1], a[2] + lo * ab[2] },
      { a[0] + hi * ab[0], a[1] + hi * ab[1], a[2] + hi * ab[2] } };
    const penumbra_rules::RayBand band =
      penumbra_rules::SampleBand(p, this->Diagonal, epsilon, tieFactor);
    blocked.clear();
    this->Query(query, 1e-9 * band.Scale,
      [&](const ExactTriangle& tri)
      {
        if (penumbra_rules::IsOwnCaster(tri.Id, own))
        {
          return;
        }
        ++candidates;
        double tlo = lo, thi = hi, planeDistance = 0.0;
        if (!BlockedInterval(p, a, ab, tri, endFraction, tlo, thi, planeDistance))
        {
          return;
        }
        if (planeDistance < band.TieLimit)
        {
          tie = true; // every hit could be inside the tracer's tie band
          return;
        }
        blocked.emplace_back(tlo, thi);
      });
    const double covered = CoveredLength(blocked, lo);
    return static_cast<float>(std::min(1.0, std::max(0.0, (hi - lo) - covered)));
  }
};

//------------------------------------------------------------------------------
vtkPenumbraLineReference::vtkPenumbraLineReference()
  : Geometry(nullptr)
  , RelativeEpsilon(penumbra_rules::DefaultRelativeEpsilon)
  , TieFactor(penumbra_rules::DefaultTieFactor)
  , NumberOfTies(0)
  , NumberOfCandidates(0)
  , LastTimeMs(0.0)
  , NumberOfBuilds(0)
  , Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraLineReference::~vtkPenumbraLineReference()
{
  this->SetGeometry(nullptr);
}

//------------------------------------------------------------------------------
vtkUnsignedCharArray* vtkPenumbraLineReference::GetTies()
{
  return this->Impl->Ties;
}

//------------------------------------------------------------------------------
const char* vtkPenumbraLineReference::GetErrorMessage()
{
  return this->Impl->Error.c_str();
}

//------------------------------------------------------------------------------
int vtkPenumbraLineReference::Fail(const std::string& text)
{
  this->Impl->Error = text;
  PENUMBRA_FAIL(this->Impl->Error);
}

//------------------------------------------------------------------------------
int vtkPenumbraLineReference::EnsureHierarchy()
{
  Internals& impl = *this->Impl;
  vtkPenumbraSceneGeometry* geometry = this->Geometry;
  if (!impl.Built.Changed(geometry))
  {
    return 1;
  }
  const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
  const vtkIdType n = triangles.Size();
  if (n > std::numeric_limits<int>::max() / 2)
  {
    return this->Fail("scene geometry has too many triangles for the line reference");
  }
  impl.Triangles.clear();
  for (vtkIdType t = 0; t < n; ++t)
  {
    ExactTriangle tri;
    if (penumbra_rules::MakeOccluder(triangles, t, tri))
    {
      impl.Triangles.push_back(tri);
    }
  }
  impl.Build();
  impl.Diagonal = penumbra_rules::SceneDiagonal(geometry);
  impl.Built.Remember(geometry);
  ++this->NumberOfBuilds;
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraLineReference::ComputeVisibility(
  vtkPenumbraViewSamples* samples, vtkPenumbraAreaLight* light, vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  impl.Error.clear();
  if (!samples || !light || !visibility)
  {
    return this->Fail("no view samples, no light or no visibility array");
  }
  if (light->GetShape() != vtkPenumbraAreaLight::Line)
  {
    return this->Fail("the exact line reference needs a linear light (Shape Line)");
  }
  const std::string problem = light->GetValidityMessage();
  if (!problem.empty())
  {
    return this->Fail("invalid area light: " + problem);
  }
  if (!this->Geometry)
  {
    return this->Fail("no scene geometry: call SetGeometry() first");
  }
  const std::string sampleProblem = samples->CheckArrays();
  if (!sampleProblem.empty())
  {
    return this->Fail(sampleProblem);
  }
  const vtkIdType count = samples->GetNumberOfSamples();
  vtkFloatArray* pos = samples->GetPositions();
  vtkFloatArray* nrm = samples->GetNormals();
  vtkIntArray* props = samples->GetPropIndices();
  vtkIdTypeArray* tris = samples->GetTriangleIds();
  if (!this->EnsureHierarchy())
  {
    return 0;
  }

  // The geometry's rebased frame, differences in double (as vtkPenumbraReference).
  double geometryOrigin[3], shift[3], centre[3], u[3], v[3], n[3];
  this->Geometry->GetOrigin(geometryOrigin);
  samples->GetOrigin(shift);
  light->GetCentre(centre);
  light->GetAxes(u, v, n);
  double a[3], ab[3];
  for (int c = 0; c < 3; ++c)
  {
    shift[c] -= geometryOrigin[c];
    a[c] = centre[c] - geometryOrigin[c] - 0.5 * light->GetWidth() * u[c];
    ab[c] = light->GetWidth() * u[c];
  }
  const bool off = !penumbra_rules::LightEmits(light);
  const double epsilon = this->RelativeEpsilon;
  const double endFraction = epsilon < 1.0 ? epsilon / (1.0 - epsilon) : 0.0;
  const double tieFactor = this->TieFactor;

  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(count);
  impl.Ties->SetNumberOfComponents(1);
  impl.Ties->SetNumberOfTuples(count);
  float* vis = count ? visibility->GetPointer(0) : nullptr;
  unsigned char* ties = count ? impl.Ties->GetPointer(0) : nullptr;
  const float* positions = count ? pos->GetPointer(0) : nullptr;
  const float* normals = count ? nrm->GetPointer(0) : nullptr;
  const int* propIds = count ? props->GetPointer(0) : nullptr;
  const vtkIdType* triangleIds = count ? tris->GetPointer(0) : nullptr;
  std::atomic<vtkIdType> candidateCount(0), tieCount(0);

  vtkSMPTools::For(0, count,
    [&](vtkIdType begin, vtkIdType end)
    {
      std::vector<std::pair<double, double>> blocked;
      vtkIdType localCandidates = 0, localTies = 0;
      for (vtkIdType s = begin; s < end; ++s)
      {
        ties[s] = 0;
        double p[3], normal[3];
        for (int c = 0; c < 3; ++c)
        {
          p[c] = static_cast<double>(positions[3 * s + c]) + shift[c];
          normal[c] = normals[3 * s + c];
        }
        if (propIds[s] < 0 || !std::isfinite(p[0] + p[1] + p[2]) ||
          !std::isfinite(normal[0] + normal[1] + normal[2]))
        {
          vis[s] = -1.0f;
          continue;
        }
        if (off)
        {
          vis[s] = 1.0f;
          continue;
        }
        bool tie = false;
        vis[s] = impl.SampleVisibility(p, normal, triangleIds[s], a, ab, epsilon, endFraction,
          tieFactor, blocked, tie, localCandidates);
        if (tie)
        {
          ties[s] = 1;
          ++localTies;
        }
      }
      candidateCount += localCandidates;
      tieCount += localTies;
    });
  this->NumberOfCandidates = candidateCount.load();
  this->NumberOfTies = tieCount.load();
  visibility->Modified();
  impl.Ties->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
void vtkPenumbraLineReference::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Geometry: " << this->Geometry << "\n";
  os << indent << "RelativeEpsilon: " << this->RelativeEpsilon << "\n";
  os << indent << "TieFactor: " << this->TieFactor << "\n";
  os << indent << "NumberOfBuilds: " << this->NumberOfBuilds << "\n";
  os << indent << "NumberOfCandidates: " << this->NumberOfCandidates << "\n";
  os << indent << "NumberOfTies: " << this->NumberOfTies << "\n";
  os << indent << "LastTimeMs: " << this->LastTimeMs << "\n";
}
