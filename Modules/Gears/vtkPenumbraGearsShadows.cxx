#include "vtkPenumbraGearsShadows.h"

#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraGearsCompute.h"
#include "vtkPenumbraGearsTree.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkTypeUInt32Array.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <numeric>
#include <set>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraGearsShadows);

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;

constexpr int MaxK = 64; // vtkPenumbraAreaLight's SamplesPerAxis limit: one 64-bit word per row

// Position tolerance of the double-precision decisions against Embree's float32 ray, relative
// to the reference's scene scale max(|p|, bounds diagonal): the value the conservative
// technique validated for the same reference (its exact one-triangle ray test).
constexpr double RelativePositionTolerance = 1e-6;

// A caster in the geometry's rebased frame with the float32 rounding Embree's copy has, and
// what the per-ray test needs precomputed (the tracer's rules).
using Caster = penumbra_rules::ExactTriangle;

// A caster's bounding sphere, kept apart from the casters so the cheap rejects touch 32 bytes
// per triangle instead of a whole Caster.
struct Sphere
{
  double Centre[3];
  double Radius;
};

using penumbra_rules::Hit;
using penumbra_rules::SegmentTest;

// Embree's watertight test never lets a ray slip between two triangles that share an edge
// (the same float vertices) and lie on opposite sides of it as seen along the ray. So a ray
// that is OnEdge for both of them, clear in t, is blocked by one or the other.
bool SealedEdge(const Caster& a, int ea, const Caster& b, int eb, const double d[3])
{
  const double* a0 = a.V[ea];
  const double* a1 = a.V[(ea + 1) % 3];
  const double* b0 = b.V[eb];
  const double* b1 = b.V[(eb + 1) % 3];
  auto same = [](const double* p, const double* q)
  { return p[0] == q[0] && p[1] == q[1] && p[2] == q[2]; };
  if (!((same(a0, b1) && same(a1, b0)) || (same(a0, b0) && same(a1, b1))))
  {
    return false;
  }
  const double along[3] = { a1[0] - a0[0], a1[1] - a0[1], a1[2] - a0[2] };
  double w[3];
  vtkMath::Cross(along, d, w);
  const double* ca = a.V[(ea + 2) % 3];
  const double* cb = b.V[(eb + 2) % 3];
  const double sa = w[0] * (ca[0] - a0[0]) + w[1] * (ca[1] - a0[1]) + w[2] * (ca[2] - a0[2]);
  const double sb = w[0] * (cb[0] - a0[0]) + w[1] * (cb[1] - a0[1]) + w[2] * (cb[2] - a0[2]);
  const double scale = vtkMath::Norm(w) *
    (std::fabs(ca[0] - a0[0]) + std::fabs(ca[1] - a0[1]) + std::fabs(ca[2] - a0[2]) +
      std::fabs(cb[0] - a0[0]) + std::fabs(cb[1] - a0[1]) + std::fabs(cb[2] - a0[2]));
  return sa * sb < -1e-6 * scale * scale;
}

inline std::uint64_t Span(int lo, int hi)
{
  if (hi < lo)
  {
    return 0;
  }
  const int width = hi - lo + 1;
  const std::uint64_t ones = width >= 64 ? ~std::uint64_t(0) : ((std::uint64_t(1) << width) - 1);
  return ones << lo;
}

// Narrows [lo, hi] to the columns i where base + i * slope >= -delta (an affine light-plane
// function evaluated at the light samples of one row). `widen` decides which way the index
// rounding slack goes: outward for "possibly" intervals, inward for "certainly" ones.
inline void Narrow(double base, double slope, double delta, int k, bool widen, int& lo, int& hi)
{
  const double bound = -delta - base;
  if (std::fabs(slope) < 1e-300)
  {
    if (widen ? 0.0 < bound : 0.0 <= bound)
    {
      hi = -1;
    }
    return;
  }
  const double x = bound / slope;
  const double fuzz = (widen ? 1e-9 : -1e-9) * (std::fabs(x) + 1.0);
  if (slope > 0.0)
  {
    const double c = std::ceil(x - fuzz);
    lo = std::max(lo, c < 0.0 ? 0 : (c > k ? k : static_cast<int>(c)));
  }
  else
  {
    const double f = std::floor(x + fuzz);
    hi = std::min(hi, f < -1.0 ? -1 : (f > k - 1 ? k - 1 : static_cast<int>(f)));
  }
}

// One affine function of the light-sample position L = centre + su U + sv V, written for
// sample indices: value(i, j) = Base + i * Di + j * Dj.
struct Affine
{
  double Base, Di, Dj;
  double At(int i, int j) const { return this->Base + i * this->Di + j * this->Dj; }
};

// The columns of row j where f(i, j) >= -delta, as a bound linear in j: lower (Di > 0),
// upper (Di < 0), or a whole-row test when f does not depend on the column.
struct ColumnBound
{
  enum
  {
    Lower,
    Upper,
    Row
  } Kind = Row;
  double X0 = 0, Step = 0; // column bound at row 0 and its change per row
  double Base = 0, Dj = 0, Delta = 0;
  bool Widen = true;

  ColumnBound() = default;
  ColumnBound(const Affine& f, double delta, bool widen)
    : Base(f.Base)
    , Dj(f.Dj)
    , Delta(delta)
    , Widen(widen)
  {
    if (std::fabs(f.Di) >= 1e-300)
    {
      this->Kind = f.Di > 0.0 ? Lower : Upper;
      this->X0 = (-delta - f.Base) / f.Di;
      this->Step = -f.Dj / f.Di;
    }
  }

  // Same rounding rules as Narrow().
  void Apply(int j, int k, int& lo, int& hi) const
  {
    if (this->Kind == Row)
    {
      const double bound = -this->Delta - (this->Base + j * this->Dj);
      if (this->Widen ? 0.0 < bound : 0.0 <= bound)
      {
        hi = -1;
      }
      return;
    }
    const double x = this->X0 + j * this->Step;
    const double fuzz = (this->Widen ? 1e-9 : -1e-9) * (std::fabs(x) + 1.0);
    if (this->Kind == Lower)
    {
      const double c = std::ceil(x - fuzz);
      lo = std::max(lo, c < 0.0 ? 0 : (c > k ? k : static_cast<int>(c)));
    }
    else
    {
      const double f = std::floor(x + fuzz);
      hi = std::min(hi, f < -1.0 ? -1 : (f > k - 1 ? k - 1 : static_cast<int>(f)));
    }
  }
};

// What the mask loop needs about the light (rebased frame).
struct LightSamples
{
  int K = 1;                  // samples per row
  int Rows = 1;               // k for a rectangle, 1 for a line
  int Count = 1;              // K * Rows
  std::vector<double> Points; // 3 per sample, index = j K + i
  double Centre[3], U[3], V[3], N[3];
  double Su0 = 0, DSu = 0, Sv0 = 0, DSv = 0; // su_i = Su0 + i DSu, sv_j = Sv0 + j DSv
  double HalfU = 0, HalfV = 0;               // largest |su|, |sv| of a sample
  double Diagonal = 0;                       // of the emitter rectangle

  Affine Along(const double g[3], double atCentre) const
  {
    const double gu = vtkMath::Dot(g, this->U);
    const double gv = vtkMath::Dot(g, this->V);
    return { atCentre + this->Su0 * gu + this->Sv0 * gv, this->DSu * gu, this->DSv * gv };
  }
  const double* Corner(int c) const
  {
    const int i = (c & 1) ? this->K - 1 : 0;
    const int j = (c & 2) ? this->Rows - 1 : 0;
    return &this->Points[3 * static_cast<size_t>(j * this->K + i)];
  }
};

// Per-sample constants of the reference's rays.
struct SampleRays
{
  double Z; // distance from the light plane, on this sample's side
  double P[3];
  double Normal[3];
  vtkIdType Own;
  double TNear, TieLimit, ErrPos, Epsilon;
  float TNearF;
};

// Step 4 for one view sample at a time (Wang, Wang, Shi, Popescu, "GEARS: A General and
// Efficient Algorithm for Rendering Shadows", Computer Graphics Forum 33(6), 2014, §3, step 4;
// the paper's per-sample rasterizer replaced by an exact cone-and-plane predicate, made exact
// against the reference): Facing holds the light samples above the tangent plane,
// Candidate those the reference traces, Blocked those a triangle provably blocks, Unknown
// those some triangle may block within the float32 tolerance.
struct MaskBuilder
{
  const LightSamples& L;
  const std::vector<Caster>& Casters;
  const double Epsilon;
  const SampleRays* R = nullptr;
  std::uint64_t Facing[MaxK], Candidate[MaxK], Blocked[MaxK], Unknown[MaxK], Pending[MaxK];
  // Per light sample with a Pending bit: the first triangle it was OnEdge for, and the edge.
  std::vector<std::uint32_t> EdgeOwner;
  std::vector<unsigned char> EdgeIndex;
  bool Open = false;
  // Nearest vertex of a caster to the light plane, and the margin for comparing it with a
  // sample's depth (a cheap reject: a triangle wholly farther from the light than
  // the sample cannot touch its segments).
  const double* ZMin = nullptr;
  const Sphere* Bounds = nullptr;
  double FarSlack = 0.0;
  double Reach = 0.0; // largest distance from the sample to a light sample (at a corner)
  double Axis[3] = { 0, 0, 1 };
  double ConeCos = -1.0, ConeSin = 0.0;
  bool ConeValid = false;
  vtkIdType Necessary = 0, Tests = 0, TreeVisits = 0;

  MaskBuilder(const LightSamples& l, const std::vector<Caster>& casters, double epsilon)
    : L(l)
    , Casters(casters)
    , Epsilon(epsilon)
    , EdgeOwner(static_cast<size_t>(l.Count))
    , EdgeIndex(static_cast<size_t>(l.Count))
  {
  }

  const double* Point(int i, int j) const
  {
    return &this->L.Points[3 * static_cast<size_t>(j * this->L.K + i)];
  }

