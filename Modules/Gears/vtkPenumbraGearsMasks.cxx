// GEARS' masks on the CPU (Wang et al. 2014, §3, step 4): the exact per-triangle predicate
// over the light samples (MaskBuilder), with the tree walk of dense cells, and the samples
// it masks.
#include "vtkPenumbraGearsShadowsInternals.h"

namespace
{
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
}

namespace penumbra_gears_shadows
{
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
    , EdgeOwner(static_cast<size_t>(l.Cells))
    , EdgeIndex(static_cast<size_t>(l.Cells))
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
        this->Facing[j] = this->Candidate[j] = this->L.Emitting[j];
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
      const std::uint64_t sure = Span(sureLo, sureHi) & this->L.Emitting[j];
      this->Facing[j] = sure;
      this->Candidate[j] = allTraced ? sure : 0;
      std::uint64_t check =
        Span(maybeLo, maybeHi) & this->L.Emitting[j] & (allTraced ? ~sure : ~std::uint64_t(0));
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
        undecided.push_back(this->L.SampleIndex(i, j));
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