  // The reference's own per-light-sample rules: facing is N . (x_j - p) > 0 in its exact
  // expression, and a ray with tfar <= tnear is not traced (counts as unoccluded). Facing is
  // affine over the light, so only samples within rounding of the tangent plane, or close
  // enough to the light for the second rule, are evaluated one by one. Returns false when
  // no light sample needs a triangle.
  bool Start(const SampleRays& r)
  {
    this->R = &r;
    const double n[3] = { r.Normal[0], r.Normal[1], r.Normal[2] };
    double reach = 0.0;
    for (int c = 0; c < 4; ++c)
    {
      const double* q = this->L.Corner(c);
      const double d[3] = { q[0] - r.P[0], q[1] - r.P[1], q[2] - r.P[2] };
      reach = std::max(reach, vtkMath::Norm(d));
    }
    this->Reach = reach;
    // The cone from P around the light samples: axis toward their centre, half-angle to the
    // farthest corner (every light sample lies inside, the rectangle being convex).
    const double toCentre[3] = { this->L.Centre[0] - r.P[0], this->L.Centre[1] - r.P[1],
      this->L.Centre[2] - r.P[2] };
    std::copy(toCentre, toCentre + 3, this->Axis);
    this->ConeValid = vtkMath::Normalize(this->Axis) > 0.0;
    double cosCone = 1.0;
    for (int c = 0; c < 4 && this->ConeValid; ++c)
    {
      const double* q = this->L.Corner(c);
      double d[3] = { q[0] - r.P[0], q[1] - r.P[1], q[2] - r.P[2] };
      this->ConeValid = vtkMath::Normalize(d) > 0.0;
      cosCone = std::min(cosCone, vtkMath::Dot(d, this->Axis));
    }
    this->ConeCos = cosCone;
    this->ConeSin = std::sqrt(std::max(0.0, 1.0 - cosCone * cosCone));
    this->ConeValid = this->ConeValid && cosCone > 0.0;
    const Affine facing = this->L.Along(n, vtkMath::Dot(n, this->L.Centre) - vtkMath::Dot(n, r.P));
    const double fuzz = 1e-12 * reach * (1.0 + vtkMath::Norm(n));
    const double plane =
      std::fabs(vtkMath::Dot(this->L.N, r.P) - vtkMath::Dot(this->L.N, this->L.Centre));
    const bool allTraced = !this->Casters.empty() &&
      static_cast<float>(plane * (1.0 - this->Epsilon) * (1.0 - 1e-6)) > r.TNearF;
    bool any = false;
    double lowest = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 4; ++c)
    {
      lowest =
        std::min(lowest, facing.At((c & 1) ? this->L.K - 1 : 0, (c & 2) ? this->L.Rows - 1 : 0));
    }
    if (allTraced && lowest > fuzz)
    {
      // The usual case: the whole light well above the tangent plane, every ray traced.
      for (int j = 0; j < this->L.Rows; ++j)
      {
        this->Blocked[j] = 0;
        this->Unknown[j] = 0;
        this->Pending[j] = 0;
        this->Facing[j] = this->Candidate[j] = Span(0, this->L.K - 1);
      }
      this->Open = true;
      return true;
    }
    const ColumnBound sureFacing(facing, -fuzz, false), maybeFacing(facing, fuzz, true);
    for (int j = 0; j < this->L.Rows; ++j)
    {
      this->Blocked[j] = 0;
      this->Unknown[j] = 0;
      this->Pending[j] = 0;
      int sureLo = 0, sureHi = this->L.K - 1, maybeLo = 0, maybeHi = this->L.K - 1;
      sureFacing.Apply(j, this->L.K, sureLo, sureHi);
      maybeFacing.Apply(j, this->L.K, maybeLo, maybeHi);
      const std::uint64_t sure = Span(sureLo, sureHi);
      this->Facing[j] = sure;
      this->Candidate[j] = allTraced ? sure : 0;
      std::uint64_t check = Span(maybeLo, maybeHi) & (allTraced ? ~sure : ~std::uint64_t(0));
      while (check)
      {
        const int i = __builtin_ctzll(check);
        check &= check - 1;
        const double* q = this->Point(i, j);
        double toLight[3] = { q[0] - r.P[0], q[1] - r.P[1], q[2] - r.P[2] };
        if (!(vtkMath::Dot(r.Normal, toLight) > 0.0))
        {
          this->Facing[j] &= ~(std::uint64_t(1) << i);
          continue;
        }
        this->Facing[j] |= std::uint64_t(1) << i;
        const double dist = vtkMath::Normalize(toLight);
        const float tfar = static_cast<float>(dist * (1.0 - this->Epsilon));
        if (!this->Casters.empty() && dist > 0.0 && tfar > r.TNearF)
        {
          this->Candidate[j] |= std::uint64_t(1) << i;
        }
      }
      any = any || this->Candidate[j];
    }
    this->Open = any;
    return any;
  }

  // One triangle's planes seen from the sample P, affine over the light samples: Beyond (the
  // light past the triangle's plane) and, when P sees the triangle as a proper cone, its
  // three edge planes through P; with the loose (Delta) and certain (Sure) margins.
  struct TriangleCone
  {
    Affine Beyond;
    Affine Edges[3];
    int NumberOfEdges = 0;
    double DeltaEdge = 0, DeltaPlane = 0, SureEdge = 0, SurePlane = 0;
    bool CertainCone = false;
  };

  // Cheap rejects: the triangle wholly farther from the light than the sample, or its
  // bounding sphere outside the cone from P around the light.
  bool Culled(std::uint32_t index) const
  {
    const SampleRays& r = *this->R;
    if (this->ZMin[index] > r.Z + this->FarSlack)
    {
      return true;
    }
    // The triangle's bounding sphere (grown by the tolerance) wholly outside the cone from P
    // around the light: no segment to a light sample comes near it.
    if (this->ConeValid)
    {
      const Sphere& bound = this->Bounds[index];
      const double v[3] = { bound.Centre[0] - r.P[0], bound.Centre[1] - r.P[1],
        bound.Centre[2] - r.P[2] };
      const double distance = vtkMath::Norm(v);
      const double radius = bound.Radius + 4.0 * r.ErrPos;
      if (distance > radius)
      {
        const double sinB = radius / distance;
        const double cosB = std::sqrt(1.0 - sinB * sinB);
        const double cosA = vtkMath::Dot(v, this->Axis) / distance;
        // angle(axis, v) > cone + asin(radius / distance), with cone + that < 90 degrees
        const double cosSum = this->ConeCos * cosB - this->ConeSin * sinB;
        if (cosSum > 0.0 && cosA < cosSum - 1e-12)
        {
          return true;
        }
      }
    }
    return false;
  }

  // The triangle's planes from P and their margins; false when it provably blocks no segment
  // (no crossing, or every hit below the tie band).
  bool Planes(const Caster& tri, TriangleCone& t) const
  {
    const SampleRays& r = *this->R;
    // Signed distances to the triangle's plane: of P, and (affine) of the light samples.
    const double h = vtkMath::Dot(tri.N, r.P) - vtkMath::Dot(tri.N, tri.V[0]);
    const Affine plane =
      this->L.Along(tri.N, vtkMath::Dot(tri.N, this->L.Centre) - vtkMath::Dot(tri.N, tri.V[0]));
    const double sgn = h >= 0.0 ? 1.0 : -1.0;
    const double dMax = this->Reach;
    double sideMin = std::numeric_limits<double>::infinity();
    double crossMin = std::numeric_limits<double>::infinity(), crossMax = -crossMin;
    for (int c = 0; c < 4; ++c)
    {
      const double dl = plane.At((c & 1) ? this->L.K - 1 : 0, (c & 2) ? this->L.Rows - 1 : 0);
      sideMin = std::min(sideMin, sgn * dl);
      crossMin = std::min(crossMin, dl - h);
      crossMax = std::max(crossMax, dl - h);
    }
    const double absH = std::fabs(h);
    const double err = r.ErrPos;
    // |cos| between a ray and the plane: a crossing ray has |n . (L - P)| = |h| + |dL| >= |h|,
    // and >= min |n . (L - P)| over the light when that keeps one sign (affine: corners).
    const double crossAbs = crossMin > 0.0 ? crossMin : (crossMax < 0.0 ? -crossMax : 0.0);
    const double cosMin = std::max(absH, crossAbs) / dMax;
    // Margins. SegmentTest's slack on a ray is err (1 + 1 / cos); a hit is at t = |h| / cos;
    // an edge plane through P at signed distance E from L is at E t / |L - P| from the hit
    // point, and the in-plane edge distance has the same sign and is at least as large. With
    // |n . (L - P)| <= |L - P| <= dMax, each test below reduces to a bound without cos:
    // - no crossing: the whole light on P's side of the plane by more than 2 err;
    if (absH > err && sideMin > 2.0 * err)
    {
      return false;
    }
    // - every hit provably below the tie band: |h| + err < cos_min (tieLimit - err);
    if (absH + err < cosMin * (r.TieLimit - err))
    {
      return false;
    }
    // - a light sample can only be blocked where E >= -2 err dMax / |h| for all three edges
    //   and the light is beyond the plane or within 2 err of it;
    // - it is certainly blocked where E > 2 err dMax / |h| for all three edges, the light
    //   is beyond the plane by more than epsilon dMax + 2 err (clear of the ray end), and
    //   |h| > tieLimit + 2 err (clear of the tie band) with no grazing ray (cos > 2e-6).
    t.DeltaEdge = std::min(2.0 * err * dMax / std::max(absH, 1e-300), 4.0 * dMax);
    t.DeltaPlane = 2.0 * err;
    const bool certainPossible = absH > r.TieLimit + 2.0 * err && cosMin > 2e-6;
    t.SureEdge = t.DeltaEdge + 1e-9 * dMax;
    t.SurePlane = this->Epsilon * dMax + 2.0 * err + 1e-9 * dMax;

    double a[3][3];
    for (int i = 0; i < 3; ++i)
    {
      for (int c = 0; c < 3; ++c)
      {
        a[i][c] = tri.V[i][c] - r.P[c];
      }
    }
    double cr[3][3];
    for (int e = 0; e < 3; ++e)
    {
      vtkMath::Cross(a[e], a[(e + 1) % 3], cr[e]);
    }
    const double det = vtkMath::Dot(cr[0], a[2]);
    // |det| > 1e-12 |a0| |a1| |a2|, squared to spare three square roots per triangle.
    const double mag2 =
      vtkMath::Dot(a[0], a[0]) * vtkMath::Dot(a[1], a[1]) * vtkMath::Dot(a[2], a[2]);
    const bool cone = det * det > 1e-24 * mag2;
    t.NumberOfEdges = 0;
    for (int e = 0; cone && e < 3; ++e)
    {
      // Unit normal of the plane through P and edge e, pointing into the triangle's cone.
      const double len = vtkMath::Norm(cr[e]);
      if (!(len > 0.0))
      {
        continue;
      }
      double m[3];
      for (int c = 0; c < 3; ++c)
      {
        m[c] = (det > 0.0 ? cr[e][c] : -cr[e][c]) / len;
      }
      t.Edges[t.NumberOfEdges++] =
        this->L.Along(m, vtkMath::Dot(m, this->L.Centre) - vtkMath::Dot(m, r.P));
    }
    t.CertainCone = certainPossible && cone && t.NumberOfEdges == 3;
    t.Beyond = { -sgn * plane.Base, -sgn * plane.Di, -sgn * plane.Dj };
    return true;
  }

  // The exact segment test for the light samples in `maybe` on row j; an OnEdge hit blocks
  // when a second triangle seals the same edge (SealedEdge). True when any is blocked.
  bool TestSegments(std::uint32_t index, const Caster& tri, int j, std::uint64_t maybe)
  {
    const SampleRays& r = *this->R;
    bool hitAny = false;
    while (maybe)
    {
      const int i = __builtin_ctzll(maybe);
      maybe &= maybe - 1;
      const double* q = this->Point(i, j);
      double d[3] = { q[0] - r.P[0], q[1] - r.P[1], q[2] - r.P[2] };
      const double dist = vtkMath::Normalize(d);
      ++this->Tests;
      int edge = 0;
      const Hit hit =
        SegmentTest(r.P, d, r.TieLimit, dist * (1.0 - this->Epsilon), tri, r.ErrPos, edge);
      const std::uint64_t bit = std::uint64_t(1) << i;
      if (hit == Hit::OnEdge)
      {
        const size_t slot = static_cast<size_t>(j * this->L.K + i);
        if (!(this->Pending[j] & bit))
        {
          this->Pending[j] |= bit;
          this->EdgeOwner[slot] = index;
          this->EdgeIndex[slot] = static_cast<unsigned char>(edge);
          continue;
        }
        const std::uint32_t other = this->EdgeOwner[slot];
        if (other != index && SealedEdge(this->Casters[other], this->EdgeIndex[slot], tri, edge, d))
        {
          this->Blocked[j] |= bit;
          hitAny = true;
          continue;
        }
        this->Unknown[j] |= bit; // a third edge, or a silhouette: undecided
      }
      else if (hit == Hit::Clear)
      {
        this->Blocked[j] |= bit;
        hitAny = true;
      }
      else if (hit == Hit::Unknown)
      {
        this->Unknown[j] |= bit;
      }
    }
    return hitAny;
  }

  // One potential blocker: loose per-row intervals bound the light samples it may block;
  // inside the certain intervals it provably blocks, in between the segment test decides.
  void Visit(std::uint32_t index)
  {
    if (this->Culled(index))
    {
      return;
    }
    const Caster& tri = this->Casters[index];
    if (penumbra_rules::IsOwnCaster(tri.Id, this->R->Own))
    {
      return; // the reference never lets a sample's own triangle (or its pieces) block it
    }
    TriangleCone t;
    if (!this->Planes(tri, t))
    {
      return;
    }

    // Rows where every condition can hold somewhere (each is affine: its row maximum is at
    // the first or last column); usually a few rows, often none.
    int jLo = 0, jHi = this->L.Rows - 1;
    auto rows = [&](const Affine& f, double delta)
    {
      const double best = f.Base + std::max(0.0, (this->L.K - 1) * f.Di);
      Narrow(best, f.Dj, delta, this->L.Rows, true, jLo, jHi);
    };
    rows(t.Beyond, t.DeltaPlane);
    for (int e = 0; e < t.NumberOfEdges && jLo <= jHi; ++e)
    {
      rows(t.Edges[e], t.DeltaEdge);
    }
    // Per condition, the column bound as a linear function of the row: one division per
    // triangle instead of one per row.
    if (jLo > jHi)
    {
      return;
    }
    ColumnBound loose[4], sure[4];
    const int nLoose = 1 + t.NumberOfEdges;
    loose[0] = ColumnBound(t.Beyond, t.DeltaPlane, true);
    for (int e = 0; e < t.NumberOfEdges; ++e)
    {
      loose[e + 1] = ColumnBound(t.Edges[e], t.DeltaEdge, true);
    }
    bool sureReady = false; // built at the first row that has candidates
    bool hitAny = false;
    for (int j = jLo; j <= jHi; ++j)
    {
      const std::uint64_t open = this->Candidate[j] & ~this->Blocked[j];
      if (!open)
      {
        continue;
      }
      int lo = 0, hi = this->L.K - 1;
      for (int c = 0; c < nLoose && lo <= hi; ++c)
      {
        loose[c].Apply(j, this->L.K, lo, hi);
      }
      std::uint64_t maybe = open & Span(lo, hi);
      if (!maybe)
      {
        continue;
      }
      if (t.CertainCone)
      {
        if (!sureReady)
        {
          sure[0] = ColumnBound(t.Beyond, -t.SurePlane, false);
          for (int e = 0; e < 3; ++e)
          {
            sure[e + 1] = ColumnBound(t.Edges[e], -t.SureEdge, false);
          }
          sureReady = true;
        }
        int sLo = 0, sHi = this->L.K - 1;
        for (int c = 0; c < 4 && sLo <= sHi; ++c)
        {
          sure[c].Apply(j, this->L.K, sLo, sHi);
        }
        const std::uint64_t certain = maybe & Span(sLo, sHi);
        if (certain)
        {
          this->Blocked[j] |= certain;
          maybe &= ~certain;
          hitAny = true;
        }
      }
      if (this->TestSegments(index, tri, j, maybe))
      {
        hitAny = true;
      }
    }
    if (hitAny)
    {
      ++this->Necessary;
      bool open = false;
      for (int j = 0; j < this->L.Rows && !open; ++j)
      {
        open = (this->Candidate[j] & ~this->Blocked[j]) != 0;
      }
      this->Open = open;
    }
  }

  // Whether a node of the casters' tree (its box in the side's light frame `pf` is in, grown
  // by the float32 ray's tolerance) can hold a point of a segment from the sample to a light
  // sample that is still open. A triangle no such segment comes near cannot change the mask
  // (the premise of Culled(): Embree's ray stays within that tolerance of the segment), and
  // blocked bits are final, so skipping the node changes nothing. Below the sample's depth
  // the box projects from the sample onto the light plane (x' = p + (x - p) pz / (pz - z)),
  // and the open bits under that projection decide; a box reaching the sample's depth only
  // gets the pyramid test (the segments at the box's depths).
  bool Reaches(const double* box, const double pf[3]) const
  {
    const double pz = pf[2];
    const double zLo = std::max(box[4], 0.0), zHi = std::min(box[5], pz);
    if (zLo > zHi)
    {
      return false;
    }
    const double s0[2] = { this->L.Su0, this->L.Sv0 }, ds[2] = { this->L.DSu, this->L.DSv };
    const int count[2] = { this->L.K, this->L.Rows };
    if (!(box[5] < pz) || !(pz > 0.0))
    {
      // Segment points at depth z are p + t (l - p), t = 1 - z / pz, l over the light samples.
      const double tA = pz > 0.0 ? 1.0 - zHi / pz : 0.0, tB = pz > 0.0 ? 1.0 - zLo / pz : 1.0;
      for (int a = 0; a < 2; ++a)
      {
        const double lMin = s0[a] - pf[a], lMax = s0[a] + (count[a] - 1) * ds[a] - pf[a];
        const double fuzz = 1e-9 *
          (std::fabs(pf[a]) + std::fabs(box[2 * a]) + std::fabs(box[2 * a + 1]) + this->L.Diagonal);
        const double from = pf[a] + std::min(tA * lMin, tB * lMin) - fuzz;
        const double to = pf[a] + std::max(tA * lMax, tB * lMax) + fuzz;
        if (box[2 * a + 1] < from || box[2 * a] > to)
        {
          return false;
        }
      }
      return true;
    }
    const double sLo = pz / (pz - zLo), sHi = pz / (pz - box[5]);
    int lo[2], hi[2];
    for (int a = 0; a < 2; ++a)
    {
      const double dLo = box[2 * a] - pf[a], dHi = box[2 * a + 1] - pf[a];
      double from = pf[a] + dLo * (dLo < 0.0 ? sHi : sLo);
      double to = pf[a] + dHi * (dHi > 0.0 ? sHi : sLo);
      const double fuzz =
        1e-9 * (std::fabs(pf[a]) + std::fabs(from) + std::fabs(to) + this->L.Diagonal);
      from -= fuzz;
      to += fuzz;
      if (ds[a] > 0.0)
      {
        const double f = std::ceil((from - s0[a]) / ds[a]), t = std::floor((to - s0[a]) / ds[a]);
        lo[a] = f < 0.0 ? 0 : (f > count[a] ? count[a] : static_cast<int>(f));
        hi[a] = t > count[a] - 1 ? count[a] - 1 : (t < -1.0 ? -1 : static_cast<int>(t));
      }
      else
      {
        lo[a] = 0; // a line light: its one row at sv = Sv0
        hi[a] = from <= s0[a] && s0[a] <= to ? count[a] - 1 : -1;
      }
      if (lo[a] > hi[a])
      {
        return false;
      }
    }
    const std::uint64_t columns = Span(lo[0], hi[0]);
    for (int j = lo[1]; j <= hi[1]; ++j)
    {
      if (this->Candidate[j] & ~this->Blocked[j] & columns)
      {
        return true;
      }
    }
    return false;
  }

  // Dense cells (vtkPenumbraGearsTree.h): the casters' tree, nearer node first, instead of
  // the cell and global lists; nodes that reach no open light sample are skipped whole.
  // Returns the triangles visited.
  vtkIdType VisitTree(const penumbra_gears::Tree& tree, const double* boxes,
    const double* triangleBoxes, const double pf[3])
  {
    if (tree.Nodes.empty())
    {
      return 0;
    }
    auto distance2 = [&](std::uint32_t n)
    {
      const double* b = boxes + 6 * static_cast<size_t>(n);
      double d2 = 0.0;
      for (int a = 0; a < 3; ++a)
      {
        const double d = 0.5 * (b[2 * a] + b[2 * a + 1]) - pf[a];
        d2 += d * d;
      }
      return d2;
    };
    std::uint32_t stack[128]; // a median-split tree over 2^32 triangles is 31 levels deep
    int top = 0;
    stack[top++] = 0;
    vtkIdType visited = 0;
    while (top > 0 && this->Open)
    {
      const std::uint32_t n = stack[--top];
      if (!this->Reaches(boxes + 6 * static_cast<size_t>(n), pf))
      {
        continue;
      }
      const penumbra_gears::TreeNode& node = tree.Nodes[n];
      if (node.Count > 0)
      {
        for (std::uint32_t t = node.First; t < node.First + node.Count && this->Open; ++t)
        {
          if (this->Reaches(triangleBoxes + 6 * static_cast<size_t>(t), pf))
          {
            this->Visit(t); // the casters are stored in leaf order
            ++visited;
          }
        }
        continue;
      }
      const bool firstNearer = distance2(node.First) <= distance2(node.First + 1);
      stack[top++] = firstNearer ? node.First + 1 : node.First;
      stack[top++] = firstNearer ? node.First : node.First + 1;
    }
    return visited;
  }

  // Facing becomes the mask of the light samples known to be lit; the undecided ones (some
  // triangle may block them within the float32 tolerance and none provably does) are
  // appended to `undecided` as light-sample indices for the reference to trace.
  void Finish(std::vector<int>& undecided)
  {
    for (int j = 0; j < this->L.Rows; ++j)
    {
      std::uint64_t open =
        (this->Unknown[j] | this->Pending[j]) & this->Candidate[j] & ~this->Blocked[j];
      this->Facing[j] &= ~(this->Blocked[j] | open);
      while (open)
      {
        const int i = __builtin_ctzll(open);
        open &= open - 1;
        undecided.push_back(j * this->L.K + i);
      }
    }
  }

  float Visibility() const
  {
    int lit = 0;
    for (int j = 0; j < this->L.Rows; ++j)
    {
      lit += __builtin_popcountll(this->Facing[j]);
    }
    return static_cast<float>(lit) / static_cast<float>(this->L.Count);
  }
};

// Triangles per grid cell from the casters' cell ranges, without visiting a single (caster,
// cell) pair: a 2-D difference array (+1 at a range's first corner, -1 past its edges) whose
// prefix sums are the list lengths. O(casters + cells), so a cell's cost is known before its
// list is built.
std::vector<std::int64_t> CellListLengths(
  int g, const std::vector<int>& range, const std::vector<std::int64_t>& touched)
{
  const size_t side = static_cast<size_t>(g) + 1;
  std::vector<std::int64_t> diff(side * side, 0);
  for (size_t t = 0; t < touched.size(); ++t)
  {
    if (touched[t] <= 0)
    {
      continue;
    }
    const int* rg = &range[4 * t];
    diff[static_cast<size_t>(rg[2]) * side + rg[0]] += 1;
    diff[static_cast<size_t>(rg[2]) * side + rg[1] + 1] -= 1;
    diff[static_cast<size_t>(rg[3] + 1) * side + rg[0]] -= 1;
    diff[static_cast<size_t>(rg[3] + 1) * side + rg[1] + 1] += 1;
  }
  std::vector<std::int64_t> length(static_cast<size_t>(g) * g, 0);
  for (int iy = 0; iy < g; ++iy)
  {
    std::int64_t row = 0;
    for (int ix = 0; ix < g; ++ix)
    {
      row += diff[static_cast<size_t>(iy) * side + ix];
      length[static_cast<size_t>(iy) * g + ix] =
        row + (iy > 0 ? length[static_cast<size_t>(iy - 1) * g + ix] : 0);
    }
  }
  return length;
}
// The state one ComputeVisibility call shares between its phases: the view samples in the
// geometry's rebased frame, the light, the outputs, the undecided pairs and the statistics.
struct CallState
{
  vtkIdType N = 0;
  const float* Pos = nullptr;
  const float* Nrm = nullptr;
  const int* Props = nullptr;
  const vtkIdType* Tris = nullptr;
  double Shift[3] = { 0, 0, 0 };                         // samples' origin minus the geometry's
  double Epsilon = 0.0, TieFactor = 0.0, Diagonal = 1.0; // the reference's
  vtkSmartPointer<vtkPenumbraAreaLight> Used;            // the light, resampled if asked
  LightSamples Light;
  bool Off = false; // switched off or zero intensity

  float* Vis = nullptr;
  unsigned char* Uncertain = nullptr;
  std::uint32_t* Masks = nullptr; // only with KeepMasks
  int Words = 0;                  // mask words per sample

  bool UseGpu = false;     // step 4 on the compute path
  double TraceLimit = 0.0; // list length above which a cell is dense; 0: never
  bool DenseTree = false;  // dense cells walk the casters' tree (else: ray traced whole)

  // Undecided (view sample, light sample) pairs, appended by the mask loop in sample order
  // within each thread's chunk.
  std::vector<vtkIdType> TraceSamples;
  std::vector<int> TraceLights;
  std::mutex TraceMutex;

  // Statistics, summed over both sides of the light plane.
  int GridUsed = 0;
  vtkIdType Flagged = 0, TracedCellSamples = 0, TreeSamples = 0, Occupied = 0, Cells = 0,
            MaxPerCell = 0, ListTotal = 0, GlobalTotal = 0;
  std::atomic<vtkIdType> Assignments{ 0 }, Necessary{ 0 }, SegmentTests{ 0 };
  double GridMs = 0.0, MaskMs = 0.0, TraceMs = 0.0;
  vtkIdType UncertainSamples = 0, TracedRays = 0, SamplesWithTracedRays = 0;

  // The reference's per-ray constants of view sample s; false if the sample is invalid.
  bool LoadSample(vtkIdType s, SampleRays& r) const
  {
    for (int c = 0; c < 3; ++c)
    {
      r.P[c] = static_cast<double>(this->Pos[3 * s + c]) + this->Shift[c];
      r.Normal[c] = this->Nrm[3 * s + c];
    }
    if (this->Props[s] < 0 || !std::isfinite(r.P[0]) || !std::isfinite(r.P[1]) ||
      !std::isfinite(r.P[2]) || !std::isfinite(r.Normal[0]) || !std::isfinite(r.Normal[1]) ||
      !std::isfinite(r.Normal[2]))
    {
      return false;
    }
    const penumbra_rules::RayBand band =
      penumbra_rules::SampleBand(r.P, this->Diagonal, this->Epsilon, this->TieFactor);
    r.Own = this->Tris[s];
    r.Epsilon = this->Epsilon;
    r.TNear = band.TNear;
    r.TNearF = static_cast<float>(r.TNear);
    r.TieLimit = static_cast<double>(static_cast<float>(band.TieLimit));
    r.ErrPos = RelativePositionTolerance * band.Scale;
    return true;
  }

  // ORs the light samples set in rows (one word per row) into sample s's kept mask.
  void WriteMask(vtkIdType s, const std::uint64_t* rows) const
  {
    if (!this->Masks)
    {
      return;
    }
    const LightSamples& ls = this->Light;
    std::uint32_t* out = this->Masks + static_cast<size_t>(s) * this->Words;
    for (int j = 0; j < ls.Rows; ++j)
    {
      for (int i = 0; i < ls.K; ++i)
      {
        if (rows[j] >> i & 1u)
        {
          const int index = j * ls.K + i;
          out[index / 32] |= 1u << (index % 32);
        }
      }
    }
  }
};

// Per caster on one side: culled, global or the grid box it touches.
struct Footprint
{
  double Box[4];
  int State; // 0 culled, 1 global, 2 cells
};

// One side of the light plane: its samples in the light's frame with z toward them
// (Wang et al. 2014, §4, A.1; the back side mirrors), the grid camera C, the casters'
// footprints and the grid being built.
struct SideState
{
  int Flip = 1;
  double Ax[3][3];                // the frame's axes
  const double* Centre = nullptr; // the light's centre, the frame's origin
  vtkIdType M = 0;                // samples on this side (Scratch.Ids, Scratch.Frame)
  double ZFar = 0.0;              // farthest sample from the light plane
  double Lo3[3], Hi3[3];          // bounds of the samples and the light, in the frame
  double Tolerance = 0.0;         // how far off the float32 ray may hit a triangle
  double Distance = 0.0, Cam[3];  // the camera C, behind the light
  double Pb[4];                   // bounds of the projected samples
  double Extent = 0.0;            // their larger side
  std::vector<double> ZNear;      // per caster: nearest vertex to the light
  std::vector<Footprint> Foot;

  // The grid: resolution G, origin (X0, Y0), cell size Cw x Ch, and the per-resolution
  // working arrays of its construction.
  int G = 1;
  double X0 = 0, Y0 = 0, Cw = 1, Ch = 1;
  std::vector<std::uint32_t> Count;  // samples per cell
  std::vector<std::int64_t> Sat;     // summed-area table of occupied cells
  std::vector<int> Range;            // per caster: ix0, ix1, iy0, iy1
  std::vector<std::int64_t> Touched; // per caster: busy cells touched, -1 global
  std::int64_t Total = 0;            // list entries the cells would hold

  void ToFrame(const double w[3], double f[3]) const
  {
    const double d[3] = { w[0] - this->Centre[0], w[1] - this->Centre[1], w[2] - this->Centre[2] };
    for (int a = 0; a < 3; ++a)
    {
      f[a] = vtkMath::Dot(this->Ax[a], d);
    }
  }
  // Projection from C onto the far plane z = ZFar.
  void Project(const double f[3], double out[2]) const
  {
    const double g = (this->ZFar - this->Cam[2]) / (f[2] - this->Cam[2]);
    out[0] = this->Cam[0] + g * (f[0] - this->Cam[0]);
    out[1] = this->Cam[1] + g * (f[1] - this->Cam[1]);
  }
};
}

struct vtkPenumbraGearsShadows::Internals
{
  // Casters, rebuilt when the geometry changes (same rule as the reference's scene).
  std::vector<Caster> Casters;
  std::vector<Sphere> Bounds;
  vtkMTimeType GeometryTime = 0;
  vtkMTimeType FlagsTime = 0;
  double Origin[3] = { 0, 0, 0 };
  vtkIdType Triangles = -1;
  double Diagonal = 1.0;

  // Per-frame working arrays sized by the samples (tens of MB at 1280 x 720), kept between
  // frames: allocating them afresh each frame cost more in page faults than the grid itself.
  struct ScratchArrays
  {
    std::vector<signed char> Side;
    std::vector<vtkIdType> Ids;
    std::vector<double> Frame, Proj;
    std::vector<std::int32_t> SampleCell, Occupied;
    std::vector<unsigned char> Traced; // per cell: a dense cell (tree walk or ray tracer)
    // Per caster, kept for the next side (SideState's arrays of the same names).
    std::vector<double> ZNear;
    std::vector<Footprint> Foot;
    std::vector<int> Range;
    std::vector<std::int64_t> Touched;
    std::vector<double> TriangleBoxes; // per caster: its box in the side's light frame, grown
    std::vector<double> TreeBoxes;     // by the float32 tolerance; the same per tree node
    std::vector<std::uint32_t> CellStart, CellList, GlobalList, SampleOrder, SampleStart, OnCPU,
      Work, Results, Rows; // Work, Results, Rows: the compute path's
  } Scratch;

  vtkNew<vtkTypeUInt32Array> Masks;
  vtkNew<vtkUnsignedCharArray> Uncertain;

  // The casters flattened for the compute path (penumbra_gears::CasterStride doubles each),
  // and a version that changes whenever they are rebuilt (the GPU copy follows it).
  std::vector<double> CasterData;
  std::uint64_t CasterVersion = 0;
  penumbra_gears::MaskCompute Compute;
  penumbra_gears::Tree Tree; // over the casters, for the dense cells
  std::string PathMessage;
  std::set<std::string> Reported; // compute-path problems already warned about

  // With `withTree` the casters' tree is built too (and the casters stored in its order):
  // only the DENSE_TREE walk needs it, and on a 1 M-triangle mesh it costs a frame's grid.
  void UpdateCasters(vtkPenumbraSceneGeometry* geometry, bool withTree)
  {
    double origin[3];
    geometry->GetOrigin(origin);
    const vtkIdType n = geometry->GetNumberOfTriangles();
    if (n == this->Triangles && geometry->GetGeometryTime() == this->GeometryTime &&
      geometry->GetFlagsTime() == this->FlagsTime && origin[0] == this->Origin[0] &&
      origin[1] == this->Origin[1] && origin[2] == this->Origin[2] &&
      (!withTree || !this->Tree.Nodes.empty() || this->Casters.empty()))
    {
      return;
    }
    this->Casters.clear();
    this->Bounds.clear();
    vtkDoubleArray* vertices = geometry->GetVertices();
    const double* v = n && vertices ? vertices->GetPointer(0) : nullptr;
    for (vtkIdType t = 0; v && t < n; ++t)
    {
      Caster c;
      if (geometry->IsOccluder(t) &&
        penumbra_rules::MakeExactTriangle(v + 9 * t, penumbra_rules::CasterOwner(geometry, t), c))
      {
        this->Casters.push_back(c);
        Sphere b;
        b.Radius = 0.0;
        for (int k = 0; k < 3; ++k)
        {
          b.Centre[k] = (c.V[0][k] + c.V[1][k] + c.V[2][k]) / 3.0;
        }
        for (int i = 0; i < 3; ++i)
        {
          const double d[3] = { c.V[i][0] - b.Centre[0], c.V[i][1] - b.Centre[1],
            c.V[i][2] - b.Centre[2] };
          b.Radius = std::max(b.Radius, vtkMath::Norm(d));
        }
        this->Bounds.push_back(b);
      }
    }
    this->Tree = penumbra_gears::Tree();
    if (withTree)
    {
      this->SortCastersByTree();
    }
    this->CasterData.clear();
    this->CasterData.reserve(this->Casters.size() * penumbra_gears::CasterStride);
    for (size_t t = 0; t < this->Casters.size(); ++t)
    {
      const Caster& c = this->Casters[t];
      const Sphere& b = this->Bounds[t];
      const double* parts[] = { &c.V[0][0], c.N, &c.M[0][0], c.MD };
      const size_t sizes[] = { 9, 3, 9, 3 };
      for (int p = 0; p < 4; ++p)
      {
        this->CasterData.insert(this->CasterData.end(), parts[p], parts[p] + sizes[p]);
      }
      this->CasterData.push_back(static_cast<double>(c.Id));
      this->CasterData.insert(this->CasterData.end(), b.Centre, b.Centre + 3);
      this->CasterData.push_back(b.Radius);
    }
    ++this->CasterVersion;
    this->Diagonal = penumbra_rules::SceneDiagonal(geometry);
    this->Triangles = n;
    this->GeometryTime = geometry->GetGeometryTime();
    this->FlagsTime = geometry->GetFlagsTime();
    std::copy(origin, origin + 3, this->Origin);
  }
  // The casters' tree (vtkPenumbraGearsTree.h), and the casters stored in its leaf order, so
  // that a leaf's triangles are Casters[First, First + Count) and a walk reads memory in
  // order (the caster index is internal: Caster::Id names the owner of the triangle).
  void SortCastersByTree()
  {
    const size_t n = this->Casters.size();
    std::vector<double> vertices(9 * n);
    for (size_t t = 0; t < n; ++t)
    {
      std::copy(&this->Casters[t].V[0][0], &this->Casters[t].V[0][0] + 9, &vertices[9 * t]);
    }
    this->Tree.Build(vertices.data(), 9, n);
    std::vector<Caster> casters(n);
    std::vector<Sphere> bounds(n);
    for (size_t t = 0; t < n; ++t)
    {
      casters[t] = this->Casters[this->Tree.Order[t]];
      bounds[t] = this->Bounds[this->Tree.Order[t]];
      this->Tree.Order[t] = static_cast<std::uint32_t>(t);
    }
    this->Casters.swap(casters);
    this->Bounds.swap(bounds);
  }

  // The phases of ComputeVisibility, in the order it runs them (defined below it).
  bool ReadSamples(vtkPenumbraViewSamples* samples, CallState& call);
  bool SetUpLight(vtkPenumbraGearsShadows* self, vtkPenumbraAreaLight* area,
    vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, CallState& call);
  void SetUpOutputs(vtkPenumbraGearsShadows* self, vtkFloatArray* visibility, CallState& call);
  void ChoosePath(vtkPenumbraGearsShadows* self, vtkRenderer* renderer, CallState& call);
  void ReportPathProblem(vtkPenumbraGearsShadows* self, const std::string& why);
  void ClassifySamples(vtkPenumbraGearsShadows* self, CallState& call);
  int TraceUndecided(vtkPenumbraGearsShadows* self, vtkPenumbraViewSamples* samples,
    vtkFloatArray* visibility, CallState& call);
  void StoreStatistics(vtkPenumbraGearsShadows* self, const CallState& call);
  // Per side of the light plane (ProcessSide runs them in this order).
  void ProcessSide(vtkPenumbraGearsShadows* self, CallState& call, int flip);
  bool GatherSide(const CallState& call, SideState& S, int flip);
  void PlaceCamera(vtkPenumbraGearsShadows* self, const CallState& call, SideState& S);
  void CasterFootprints(const CallState& call, SideState& S);
  void BuildGrid(vtkPenumbraGearsShadows* self, const CallState& call, SideState& S);
  void BinSamples(SideState& S);
  void CasterRanges(SideState& S);
  void MarkTracedCells(const CallState& call, SideState& S);
  void FillCellLists(SideState& S);
  void RouteTracedCells(CallState& call);
  bool MasksOnComputePath(vtkPenumbraGearsShadows* self, CallState& call, const SideState& S);
  void MasksOnCPU(CallState& call, const SideState& S, bool allOnCPU);
  void MaskOneSample(CallState& call, MaskBuilder& builder, std::vector<int>& undecided,
    std::uint32_t o, std::int32_t cell);
};

//------------------------------------------------------------------------------
vtkPenumbraGearsShadows::vtkPenumbraGearsShadows()
  : Reference(vtkPenumbraReference::New())
  , Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraGearsShadows::~vtkPenumbraGearsShadows()
{
  this->Reference->Delete();
}

//------------------------------------------------------------------------------
vtkTypeUInt32Array* vtkPenumbraGearsShadows::GetMasks()
{
  return this->Impl->Masks;
}

//------------------------------------------------------------------------------
vtkUnsignedCharArray* vtkPenumbraGearsShadows::GetUncertainSamples()
{
  return this->Impl->Uncertain;
}

//------------------------------------------------------------------------------
double vtkPenumbraGearsShadows::GetUncertainFraction()
{
  return this->NumberOfValidSamples > 0
    ? static_cast<double>(this->NumberOfUncertainSamples + this->NumberOfTracedCellSamples +
        this->NumberOfSamplesWithTracedRays) /
      this->NumberOfValidSamples
    : 0.0;
}

//------------------------------------------------------------------------------
const char* vtkPenumbraGearsShadows::GetPathMessage()
{
  return this->Impl->PathMessage.c_str();
}

//------------------------------------------------------------------------------
void vtkPenumbraGearsShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Compute.Release(window);
}

//------------------------------------------------------------------------------
double vtkPenumbraGearsShadows::GetBlockingShare()
{
  return this->NumberOfAssignments > 0
    ? static_cast<double>(this->NumberOfNecessaryAssignments) / this->NumberOfAssignments
    : 0.0;
}

//------------------------------------------------------------------------------
// Wang et al. 2014, §3, for one area light: the input checks and light set-up, the sample
// classification, then per side of the light plane the grid (A.1-A.2), the triangle lists
// (A.3) and the masks (step 4), and last the reference for whatever stayed undecided.
int vtkPenumbraGearsShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  if (!geometry || !samples || !light || !visibility)
  {
    PENUMBRA_FAIL("needs scene geometry, view samples, a light and an output array");
  }
  this->Reference->SetGeometry(geometry);
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  this->LastLightWasArea = area != nullptr;
  if (!area)
  {
    // GEARS is an area-light algorithm; other lights get the exact one-ray answer.
    const int ok = this->Reference->ComputeVisibility(samples, light, visibility);
    this->LastTimeMs = ElapsedMs(start);
    return ok;
  }
  const std::string problem = area->GetValidityMessage();
  if (!problem.empty())
  {
    PENUMBRA_FAIL("invalid area light: " << problem);
  }
  Internals& impl = *this->Impl;
  CallState call;
  if (!impl.ReadSamples(samples, call))
  {
    PENUMBRA_FAIL("view sample arrays are missing or do not match the sample count");
  }
  impl.UpdateCasters(geometry, this->DenseCells == DENSE_TREE);
  if (!impl.SetUpLight(this, area, geometry, samples, call))
  {
    PENUMBRA_FAIL("unsupported light sampling: " << call.Light.K << " samples per axis");
  }
  impl.SetUpOutputs(this, visibility, call);
  impl.ChoosePath(this, renderer, call);
  impl.ClassifySamples(this, call);
  // ---- Per side of the light plane: grid, lists, masks.
  call.GridUsed = this->GridResolution;
  for (const int flip : { 1, -1 })
  {
    impl.ProcessSide(this, call, flip);
  }
  if (!impl.TraceUndecided(this, samples, visibility, call))
  {
    return 0;
  }
  impl.StoreStatistics(this, call);
  visibility->Modified();
  impl.Uncertain->Modified();
  impl.Masks->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
// Input check: the view samples' arrays, all of one length.
bool vtkPenumbraGearsShadows::Internals::ReadSamples(
  vtkPenumbraViewSamples* samples, CallState& call)
{
  const vtkIdType n = samples->GetNumberOfSamples();
  vtkFloatArray* posArray = samples->GetPositions();
  vtkFloatArray* nrmArray = samples->GetNormals();
  vtkIntArray* propArray = samples->GetPropIndices();
  vtkIdTypeArray* triArray = samples->GetTriangleIds();
  if (!posArray || !nrmArray || !propArray || !triArray || posArray->GetNumberOfComponents() != 3 ||
    nrmArray->GetNumberOfComponents() != 3 || posArray->GetNumberOfTuples() != n ||
    nrmArray->GetNumberOfTuples() != n || propArray->GetNumberOfTuples() != n ||
    triArray->GetNumberOfTuples() != n)
  {
    return false;
  }
  call.N = n;
  call.Pos = n ? posArray->GetPointer(0) : nullptr;
  call.Nrm = n ? nrmArray->GetPointer(0) : nullptr;
  call.Props = n ? propArray->GetPointer(0) : nullptr;
  call.Tris = n ? triArray->GetPointer(0) : nullptr;
  return true;
}

//------------------------------------------------------------------------------
// Light set-up: the light samples in the geometry's rebased frame (differences in double,
// as the reference takes them), the emitter's axes and extent, and the reference's
// constants. False if the light's sampling does not fit a mask row.
bool vtkPenumbraGearsShadows::Internals::SetUpLight(vtkPenumbraGearsShadows* self,
  vtkPenumbraAreaLight* area, vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples,
  CallState& call)
{
  double origin[3], samplesOrigin[3];
  geometry->GetOrigin(origin);
  samples->GetOrigin(samplesOrigin);
  vtkSmartPointer<vtkPenumbraAreaLight> used = area;
  if (self->SamplesPerAxis > 0 && self->SamplesPerAxis != area->GetSamplesPerAxis())
  {
    used = vtkSmartPointer<vtkPenumbraAreaLight>::Take(
      vtkPenumbraAreaLight::SafeDownCast(area->ShallowClone()));
    used->SetSamplesPerAxis(self->SamplesPerAxis);
  }
  call.Used = used;
  LightSamples& ls = call.Light;
  ls.K = used->GetSamplesPerAxis();
  const bool line = used->GetShape() == vtkPenumbraAreaLight::Line;
  ls.Rows = line ? 1 : ls.K;
  ls.Count = used->GetNumberOfSamples();
  if (ls.K > MaxK || ls.Count != ls.K * ls.Rows)
  {
    return false;
  }
  ls.Points.resize(3 * static_cast<size_t>(ls.Count));
  for (int j = 0; j < ls.Count; ++j)
  {
    double* q = &ls.Points[3 * static_cast<size_t>(j)];
    used->GetSamplePosition(j, q);
    for (int c = 0; c < 3; ++c)
    {
      q[c] -= origin[c];
    }
  }
  used->GetAxes(ls.U, ls.V, ls.N);
  used->GetCentre(ls.Centre);
  for (int c = 0; c < 3; ++c)
  {
    ls.Centre[c] -= origin[c];
  }
  const double width = used->GetWidth();
  const double height = line ? 0.0 : used->GetHeight();
  ls.DSu = width / ls.K;
  ls.Su0 = (0.5 / ls.K - 0.5) * width;
  ls.DSv = line ? 0.0 : height / ls.K;
  ls.Sv0 = line ? 0.0 : (0.5 / ls.K - 0.5) * height;
  ls.HalfU = std::fabs(ls.Su0);
  ls.HalfV = std::fabs(ls.Sv0);
  ls.Diagonal = std::sqrt(width * width + height * height);
  call.Off = !penumbra_rules::LightEmits(used);

  for (int c = 0; c < 3; ++c)
  {
    call.Shift[c] = samplesOrigin[c] - origin[c];
  }
  call.Epsilon = self->Reference->GetRelativeEpsilon();
  call.TieFactor = self->Reference->GetTieFactor();
  call.Diagonal = this->Diagonal;
  return true;
}

//------------------------------------------------------------------------------
// The outputs, sized and cleared: visibility, the uncertain flags and (if kept) the masks.
void vtkPenumbraGearsShadows::Internals::SetUpOutputs(
  vtkPenumbraGearsShadows* self, vtkFloatArray* visibility, CallState& call)
{
  const vtkIdType n = call.N;
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  call.Vis = n ? visibility->GetPointer(0) : nullptr;
  this->Uncertain->SetNumberOfComponents(1);
  this->Uncertain->SetNumberOfTuples(n);
  call.Uncertain = n ? this->Uncertain->GetPointer(0) : nullptr;
  if (call.Uncertain)
  {
    std::fill(call.Uncertain, call.Uncertain + n, 0);
  }
  call.Words = (call.Light.Count + 31) / 32;
  call.Masks = nullptr;
  if (self->KeepMasks)
  {
    this->Masks->SetNumberOfComponents(call.Words);
    this->Masks->SetNumberOfTuples(n);
    call.Masks = n ? this->Masks->GetPointer(0) : nullptr;
    if (call.Masks)
    {
      std::fill(call.Masks, call.Masks + static_cast<size_t>(n) * call.Words, 0u);
    }
  }
  else
  {
    this->Masks->Initialize();
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraGearsShadows::Internals::ReportPathProblem(
  vtkPenumbraGearsShadows* self, const std::string& why)
{
  this->PathMessage =
    "GEARS compute path unavailable (" + why + "); the CPU path computes the masks";
  if (this->Reported.insert(why).second)
  {
    vtkWarningWithObjectMacro(self, << this->PathMessage);
  }
}

//------------------------------------------------------------------------------
// Where step 4 runs: the compute path when asked for and possible, else the CPU; and the
// list length above which a cell's samples are ray traced whole (CPU path only: the compute
// path has no use for the split).
void vtkPenumbraGearsShadows::Internals::ChoosePath(
  vtkPenumbraGearsShadows* self, vtkRenderer* renderer, CallState& call)
{
  const int requested = self->Path == PATH_AUTO ? PATH_CPU : self->Path;
  bool useGpu = false;
  this->PathMessage.clear();
  if (requested == PATH_GPU && !call.Off && call.N > 0 && !this->Casters.empty())
  {
    std::string why;
    auto* window =
      renderer ? vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow()) : nullptr;
    if (std::any_of(this->Casters.begin(), this->Casters.end(),
          [](const Caster& c) { return c.Id > std::numeric_limits<std::int32_t>::max(); }))
    {
      why = "triangle ids beyond 2^31 do not fit the shader's 32-bit ids";
    }
    else
    {
      useGpu = this->Compute.Prepare(window, call.Light.K, call.Light.Rows, self->KeepMasks, why) &&
        this->Compute.SetCasters(this->CasterData, this->CasterVersion, why) &&
        this->Compute.SetSamples(call.Pos, call.Nrm, call.Tris, call.N, why);
    }
    if (!useGpu)
    {
      this->ReportPathProblem(self, why);
    }
  }
  self->LastPath = PATH_CPU;
  call.UseGpu = useGpu;
  call.TraceLimit =
    !useGpu && self->TraceThreshold > 0.0 ? self->TraceThreshold * call.Light.Count : 0.0;
  call.DenseTree = self->DenseCells == DENSE_TREE;
}

//------------------------------------------------------------------------------
// Classify the samples: invalid, light off, facing away from the whole light, or on a side
// of the light plane (Scratch.Side: 1 front, -1 back, 2 on the plane, 0 decided).
void vtkPenumbraGearsShadows::Internals::ClassifySamples(
  vtkPenumbraGearsShadows* self, CallState& call)
{
  const vtkIdType n = call.N;
  const LightSamples& ls = call.Light;
  float* vis = call.Vis;
  std::vector<signed char>& side = this->Scratch.Side;
  side.assign(static_cast<size_t>(n), 0);
  std::atomic<vtkIdType> validCount(0);
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType localValid = 0;
      std::uint64_t rows[MaxK];
      for (vtkIdType s = begin; s < end; ++s)
      {
        SampleRays r;
        if (!call.LoadSample(s, r))
        {
          vis[s] = -1.0f;
          continue;
        }
        ++localValid;
        if (call.Off)
        {
          vis[s] = 1.0f; // the reference's rule: nothing to shadow
          for (int j = 0; j < ls.Rows; ++j)
          {
            rows[j] = Span(0, ls.K - 1);
          }
          call.WriteMask(s, rows);
          continue;
        }
        // Facing is affine over the light: below the tangent plane at every corner (with a
        // margin for the per-sample rounding) means below it for every light sample.
        double best = -std::numeric_limits<double>::infinity();
        double reach = 0.0;
        for (int c = 0; c < 4; ++c)
        {
          const double* q = ls.Corner(c);
          const double toLight[3] = { q[0] - r.P[0], q[1] - r.P[1], q[2] - r.P[2] };
          best = std::max(best, vtkMath::Dot(r.Normal, toLight));
          reach = std::max(reach, vtkMath::Norm(toLight));
        }
        if (best < -1e-9 * reach)
        {
          vis[s] = 0.0f;
          continue;
        }
        const double z = vtkMath::Dot(ls.N, r.P) - vtkMath::Dot(ls.N, ls.Centre);
        side[static_cast<size_t>(s)] = z > 0.0 ? 1 : (z < 0.0 ? -1 : 2);
      }
      validCount += localValid;
    });
  self->NumberOfValidSamples = validCount.load();
}

//------------------------------------------------------------------------------
// One side of the light plane: the grid camera and the sample binning (Wang et al. 2014,
// A.1-A.2), the triangle lists (A.3, with the switch of long-list cells to ray tracing) and
// the masks (§3, step 4) on the compute path or the CPU.
void vtkPenumbraGearsShadows::Internals::ProcessSide(
  vtkPenumbraGearsShadows* self, CallState& call, int flip)
{
  const auto gridStart = Clock::now();
  SideState S;
  if (!this->GatherSide(call, S, flip))
  {
    return;
  }
  // The per-caster arrays of the last side (tens of MB on a 1 M-triangle mesh) are reused:
  // fresh ones cost page faults every frame.
  ScratchArrays& keep = this->Scratch;
  S.ZNear.swap(keep.ZNear);
  S.Foot.swap(keep.Foot);
  S.Range.swap(keep.Range);
  S.Touched.swap(keep.Touched);
  this->PlaceCamera(self, call, S);
  this->CasterFootprints(call, S);
  this->BuildGrid(self, call, S);
  const ScratchArrays& sc = this->Scratch;
  call.GridUsed = std::min(call.GridUsed, S.G);
  const size_t cells = static_cast<size_t>(S.G) * S.G;
  call.Occupied += static_cast<vtkIdType>(sc.Occupied.size());
  call.Cells += static_cast<vtkIdType>(cells);
  call.ListTotal += static_cast<vtkIdType>(sc.CellList.size());
  call.GlobalTotal += static_cast<vtkIdType>(sc.GlobalList.size());
  for (const std::int32_t c : sc.Occupied)
  {
    call.MaxPerCell = std::max<vtkIdType>(call.MaxPerCell, sc.CellStart[c + 1] - sc.CellStart[c]);
  }
  call.GridMs += ElapsedMs(gridStart);

  // ---- Step 4: masks. Every sample considers its cell list and the global list.
  const auto maskStart = Clock::now();
  this->RouteTracedCells(call);
  if (call.DenseTree &&
    std::any_of(sc.Occupied.begin(), sc.Occupied.end(),
      [&](std::int32_t c) { return sc.Traced[static_cast<size_t>(c)] != 0; }))
  {
    this->Tree.Refit(this->Scratch.TriangleBoxes.data(), this->Scratch.TreeBoxes);
  }
  this->Scratch.OnCPU.clear();
  bool allOnCPU = !call.UseGpu;
  if (call.UseGpu && !this->MasksOnComputePath(self, call, S))
  {
    allOnCPU = true;
  }
  this->MasksOnCPU(call, S, allOnCPU);
  call.MaskMs += ElapsedMs(maskStart);
  S.ZNear.swap(keep.ZNear);
  S.Foot.swap(keep.Foot);
  S.Range.swap(keep.Range);
  S.Touched.swap(keep.Touched);
}

//------------------------------------------------------------------------------
// The light frame of this side, z toward the samples (Wang et al. 2014, §4, A.1; the back
// side mirrors), and this side's samples in it (Scratch.Ids, Scratch.Frame). False if the
// side has no samples.
bool vtkPenumbraGearsShadows::Internals::GatherSide(const CallState& call, SideState& S, int flip)
{
  const LightSamples& ls = call.Light;
  S.Flip = flip;
  S.Centre = ls.Centre;
  for (int c = 0; c < 3; ++c)
  {
    S.Ax[0][c] = ls.U[c];
    S.Ax[1][c] = ls.V[c];
    S.Ax[2][c] = flip * ls.N[c];
  }
  const std::vector<signed char>& side = this->Scratch.Side;
  std::vector<vtkIdType>& ids = this->Scratch.Ids;
  ids.clear();
  for (vtkIdType s = 0; s < call.N; ++s)
  {
    if (side[static_cast<size_t>(s)] == flip)
    {
      ids.push_back(s);
    }
  }
  if (ids.empty())
  {
    return false;
  }
  const vtkIdType m = static_cast<vtkIdType>(ids.size());
  S.M = m;
  std::vector<double>& frame = this->Scratch.Frame;
  frame.assign(3 * static_cast<size_t>(m), 0.0);
  double maxScale = call.Diagonal;
  S.ZFar = 0.0;
  const double lo3[3] = { -ls.HalfU, -ls.HalfV, 0.0 }, hi3[3] = { ls.HalfU, ls.HalfV, 0.0 };
  std::copy(lo3, lo3 + 3, S.Lo3);
  std::copy(hi3, hi3 + 3, S.Hi3);
  for (vtkIdType q = 0; q < m; ++q)
  {
    const vtkIdType s = ids[static_cast<size_t>(q)];
    double p[3];
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(call.Pos[3 * s + c]) + call.Shift[c];
    }
    double* f = &frame[3 * static_cast<size_t>(q)];
    S.ToFrame(p, f);
    f[2] = std::max(f[2], 0.0); // rounding of the side test; z > 0 by construction
    S.ZFar = std::max(S.ZFar, f[2]);
    maxScale = std::max(maxScale, vtkMath::Norm(p));
    for (int c = 0; c < 3; ++c)
    {
      S.Lo3[c] = std::min(S.Lo3[c], f[c]);
      S.Hi3[c] = std::max(S.Hi3[c], f[c]);
    }
  }
  // Triangles within this of the light plane, the far plane or a cell border are treated
  // as touching it: the float32 ray may hit them that much off.
  S.Tolerance = 4.0 * RelativePositionTolerance * maxScale;
  return true;
}

//------------------------------------------------------------------------------
// Camera C behind the light (z < 0) on the line from the AABB centre through the light
// centre, at CameraDistanceFactor x diagonal (Wang et al. 2014, §4, A.1); any z_C < 0 is
// conservative. The samples projected from C onto the far plane (Scratch.Proj) and their
// bounds.
void vtkPenumbraGearsShadows::Internals::PlaceCamera(
  vtkPenumbraGearsShadows* self, const CallState& call, SideState& S)
{
  double dir[3] = { -0.5 * (S.Lo3[0] + S.Hi3[0]), -0.5 * (S.Lo3[1] + S.Hi3[1]),
    -0.5 * (S.Lo3[2] + S.Hi3[2]) };
  if (!(vtkMath::Normalize(dir) > 0.0) || !(dir[2] < -0.25))
  {
    dir[0] = 0.0;
    dir[1] = 0.0;
    dir[2] = -1.0;
  }
  S.Distance =
    std::max(self->CameraDistanceFactor * call.Light.Diagonal, 1e-3 * std::max(S.ZFar, 1e-300));
  for (int c = 0; c < 3; ++c)
  {
    S.Cam[c] = dir[c] * S.Distance;
  }
  const std::vector<double>& frame = this->Scratch.Frame;
  std::vector<double>& proj = this->Scratch.Proj;
  proj.assign(2 * static_cast<size_t>(S.M), 0.0);
  double* pb = S.Pb;
  pb[0] = std::numeric_limits<double>::infinity();
  pb[1] = -std::numeric_limits<double>::infinity();
  pb[2] = std::numeric_limits<double>::infinity();
  pb[3] = -std::numeric_limits<double>::infinity();
  for (vtkIdType q = 0; q < S.M; ++q)
  {
    double* pr = &proj[2 * static_cast<size_t>(q)];
    S.Project(&frame[3 * static_cast<size_t>(q)], pr);
    pb[0] = std::min(pb[0], pr[0]);
    pb[1] = std::max(pb[1], pr[0]);
    pb[2] = std::min(pb[2], pr[1]);
    pb[3] = std::max(pb[3], pr[1]);
  }
  S.Extent = std::max({ pb[1] - pb[0], pb[3] - pb[2], 1e-9 * (S.ZFar + S.Distance) });
}

//------------------------------------------------------------------------------
// Per caster on this side: culled, global (touches the light plane) or the box on the far
// plane that its shadow can reach (Wang et al. 2014, A.3, in closed form in the light's
// frame: extrusion rectangles and projections from C).
void vtkPenumbraGearsShadows::Internals::CasterFootprints(const CallState& call, SideState& S)
{
  const LightSamples& ls = call.Light;
  const vtkIdType nCasters = static_cast<vtkIdType>(this->Casters.size());
  S.ZNear.assign(static_cast<size_t>(nCasters), 0.0);
  S.Foot.resize(static_cast<size_t>(nCasters));
  std::vector<double>& triBoxes = this->Scratch.TriangleBoxes;
  triBoxes.resize(6 * static_cast<size_t>(nCasters));
  const double tolerance = S.Tolerance, zFar = S.ZFar;
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        const Caster& tri = this->Casters[static_cast<size_t>(t)];
        Footprint& fp = S.Foot[static_cast<size_t>(t)];
        double f[3][3];
        double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
        for (int i = 0; i < 3; ++i)
        {
          S.ToFrame(tri.V[i], f[i]);
          zmin = std::min(zmin, f[i][2]);
          zmax = std::max(zmax, f[i][2]);
        }
        S.ZNear[static_cast<size_t>(t)] = zmin;
        double* tb = &triBoxes[6 * static_cast<size_t>(t)];
        for (int a = 0; a < 3; ++a)
        {
          tb[2 * a] = std::min({ f[0][a], f[1][a], f[2][a] }) - tolerance;
          tb[2 * a + 1] = std::max({ f[0][a], f[1][a], f[2][a] }) + tolerance;
        }
        if (zmax < -tolerance || zmin > zFar + tolerance)
        {
          fp.State = 0; // wholly behind the light plane or beyond every sample
          continue;
        }
        if (zmin <= tolerance)
        {
          fp.State = 1; // touches the light plane: unbounded extrusion
          continue;
        }
        double box[4] = { std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity() };
        double rmax = 1.0;
        for (int i = 0; i < 3; ++i)
        {
          const double r = zFar / f[i][2];
          rmax = std::max(rmax, r);
          const double hx = std::fabs(r - 1.0) * ls.HalfU;
          const double hy = std::fabs(r - 1.0) * ls.HalfV;
          box[0] = std::min(box[0], r * f[i][0] - hx);
          box[1] = std::max(box[1], r * f[i][0] + hx);
          box[2] = std::min(box[2], r * f[i][1] - hy);
          box[3] = std::max(box[3], r * f[i][1] + hy);
          double pc[2];
          S.Project(f[i], pc);
          box[0] = std::min(box[0], pc[0]);
          box[1] = std::max(box[1], pc[0]);
          box[2] = std::min(box[2], pc[1]);
          box[3] = std::max(box[3], pc[1]);
        }
        const double pad =
          2.0 * tolerance * (rmax + (zFar - S.Cam[2]) / (-S.Cam[2])) + 1e-9 * S.Extent;
        fp.Box[0] = box[0] - pad;
        fp.Box[1] = box[1] + pad;
        fp.Box[2] = box[2] - pad;
        fp.Box[3] = box[3] + pad;
        fp.State = std::isfinite(pad) && std::isfinite(box[0] + box[1] + box[2] + box[3]) ? 2 : 1;
      }
    });
}

//------------------------------------------------------------------------------
// The grid and its lists at GridResolution, coarsened while the lists would exceed
// MaxListEntries (Wang et al. 2014, A.2-A.3).
void vtkPenumbraGearsShadows::Internals::BuildGrid(
  vtkPenumbraGearsShadows* self, const CallState& call, SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  sc.SampleCell.assign(static_cast<size_t>(S.M), 0);
  for (auto* v : { &sc.CellStart, &sc.CellList, &sc.GlobalList, &sc.SampleOrder, &sc.SampleStart })
  {
    v->clear();
  }
  sc.Occupied.clear();
  S.G = self->GridResolution;
  for (;;)
  {
    this->BinSamples(S);
    this->CasterRanges(S);
    this->MarkTracedCells(call, S);
    const int g = S.G;
    if (S.Total > static_cast<std::int64_t>(self->MaxListEntries) && g > 1)
    {
      vtkWarningWithObjectMacro(self,
        "GEARS lists would hold " << S.Total << " entries (limit " << self->MaxListEntries
                                  << ") at a " << g << "^2 grid; coarsening to " << g / 2 << "^2");
      S.G /= 2;
      continue;
    }
    if (g == 1)
    {
      // Every remaining caster covers the single cell: list them once, globally.
      for (size_t t = 0; t < this->Casters.size(); ++t)
      {
        if (S.Touched[t] > 0)
        {
          sc.GlobalList.push_back(static_cast<std::uint32_t>(t));
        }
      }
      sc.CellStart.assign(2, 0);
      sc.CellList.clear();
      S.Total = 0;
      break;
    }
    this->FillCellLists(S);
    break;
  }
}

//------------------------------------------------------------------------------
// Wang et al. 2014, A.2: the grid over the projected samples, and the samples binned by cell
// (counting sort), with the occupied cells and a summed-area table of them.
void vtkPenumbraGearsShadows::Internals::BinSamples(SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  const int g = S.G;
  const vtkIdType m = S.M;
  const double* pb = S.Pb;
  const double extent = S.Extent;
  const double x0 = S.X0 = pb[0] - 1e-9 * extent;
  const double y0 = S.Y0 = pb[2] - 1e-9 * extent;
  const double cw = S.Cw = std::max(pb[1] - pb[0], 1e-6 * extent) * (1.0 + 1e-7) / g;
  const double ch = S.Ch = std::max(pb[3] - pb[2], 1e-6 * extent) * (1.0 + 1e-7) / g;
  const size_t cells = static_cast<size_t>(g) * g;
  auto cellOf = [&](double px, double py, int& ix, int& iy)
  {
    ix = static_cast<int>(std::min<double>(g - 1, std::max(0.0, std::floor((px - x0) / cw))));
    iy = static_cast<int>(std::min<double>(g - 1, std::max(0.0, std::floor((py - y0) / ch))));
  };
  std::vector<std::uint32_t>& count = S.Count;
  count.assign(cells + 1, 0);
  const std::vector<double>& proj = sc.Proj;
  for (vtkIdType q = 0; q < m; ++q)
  {
    int ix, iy;
    cellOf(proj[2 * q], proj[2 * q + 1], ix, iy);
    sc.SampleCell[static_cast<size_t>(q)] = iy * g + ix;
    ++count[static_cast<size_t>(iy * g + ix)];
  }
  // Summed-area table of occupancy: cells a footprint touches, counted in O(1).
  std::vector<std::int64_t>& sat = S.Sat;
  sat.assign(static_cast<size_t>(g + 1) * (g + 1), 0);
  sc.Occupied.clear();
  for (int iy = 0; iy < g; ++iy)
  {
    for (int ix = 0; ix < g; ++ix)
    {
      const bool busy = count[static_cast<size_t>(iy * g + ix)] > 0;
      if (busy)
      {
        sc.Occupied.push_back(iy * g + ix);
      }
      sat[static_cast<size_t>(iy + 1) * (g + 1) + ix + 1] = (busy ? 1 : 0) +
        sat[static_cast<size_t>(iy) * (g + 1) + ix + 1] +
        sat[static_cast<size_t>(iy + 1) * (g + 1) + ix] -
        sat[static_cast<size_t>(iy) * (g + 1) + ix];
    }
  }
  std::vector<std::uint32_t>& sampleStart = sc.SampleStart;
  sampleStart.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c)
  {
    sampleStart[c + 1] = sampleStart[c] + count[c];
  }
  sc.SampleOrder.resize(static_cast<size_t>(m));
  std::vector<std::uint32_t> cursor(sampleStart.begin(), sampleStart.end() - 1);
  for (vtkIdType q = 0; q < m; ++q)
  {
    sc.SampleOrder[cursor[static_cast<size_t>(sc.SampleCell[static_cast<size_t>(q)])]++] =
      static_cast<std::uint32_t>(q);
  }
}

//------------------------------------------------------------------------------
// Wang et al. 2014, A.3: each caster's footprint as a range of cells; those that would enter
// more than half the busy cells join the global list instead (Scratch.GlobalList).
void vtkPenumbraGearsShadows::Internals::CasterRanges(SideState& S)
{
  const vtkIdType nCasters = static_cast<vtkIdType>(this->Casters.size());
  const int g = S.G;
  const double x0 = S.X0, y0 = S.Y0, cw = S.Cw, ch = S.Ch;
  const std::vector<std::int64_t>& sat = S.Sat;
  std::vector<int>& range = S.Range;
  std::vector<std::int64_t>& touched = S.Touched;
  range.assign(4 * static_cast<size_t>(nCasters), 0);
  touched.assign(static_cast<size_t>(nCasters), 0);
  const std::int64_t busyCells = static_cast<std::int64_t>(this->Scratch.Occupied.size());
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        const Footprint& fp = S.Foot[static_cast<size_t>(t)];
        int* rg = &range[4 * static_cast<size_t>(t)];
        if (fp.State != 2)
        {
          touched[static_cast<size_t>(t)] = fp.State == 1 ? -1 : 0;
          continue;
        }
        const double bx0 = std::floor((fp.Box[0] - x0) / cw),
                     bx1 = std::floor((fp.Box[1] - x0) / cw);
        const double by0 = std::floor((fp.Box[2] - y0) / ch),
                     by1 = std::floor((fp.Box[3] - y0) / ch);
        if (bx1 < 0 || by1 < 0 || bx0 > g - 1 || by0 > g - 1)
        {
          touched[static_cast<size_t>(t)] = 0;
          continue;
        }
        rg[0] = static_cast<int>(std::max(0.0, bx0));
        rg[1] = static_cast<int>(std::min<double>(g - 1, bx1));
        rg[2] = static_cast<int>(std::max(0.0, by0));
        rg[3] = static_cast<int>(std::min<double>(g - 1, by1));
        const std::int64_t c = sat[static_cast<size_t>(rg[3] + 1) * (g + 1) + rg[1] + 1] -
          sat[static_cast<size_t>(rg[2]) * (g + 1) + rg[1] + 1] -
          sat[static_cast<size_t>(rg[3] + 1) * (g + 1) + rg[0]] +
          sat[static_cast<size_t>(rg[2]) * (g + 1) + rg[0]];
        // A list entry in more than half the busy cells costs more than one global entry.
        touched[static_cast<size_t>(t)] = (busyCells > 8 && 2 * c > busyCells) ? -1 : c;
      }
    });
  std::vector<std::uint32_t>& globalList = this->Scratch.GlobalList;
  std::int64_t total = 0;
  globalList.clear();
  for (vtkIdType t = 0; t < nCasters; ++t)
  {
    const std::int64_t c = touched[static_cast<size_t>(t)];
    if (c < 0)
    {
      globalList.push_back(static_cast<std::uint32_t>(t));
    }
    else
    {
      total += c;
    }
  }
  S.Total = total;
}

//------------------------------------------------------------------------------
// The long-list switch: cells whose list costs more than tracing their light samples. On a
// dense mesh under a large light a cell meets hundreds of tiny triangles each covering less
// than one light sample, and Embree's log N per ray wins. Their samples go to the reference
// whole (exact by construction) and their lists are never built (Scratch.Traced).
void vtkPenumbraGearsShadows::Internals::MarkTracedCells(const CallState& call, SideState& S)
{
  const int g = S.G;
  std::vector<unsigned char>& traced = this->Scratch.Traced;
  traced.assign(static_cast<size_t>(g) * g, 0);
  if (call.TraceLimit > 0.0 && g > 1)
  {
    const std::vector<std::int64_t> lengths = CellListLengths(g, S.Range, S.Touched);
    const double limit = call.TraceLimit - static_cast<double>(this->Scratch.GlobalList.size());
    for (const std::int32_t c : this->Scratch.Occupied)
    {
      if (static_cast<double>(lengths[static_cast<size_t>(c)]) > limit)
      {
        traced[static_cast<size_t>(c)] = 1;
        S.Total -= lengths[static_cast<size_t>(c)];
      }
    }
  }
}

//------------------------------------------------------------------------------
// The cell lists (Wang et al. 2014, A.3): a counting sort of (caster, cell) pairs by cell,
// busy untraced cells only, each list sorted largest triangle first.
void vtkPenumbraGearsShadows::Internals::FillCellLists(SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  const vtkIdType nCasters = static_cast<vtkIdType>(this->Casters.size());
  const int g = S.G;
  const size_t cells = static_cast<size_t>(g) * g;
  std::vector<std::atomic<std::uint32_t>> perCell(cells);
  for (auto& a : perCell)
  {
    a.store(0, std::memory_order_relaxed);
  }
  // Per row, the columns of the cells that get a list (busy, not dense), so a caster's
  // range costs its list entries, not its area: under a large light the footprints span
  // thousands of cells, most of them empty or dense. A summed-area table of those cells
  // skips the casters (most of a dense mesh) whose range holds none.
  std::vector<std::uint32_t> rowStart(static_cast<size_t>(g) + 1, 0);
  std::vector<int> columns;
  std::vector<std::uint32_t> listed(static_cast<size_t>(g + 1) * (g + 1), 0);
  for (const std::int32_t c : sc.Occupied) // row-major order
  {
    if (!sc.Traced[static_cast<size_t>(c)])
    {
      columns.push_back(c % g);
      ++rowStart[static_cast<size_t>(c / g) + 1];
      listed[static_cast<size_t>(c / g + 1) * (g + 1) + c % g + 1] = 1;
    }
  }
  for (int iy = 0; iy < g; ++iy)
  {
    rowStart[static_cast<size_t>(iy) + 1] += rowStart[static_cast<size_t>(iy)];
  }
  for (int iy = 1; iy <= g; ++iy)
  {
    for (int ix = 1; ix <= g; ++ix)
    {
      const size_t at = static_cast<size_t>(iy) * (g + 1) + ix;
      listed[at] += listed[at - 1] + listed[at - (g + 1)] - listed[at - (g + 1) - 1];
    }
  }
  auto forCells = [&](vtkIdType t, auto&& fn)
  {
    const int* rg = &S.Range[4 * static_cast<size_t>(t)];
    const size_t w = static_cast<size_t>(g) + 1;
    if (listed[(rg[3] + 1) * w + rg[1] + 1] - listed[rg[2] * w + rg[1] + 1] -
        listed[(rg[3] + 1) * w + rg[0]] + listed[rg[2] * w + rg[0]] ==
      0)
    {
      return;
    }
    for (int iy = rg[2]; iy <= rg[3]; ++iy)
    {
      const auto rowEnd = columns.begin() + rowStart[static_cast<size_t>(iy) + 1];
      for (auto it =
             std::lower_bound(columns.begin() + rowStart[static_cast<size_t>(iy)], rowEnd, rg[0]);
           it != rowEnd && *it <= rg[1]; ++it)
      {
        fn(static_cast<size_t>(iy) * g + *it);
      }
    }
  };
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        if (S.Touched[static_cast<size_t>(t)] > 0)
        {
          forCells(t, [&](size_t cell) { perCell[cell].fetch_add(1, std::memory_order_relaxed); });
        }
      }
    });
  std::vector<std::uint32_t>& cellStart = sc.CellStart;
  std::vector<std::uint32_t>& cellList = sc.CellList;
  cellStart.assign(cells + 1, 0);
  for (size_t c = 0; c < cells; ++c)
  {
    cellStart[c + 1] = cellStart[c] + perCell[c].load(std::memory_order_relaxed);
    perCell[c].store(cellStart[c], std::memory_order_relaxed);
  }
  cellList.resize(static_cast<size_t>(cellStart[cells]));
  vtkSMPTools::For(0, nCasters,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        if (S.Touched[static_cast<size_t>(t)] > 0)
        {
          forCells(t,
            [&](size_t cell)
            {
              cellList[perCell[cell].fetch_add(1, std::memory_order_relaxed)] =
                static_cast<std::uint32_t>(t);
            });
        }
      }
    });
  // Largest triangles first: a sample in umbra fills its mask and stops sooner. The
  // order also makes the lists (and the statistics) independent of thread timing.
  const auto& bounds = this->Bounds;
  vtkSMPTools::For(0, static_cast<vtkIdType>(sc.Occupied.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType b = begin; b < end; ++b)
      {
        const size_t cell = static_cast<size_t>(sc.Occupied[static_cast<size_t>(b)]);
        std::sort(cellList.begin() + cellStart[cell], cellList.begin() + cellStart[cell + 1],
          [&](std::uint32_t x, std::uint32_t y) {
            return bounds[x].Radius > bounds[y].Radius ||
              (bounds[x].Radius == bounds[y].Radius && x < y);
          });
      }
    });
}

//------------------------------------------------------------------------------
// Step 4's bookkeeping: the samples of ray-traced cells are flagged uncertain (the reference
// takes them whole); every other sample will consider its cell list and the global list.
void vtkPenumbraGearsShadows::Internals::RouteTracedCells(CallState& call)
{
  const ScratchArrays& sc = this->Scratch;
  for (const std::int32_t cell : sc.Occupied)
  {
    if (sc.Traced[static_cast<size_t>(cell)] && call.DenseTree)
    {
      call.TreeSamples += sc.SampleStart[cell + 1] - sc.SampleStart[cell];
      continue; // the tree walk counts its own assignments
    }
    if (sc.Traced[static_cast<size_t>(cell)])
    {
      for (std::uint32_t o = sc.SampleStart[cell]; o < sc.SampleStart[cell + 1]; ++o)
      {
        call.Uncertain[sc.Ids[sc.SampleOrder[o]]] = 1;
      }
      call.TracedCellSamples += sc.SampleStart[cell + 1] - sc.SampleStart[cell];
      continue;
    }
    call.Assignments += static_cast<vtkIdType>(sc.SampleStart[cell + 1] - sc.SampleStart[cell]) *
      static_cast<vtkIdType>(sc.CellStart[cell + 1] - sc.CellStart[cell] + sc.GlobalList.size());
  }
}

//------------------------------------------------------------------------------
// Step 4 on the compute path: the shader's masks for this side, the samples it flagged left
// to the CPU (Scratch.OnCPU). False, with the path dropped for the rest of the call, if the
// run failed.
bool vtkPenumbraGearsShadows::Internals::MasksOnComputePath(
  vtkPenumbraGearsShadows* self, CallState& call, const SideState& S)
{
  ScratchArrays& sc = this->Scratch;
  const LightSamples& ls = call.Light;
  const vtkIdType m = S.M;
  std::vector<std::uint32_t>& work = sc.Work;
  work.assign(2 * static_cast<size_t>(m), 0u);
  for (vtkIdType o = 0; o < m; ++o)
  {
    const std::uint32_t q = sc.SampleOrder[static_cast<size_t>(o)];
    work[2 * o] = static_cast<std::uint32_t>(sc.Ids[q]);
    work[2 * o + 1] = static_cast<std::uint32_t>(sc.SampleCell[q]);
  }
  penumbra_gears::ComputeLight cl;
  cl.K = ls.K;
  cl.Rows = ls.Rows;
  cl.Points = ls.Points.data();
  std::copy(ls.Centre, ls.Centre + 3, cl.Centre);
  std::copy(ls.U, ls.U + 3, cl.U);
  std::copy(ls.V, ls.V + 3, cl.V);
  std::copy(ls.N, ls.N + 3, cl.N);
  cl.Su0 = ls.Su0;
  cl.DSu = ls.DSu;
  cl.Sv0 = ls.Sv0;
  cl.DSv = ls.DSv;
  penumbra_gears::ComputeConstants cc;
  std::copy(call.Shift, call.Shift + 3, cc.Shift);
  cc.Epsilon = call.Epsilon;
  cc.TieFactor = call.TieFactor;
  cc.Diagonal = call.Diagonal;
  cc.RelativeTolerance = RelativePositionTolerance;
  penumbra_gears::ComputeSide cs;
  cs.Flip = S.Flip;
  cs.FarSlack = S.Tolerance;
  cs.ZNear = S.ZNear.data();
  cs.CellStart = sc.CellStart.data();
  cs.Cells = sc.CellStart.size() - 1;
  cs.CellList = sc.CellList.data();
  cs.ListSize = sc.CellList.size();
  cs.GlobalList = sc.GlobalList.data();
  cs.GlobalSize = sc.GlobalList.size();
  cs.Work = work.data();
  cs.WorkCount = static_cast<size_t>(m);
  std::string why;
  if (!this->Compute.Run(cl, cc, cs, sc.Results, call.Masks ? &sc.Rows : nullptr, why))
  {
    this->ReportPathProblem(self, why);
    call.UseGpu = false;
    return false;
  }
  self->LastPath = PATH_GPU;
  vtkIdType sideNecessary = 0, sideTests = 0;
  for (vtkIdType o = 0; o < m; ++o)
  {
    const std::uint32_t* res = &sc.Results[3 * static_cast<size_t>(o)];
    if (res[0] == penumbra_gears::Flagged)
    {
      sc.OnCPU.push_back(static_cast<std::uint32_t>(o));
      continue;
    }
    const vtkIdType s = sc.Ids[sc.SampleOrder[static_cast<size_t>(o)]];
    call.Vis[s] = static_cast<float>(res[0]) / static_cast<float>(ls.Count);
    sideNecessary += res[1];
    sideTests += res[2];
    if (call.Masks)
    {
      std::uint64_t rows[MaxK];
      for (int j = 0; j < ls.Rows; ++j)
      {
        rows[j] = sc.Rows[static_cast<size_t>(o) * ls.Rows + j];
      }
      call.WriteMask(s, rows);
    }
  }
  call.Necessary += sideNecessary;
  call.SegmentTests += sideTests;
  call.Flagged += static_cast<vtkIdType>(sc.OnCPU.size());
  return true;
}

//------------------------------------------------------------------------------
// Step 4 on the CPU (Wang et al. 2014, §3, step 4, with the exact predicate of MaskBuilder):
// the samples the compute path flagged, or with allOnCPU every sample outside the traced
// cells, in cell order (neighbouring samples share a cell's lists).
void vtkPenumbraGearsShadows::Internals::MasksOnCPU(
  CallState& call, const SideState& S, bool allOnCPU)
{
  ScratchArrays& sc = this->Scratch;
  std::vector<std::uint32_t>& onCPU = sc.OnCPU;
  if (allOnCPU)
  {
    for (std::uint32_t o = 0; o < static_cast<std::uint32_t>(S.M); ++o)
    {
      if (call.DenseTree || !sc.Traced[static_cast<size_t>(sc.SampleCell[sc.SampleOrder[o]])])
      {
        onCPU.push_back(o);
      }
    }
  }
  vtkSMPTools::For(0, static_cast<vtkIdType>(onCPU.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      MaskBuilder builder(call.Light, this->Casters, call.Epsilon);
      builder.ZMin = S.ZNear.data();
      builder.Bounds = this->Bounds.data();
      builder.FarSlack = S.Tolerance;
      std::vector<int> undecided;
      for (vtkIdType f = begin; f < end; ++f)
      {
        const std::uint32_t o = onCPU[static_cast<size_t>(f)];
        this->MaskOneSample(call, builder, undecided, o, sc.SampleCell[sc.SampleOrder[o]]);
      }
      call.Necessary += builder.Necessary;
      call.SegmentTests += builder.Tests;
      call.Assignments += builder.TreeVisits;
    });
}

//------------------------------------------------------------------------------
// One view sample on the CPU: sampleOrder position `o` of cell `cell`. Its visibility and
// mask are written; its undecided light samples join the pairs the reference traces.
void vtkPenumbraGearsShadows::Internals::MaskOneSample(CallState& call, MaskBuilder& builder,
  std::vector<int>& undecided, std::uint32_t o, std::int32_t cell)
{
  const ScratchArrays& sc = this->Scratch;
  const std::uint32_t* list = sc.CellList.data() + sc.CellStart[cell];
  const std::uint32_t listSize = sc.CellStart[cell + 1] - sc.CellStart[cell];
  const vtkIdType s = sc.Ids[sc.SampleOrder[o]];
  SampleRays r;
  call.LoadSample(s, r);
  r.Z = sc.Frame[3 * static_cast<size_t>(sc.SampleOrder[o]) + 2];
  if (!builder.Start(r))
  {
    call.Vis[s] = builder.Visibility();
    call.WriteMask(s, builder.Facing);
    return;
  }
  if (sc.Traced[static_cast<size_t>(cell)])
  {
    // A dense cell: the tree holds every caster, the global ones included.
    builder.TreeVisits += builder.VisitTree(this->Tree, sc.TreeBoxes.data(),
      sc.TriangleBoxes.data(), &sc.Frame[3 * static_cast<size_t>(sc.SampleOrder[o])]);
  }
  for (std::uint32_t e = 0; e < listSize && builder.Open; ++e)
  {
    builder.Visit(list[e]);
  }
  for (size_t e = 0; e < sc.GlobalList.size() && builder.Open && !sc.Traced[cell]; ++e)
  {
    builder.Visit(sc.GlobalList[e]);
  }
  undecided.clear();
  builder.Finish(undecided);
  call.Vis[s] = builder.Visibility();
  call.WriteMask(s, builder.Facing);
  if (!undecided.empty())
  {
    std::lock_guard<std::mutex> lock(call.TraceMutex);
    for (const int j : undecided)
    {
      call.TraceSamples.push_back(s);
      call.TraceLights.push_back(j);
    }
  }
}

//------------------------------------------------------------------------------
// Samples on the light plane and in ray-traced cells go to the reference whole; undecided
// light samples one by one, with its exact rules (Wang et al. 2014, §5.1: "identical to ray
// tracing").
int vtkPenumbraGearsShadows::Internals::TraceUndecided(vtkPenumbraGearsShadows* self,
  vtkPenumbraViewSamples* samples, vtkFloatArray* visibility, CallState& call)
{
  const auto traceStart = Clock::now();
  const vtkIdType n = call.N;
  const LightSamples& ls = call.Light;
  const std::vector<signed char>& side = this->Scratch.Side;
  unsigned char* uncertain = call.Uncertain;
  float* vis = call.Vis;
  vtkIdType nWhole = 0;
  for (vtkIdType s = 0; s < n; ++s)
  {
    if (side[static_cast<size_t>(s)] == 2)
    {
      uncertain[s] = 1;
    }
    nWhole += uncertain[s];
  }
  call.UncertainSamples = nWhole - call.TracedCellSamples;
  if (nWhole > 0)
  {
    if (!self->Reference->ComputeVisibility(samples, call.Used, visibility, this->Uncertain))
    {
      PENUMBRA_FAIL_FOR(
        self, "tracing the uncertain samples failed: " << self->Reference->GetErrorMessage());
    }
  }
  const vtkIdType nTrace = static_cast<vtkIdType>(call.TraceSamples.size());
  vtkIdType withTracedRays = 0;
  if (nTrace > 0)
  {
    std::vector<unsigned char> lit(static_cast<size_t>(nTrace));
    if (!self->Reference->TraceAreaRays(samples, call.Used, nTrace, call.TraceSamples.data(),
          call.TraceLights.data(), lit.data()))
    {
      PENUMBRA_FAIL_FOR(
        self, "tracing the undecided light samples failed: " << self->Reference->GetErrorMessage());
    }
    vtkIdType previous = -1;
    for (vtkIdType i = 0; i < nTrace; ++i)
    {
      const vtkIdType s = call.TraceSamples[static_cast<size_t>(i)];
      withTracedRays += s != previous;
      previous = s;
      if (!lit[static_cast<size_t>(i)])
      {
        continue;
      }
      // vis[s] = float(lit) / float(n) with lit recovered exactly from the known part.
      const int known = static_cast<int>(std::lround(vis[s] * ls.Count));
      vis[s] = static_cast<float>(known + 1) / static_cast<float>(ls.Count);
      if (call.Masks)
      {
        const int j = call.TraceLights[static_cast<size_t>(i)];
        call.Masks[static_cast<size_t>(s) * call.Words + j / 32] |= 1u << (j % 32);
      }
    }
  }
  call.TracedRays = nTrace;
  call.SamplesWithTracedRays = withTracedRays;
  call.TraceMs = nWhole > 0 || nTrace > 0 ? ElapsedMs(traceStart) : 0.0;
  return 1;
}

//------------------------------------------------------------------------------
// Statistics: the call's counts and times, for the getters.
void vtkPenumbraGearsShadows::Internals::StoreStatistics(
  vtkPenumbraGearsShadows* self, const CallState& call)
{
  self->TraceTimeMs = call.TraceMs;
  self->NumberOfTracedCellSamples = call.TracedCellSamples;
  self->NumberOfTreeSamples = call.TreeSamples;
  self->NumberOfTracedRays = call.TracedRays;
  self->NumberOfSamplesWithTracedRays = call.SamplesWithTracedRays;
  self->GridTimeMs = call.GridMs;
  self->MaskTimeMs = call.MaskMs;
  self->NumberOfUncertainSamples = call.UncertainSamples;
  self->NumberOfFlaggedSamples = call.Flagged;
  self->NumberOfOccupiedCells = call.Occupied;
  self->NumberOfCells = call.Cells;
  self->MaxTrianglesPerCell = call.MaxPerCell;
  self->AverageTrianglesPerCell =
    call.Occupied > 0 ? static_cast<double>(call.ListTotal) / call.Occupied : 0.0;
  self->NumberOfGlobalTriangles = call.GlobalTotal;
  self->NumberOfAssignments = call.Assignments.load();
  self->NumberOfNecessaryAssignments = call.Necessary.load();
  self->NumberOfSegmentTests = call.SegmentTests.load();
  self->EffectiveGridResolution = call.GridUsed;
}

//------------------------------------------------------------------------------
void vtkPenumbraGearsShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SamplesPerAxis: " << this->SamplesPerAxis << "\n";
  os << indent << "GridResolution: " << this->GridResolution << "\n";
  os << indent << "CameraDistanceFactor: " << this->CameraDistanceFactor << "\n";
  os << indent << "MaxListEntries: " << this->MaxListEntries << "\n";
  os << indent << "TraceThreshold: " << this->TraceThreshold << "\n";
  os << indent << "KeepMasks: " << this->KeepMasks << "\n";
  os << indent << "Path: " << this->Path << " (last " << this->LastPath << ")\n";
  os << indent << "NumberOfFlaggedSamples: " << this->NumberOfFlaggedSamples << "\n";
  os << indent << "NumberOfUncertainSamples: " << this->NumberOfUncertainSamples << "\n";
  os << indent << "NumberOfAssignments: " << this->NumberOfAssignments << "\n";
  os << indent << "NumberOfNecessaryAssignments: " << this->NumberOfNecessaryAssignments << "\n";
}

//------------------------------------------------------------------------------
const char* vtkPenumbraGearsShadows::GetTechniqueNameFor(vtkLight* light)
{
  return vtkPenumbraAreaLight::SafeDownCast(light) ? this->GetTechniqueName() : "raytraced";
}
