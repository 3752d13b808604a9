// GEARS step 4 (Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for Rendering
// Shadows", Computer Graphics Forum 33(6), 2014, §3, step 4; an exact cone-and-plane predicate in
// place of the paper's per-sample rasterizer) as a GL 4.3 compute shader:
// one invocation per view sample of one side of the light plane, in cell order, so the
// invocations of a work group mostly share one cell list. It is a port of MaskBuilder::Start
// and MaskBuilder::Visit of vtkPenumbraGearsMasks.cxx in double precision with the same
// margins; where the CPU path needs its per-light-sample bookkeeping (a ray on a triangle
// edge, a bit too close to call against Embree's float32 ray, a float32 rounding the CPU
// takes exactly) the sample is flagged and the CPU path redoes it, so the result stays bit
// for bit the reference's. The C++ side prepends #version 430 and the GEARS_* defines.
//
// Results per work item: [0] unoccluded light samples, or FLAGGED; [1] necessary
// assignments; [2] segment tests. With GEARS_KEEP_MASKS, GEARS_ROWS lit-mask rows follow in
// the mask buffer.

layout(local_size_x = GEARS_LOCAL_SIZE) in;

const int K = GEARS_K;         // light samples per row (<= 32: one uint per row)
const int ROWS = GEARS_ROWS;   // rows (1 for a linear light)
const int STRIDE = 29;         // doubles per caster, see vtkPenumbraGearsShadowsInternals.h
const uint FLAGGED = 0xFFFFFFFFu;

layout(std430, binding = 0) readonly buffer CasterBuffer { double casterData[]; };
layout(std430, binding = 1) readonly buffer ZNearBuffer { double zNear[]; };
layout(std430, binding = 2) readonly buffer CellStartBuffer { uint cellStart[]; };
layout(std430, binding = 3) readonly buffer CellListBuffer { uint cellList[]; };
layout(std430, binding = 4) readonly buffer GlobalListBuffer { uint globalList[]; };
layout(std430, binding = 5) readonly buffer PositionBuffer { float positions[]; };
layout(std430, binding = 6) readonly buffer NormalBuffer { float normals[]; };
layout(std430, binding = 7) readonly buffer OwnerBuffer { int owners[]; }; // vtkIdType: low word first
layout(std430, binding = 8) readonly buffer WorkBuffer { uint work[]; };   // (sample, cell) pairs
layout(std430, binding = 9) readonly buffer LightPointBuffer { double lightPoints[]; };
layout(std430, binding = 10) writeonly buffer ResultBuffer { uint results[]; };
#if GEARS_KEEP_MASKS
layout(std430, binding = 11) writeonly buffer MaskBuffer { uint masks[]; };
#endif

uniform dvec3 uCentre;
uniform dvec3 uAxisU;
uniform dvec3 uAxisV;
uniform dvec3 uAxisN;
uniform dvec3 uShift;
uniform double uSu0;
uniform double uDSu;
uniform double uSv0;
uniform double uDSv;
uniform double uEpsilon;
uniform double uTieFactor;
uniform double uDiagonal;
uniform double uFarSlack;
uniform double uFlip;
uniform double uRelativeTolerance;
uniform uint uWorkOffset;
uniform uint uWorkCount;
uniform uint uGlobalCount;
uniform int uHasCasters;
uniform uint uLoopProbe; // 2: see the end of main()
uniform uint uEmitting[ROWS]; // per row: the grid cells that hold light samples (a disc's)

// Per-invocation state (MaskBuilder's members).
uint facing[ROWS];
uint candidate[ROWS];
uint blocked[ROWS];
bool flagged;
bool open;
dvec3 P;
dvec3 sampleNormal;
double sampleZ;
int own;
double tieLimit;
double errPos;
double tnearF; // float(tnear), as a double
double reach;
dvec3 coneAxis;
double coneCos;
double coneSin;
bool coneValid;
uint necessary;
uint tests;

struct Affine
{
  double base;
  double di;
  double dj;
};

double at(Affine f, int i, int j)
{
  return f.base + double(i) * f.di + double(j) * f.dj;
}

Affine along(dvec3 g, double atCentre)
{
  double gu = dot(g, uAxisU);
  double gv = dot(g, uAxisV);
  return Affine(atCentre + uSu0 * gu + uSv0 * gv, uDSu * gu, uDSv * gv);
}

dvec3 lightPoint(int i, int j)
{
  int b = 3 * (j * K + i);
  return dvec3(lightPoints[b], lightPoints[b + 1], lightPoints[b + 2]);
}

dvec3 corner(int c)
{
  return lightPoint((c & 1) != 0 ? K - 1 : 0, (c & 2) != 0 ? ROWS - 1 : 0);
}

uint span(int lo, int hi)
{
  if (hi < lo)
  {
    return 0u;
  }
  int width = hi - lo + 1;
  uint ones = width >= 32 ? 0xFFFFFFFFu : ((1u << uint(width)) - 1u);
  return ones << uint(lo);
}

// The comparison float(x) > tnearF of the CPU path, decided only outside a band of a few
// float32 ulps (the CPU and this shader may round tnear one ulp apart); inside it the
// sample is flagged. Returns 1 (true), 0 (false) or -1 (flag).
int floatAboveTNear(double x)
{
  if (x >= tnearF * (1.0LF + 3e-7LF))
  {
    return 1;
  }
  if (x <= tnearF * (1.0LF - 3e-7LF))
  {
    return 0;
  }
  return -1;
}

// Narrows [lo, hi] to the columns i where base + i slope >= -delta (see Narrow()).
void narrow(double base, double slope, double delta, int k, bool widen, inout int lo, inout int hi)
{
  double bound = -delta - base;
  if (abs(slope) < 1e-300LF)
  {
    if (widen ? 0.0LF < bound : 0.0LF <= bound)
    {
      hi = -1;
    }
    return;
  }
  double x = bound / slope;
  double fuzz = (widen ? 1e-9LF : -1e-9LF) * (abs(x) + 1.0LF);
  if (slope > 0.0LF)
  {
    double c = ceil(x - fuzz);
    lo = max(lo, c < 0.0LF ? 0 : (c > double(k) ? k : int(c)));
  }
  else
  {
    double f = floor(x + fuzz);
    hi = min(hi, f < -1.0LF ? -1 : (f > double(k - 1) ? k - 1 : int(f)));
  }
}

// ColumnBound of the CPU path: kind 0 lower, 1 upper, 2 whole row.
struct Bound
{
  int kind;
  double x0;
  double stepJ;
  double base;
  double dj;
  double delta;
  bool widen;
};

Bound makeBound(Affine f, double delta, bool widen)
{
  Bound b = Bound(2, 0.0LF, 0.0LF, f.base, f.dj, delta, widen);
  if (abs(f.di) >= 1e-300LF)
  {
    b.kind = f.di > 0.0LF ? 0 : 1;
    b.x0 = (-delta - f.base) / f.di;
    b.stepJ = -f.dj / f.di;
  }
  return b;
}

void applyBound(Bound b, int j, inout int lo, inout int hi)
{
  if (b.kind == 2)
  {
    double bound = -b.delta - (b.base + double(j) * b.dj);
    if (b.widen ? 0.0LF < bound : 0.0LF <= bound)
    {
      hi = -1;
    }
    return;
  }
  double x = b.x0 + double(j) * b.stepJ;
  double fuzz = (b.widen ? 1e-9LF : -1e-9LF) * (abs(x) + 1.0LF);
  if (b.kind == 0)
  {
    double c = ceil(x - fuzz);
    lo = max(lo, c < 0.0LF ? 0 : (c > double(K) ? K : int(c)));
  }
  else
  {
    double f = floor(x + fuzz);
    hi = min(hi, f < -1.0LF ? -1 : (f > double(K - 1) ? K - 1 : int(f)));
  }
}

dvec3 casterVector(int base, int offset)
{
  return dvec3(casterData[base + offset], casterData[base + offset + 1], casterData[base + offset + 2]);
}

// SegmentTest(): 0 clear hit, 1 miss, 2 on an edge, 3 too close to call.
int segmentTest(dvec3 o, dvec3 d, double tmax, int cb)
{
  dvec3 n = casterVector(cb, 9);
  double cosine = dot(d, n);
  if (!(abs(cosine) > 1e-6LF))
  {
    return 3;
  }
  dvec3 v0 = casterVector(cb, 0);
  double height = n.x * (v0.x - o.x) + n.y * (v0.y - o.y) + n.z * (v0.z - o.z);
  double slack = errPos * (1.0LF + 1.0LF / abs(cosine));
  double t = height / cosine;
  if (t < tieLimit - slack || t > tmax + slack)
  {
    return 1;
  }
  bool clearT = t > tieLimit + slack && t < tmax - slack;
  dvec3 x = o + t * d;
  int near = 0;
  for (int e = 0; e < 3; ++e)
  {
    double distance = dot(casterVector(cb, 12 + 3 * e), x) - casterData[cb + 21 + e];
    if (distance < -slack)
    {
      return 1;
    }
    if (!(distance > slack))
    {
      ++near;
    }
  }
  if (!clearT || near > 1)
  {
    return 3;
  }
  return near == 0 ? 0 : 2;
}

// MaskBuilder::Start(): the light samples above the tangent plane and those the reference
// traces. Returns false when no light sample needs a triangle.
bool start()
{
  reach = 0.0LF;
  for (int c = 0; c < 4; ++c)
  {
    reach = max(reach, length(corner(c) - P));
  }
  coneAxis = uCentre - P;
  double axisLength = length(coneAxis);
  coneValid = axisLength > 0.0LF;
  if (coneValid)
  {
    coneAxis /= axisLength;
  }
  double cosCone = 1.0LF;
  for (int c = 0; c < 4 && coneValid; ++c)
  {
    dvec3 d = corner(c) - P;
    double len = length(d);
    coneValid = len > 0.0LF;
    if (coneValid)
    {
      cosCone = min(cosCone, dot(d / len, coneAxis));
    }
  }
  coneCos = cosCone;
  coneSin = sqrt(max(0.0LF, 1.0LF - cosCone * cosCone));
  coneValid = coneValid && cosCone > 0.0LF;

  Affine facingF = along(sampleNormal, dot(sampleNormal, uCentre) - dot(sampleNormal, P));
  double fuzz = 1e-12LF * reach * (1.0LF + length(sampleNormal));
  double plane = abs(dot(uAxisN, P) - dot(uAxisN, uCentre));
  bool allTraced = false;
  if (uHasCasters != 0)
  {
    int above = floatAboveTNear(plane * (1.0LF - uEpsilon) * (1.0LF - 1e-6LF));
    if (above < 0)
    {
      flagged = true;
      return false;
    }
    allTraced = above == 1;
  }
  double lowest = 1.0e300LF;
  for (int c = 0; c < 4; ++c)
  {
    lowest = min(lowest, at(facingF, (c & 1) != 0 ? K - 1 : 0, (c & 2) != 0 ? ROWS - 1 : 0));
  }
  if (allTraced && lowest > fuzz)
  {
    for (int j = 0; j < ROWS; ++j)
    {
      blocked[j] = 0u;
      facing[j] = uEmitting[j];
      candidate[j] = facing[j];
    }
    return true;
  }
  Bound sureFacing = makeBound(facingF, -fuzz, false);
  Bound maybeFacing = makeBound(facingF, fuzz, true);
  bool any = false;
  for (int j = 0; j < ROWS; ++j)
  {
    blocked[j] = 0u;
    int sureLo = 0, sureHi = K - 1, maybeLo = 0, maybeHi = K - 1;
    applyBound(sureFacing, j, sureLo, sureHi);
    applyBound(maybeFacing, j, maybeLo, maybeHi);
    uint sure = span(sureLo, sureHi) & uEmitting[j];
    facing[j] = sure;
    candidate[j] = allTraced ? sure : 0u;
    uint check = span(maybeLo, maybeHi) & uEmitting[j] & (allTraced ? ~sure : 0xFFFFFFFFu);
    if (allTraced && check != 0u)
    {
      // Light samples within rounding of the tangent plane: the CPU path evaluates the
      // reference's exact expression.
      flagged = true;
      return false;
    }
    while (check != 0u)
    {
      int i = findLSB(check);
      check &= check - 1u;
      dvec3 toLight = lightPoint(i, j) - P;
      double dist = length(toLight);
      double side = dot(sampleNormal, toLight);
      double band = 1e-13LF * length(sampleNormal) * dist;
      if (abs(side) <= band)
      {
        flagged = true;
        return false;
      }
      uint bit = 1u << uint(i);
      if (side < 0.0LF)
      {
        facing[j] &= ~bit;
        continue;
      }
      facing[j] |= bit;
      if (uHasCasters != 0 && dist > 0.0LF)
      {
        int above = floatAboveTNear(dist * (1.0LF - uEpsilon));
        if (above < 0)
        {
          flagged = true;
          return false;
        }
        if (above == 1)
        {
          candidate[j] |= bit;
        }
      }
    }
    any = any || candidate[j] != 0u;
  }
  return any;
}

// MaskBuilder::Visit()'s cone test: true when the caster's bounding sphere at `cb` lies
// outside the cone from P around the light.
bool outsideCone(int cb)
{
  if (coneValid)
  {
    dvec3 v = casterVector(cb, 25) - P;
    double distance = length(v);
    double radius = casterData[cb + 28] + 4.0LF * errPos;
    if (distance > radius)
    {
      double sinB = radius / distance;
      double cosB = sqrt(1.0LF - sinB * sinB);
      double cosA = dot(v, coneAxis) / distance;
      double cosSum = coneCos * cosB - coneSin * sinB;
      if (cosSum > 0.0LF && cosA < cosSum - 1e-12LF)
      {
        return true;
      }
    }
  }
  return false;
}

// MaskBuilder::Visit()'s caster plane: the plane's distance over the light (planeF), the side
// of P (sgn) and the tolerances of the edge and plane tests; false when the whole light lies
// on P's side of the plane, or the plane is too close to P to block.
bool casterPlane(int cb, out Affine planeF, out double sgn, out double deltaEdge,
  out double deltaPlane, out bool certainPossible, out double sureEdge, out double surePlane)
{
  dvec3 n = casterVector(cb, 9);
  dvec3 v0 = casterVector(cb, 0);
  double h = dot(n, P) - dot(n, v0);
  planeF = along(n, dot(n, uCentre) - dot(n, v0));
  sgn = h >= 0.0LF ? 1.0LF : -1.0LF;
  double dMax = reach;
  double sideMin = 1.0e300LF;
  double crossMin = 1.0e300LF;
  double crossMax = -crossMin;
  for (int c = 0; c < 4; ++c)
  {
    double dl = at(planeF, (c & 1) != 0 ? K - 1 : 0, (c & 2) != 0 ? ROWS - 1 : 0);
    sideMin = min(sideMin, sgn * dl);
    crossMin = min(crossMin, dl - h);
    crossMax = max(crossMax, dl - h);
  }
  double absH = abs(h);
  double err = errPos;
  double crossAbs = crossMin > 0.0LF ? crossMin : (crossMax < 0.0LF ? -crossMax : 0.0LF);
  double cosMin = max(absH, crossAbs) / dMax;
  if (absH > err && sideMin > 2.0LF * err)
  {
    return false;
  }
  if (absH + err < cosMin * (tieLimit - err))
  {
    return false;
  }
  deltaEdge = min(2.0LF * err * dMax / max(absH, 1e-300LF), 4.0LF * dMax);
  deltaPlane = 2.0LF * err;
  certainPossible = absH > tieLimit + 2.0LF * err && cosMin > 2e-6LF;
  sureEdge = deltaEdge + 1e-9LF * dMax;
  surePlane = uEpsilon * dMax + 2.0LF * err + 1e-9LF * dMax;
  return true;
}

// MaskBuilder::Visit()'s edge planes: the planes through P and the caster's edges, facing
// into the triangle's cone from P (none when P lies too close to the triangle's plane for
// the cone to be well-defined, `cone` false). Returns how many there are.
int edgePlanes(int cb, out bool cone, out Affine edges[3])
{
  int nEdges = 0;
  dvec3 a[3];
  for (int i = 0; i < 3; ++i)
  {
    a[i] = casterVector(cb, 3 * i) - P;
  }
  dvec3 cr[3];
  for (int e = 0; e < 3; ++e)
  {
    cr[e] = cross(a[e], a[(e + 1) % 3]);
  }
  double det = dot(cr[0], a[2]);
  double mag2 = dot(a[0], a[0]) * dot(a[1], a[1]) * dot(a[2], a[2]);
  cone = det * det > 1e-24LF * mag2;
  for (int e = 0; cone && e < 3; ++e)
  {
    double len = length(cr[e]);
    if (!(len > 0.0LF))
    {
      continue;
    }
    dvec3 m = (det > 0.0LF ? cr[e] : -cr[e]) / len;
    edges[nEdges++] = along(m, dot(m, uCentre) - dot(m, P));
  }
  return nEdges;
}

// MaskBuilder::Visit()'s rows jLo..jHi: the open candidate light samples between the loose
// bounds, blocked at once inside the sure ones (certainCone), else by the exact segment test.
// False when a test cannot decide (the sample is flagged for the CPU).
bool maskRows(int cb, int jLo, int jHi, Bound loose[4], int nLoose, bool certainCone,
  Bound sure[4], inout bool hitAny)
{
  for (int j = jLo; j <= jHi; ++j)
  {
    uint openBits = candidate[j] & ~blocked[j];
    if (openBits == 0u)
    {
      continue;
    }
    int lo = 0, hi = K - 1;
    for (int c = 0; c < nLoose && lo <= hi; ++c)
    {
      applyBound(loose[c], j, lo, hi);
    }
    uint maybe = openBits & span(lo, hi);
    if (maybe == 0u)
    {
      continue;
    }
    if (certainCone)
    {
      int sLo = 0, sHi = K - 1;
      for (int c = 0; c < 4 && sLo <= sHi; ++c)
      {
        applyBound(sure[c], j, sLo, sHi);
      }
      uint certain = maybe & span(sLo, sHi);
      if (certain != 0u)
      {
        blocked[j] |= certain;
        maybe &= ~certain;
        hitAny = true;
      }
    }
    while (maybe != 0u)
    {
      int i = findLSB(maybe);
      maybe &= maybe - 1u;
      dvec3 d = lightPoint(i, j) - P;
      double dist = length(d);
      d /= dist;
      ++tests;
      int hit = segmentTest(P, d, dist * (1.0LF - uEpsilon), cb);
      if (hit == 0)
      {
        blocked[j] |= 1u << uint(i);
        hitAny = true;
      }
      else if (hit != 1)
      {
        // On an edge (the CPU path pairs it with the neighbour sharing the edge) or too
        // close to call (the CPU path asks Embree): the CPU redoes the whole sample.
        flagged = true;
        return false;
      }
    }
  }
  return true;
}

// MaskBuilder::Visit(): one potential blocker.
void visit(uint index)
{
  if (zNear[index] > sampleZ + uFarSlack)
  {
    return;
  }
  int cb = int(index) * STRIDE;
  if (outsideCone(cb))
  {
    return;
  }
  if (own >= 0 && int(casterData[cb + 24]) == own) // penumbra_rules::IsOwnCaster
  {
    return;
  }
  Affine planeF;
  double sgn, deltaEdge, deltaPlane, sureEdge, surePlane;
  bool certainPossible;
  if (!casterPlane(
        cb, planeF, sgn, deltaEdge, deltaPlane, certainPossible, sureEdge, surePlane))
  {
    return;
  }

  Affine edges[3];
  bool cone;
  int nEdges = edgePlanes(cb, cone, edges);
  bool certainCone = certainPossible && cone && nEdges == 3;

  Affine beyond = Affine(-sgn * planeF.base, -sgn * planeF.di, -sgn * planeF.dj);
  int jLo = 0, jHi = ROWS - 1;
  narrow(beyond.base + max(0.0LF, double(K - 1) * beyond.di), beyond.dj, deltaPlane, ROWS, true,
    jLo, jHi);
  for (int e = 0; e < nEdges && jLo <= jHi; ++e)
  {
    narrow(edges[e].base + max(0.0LF, double(K - 1) * edges[e].di), edges[e].dj, deltaEdge, ROWS,
      true, jLo, jHi);
  }
  if (jLo > jHi)
  {
    return;
  }
  Bound loose[4];
  int nLoose = 1 + nEdges;
  loose[0] = makeBound(beyond, deltaPlane, true);
  for (int e = 0; e < nEdges; ++e)
  {
    loose[e + 1] = makeBound(edges[e], deltaEdge, true);
  }
  Bound sure[4];
  if (certainCone)
  {
    sure[0] = makeBound(beyond, -surePlane, false);
    for (int e = 0; e < 3; ++e)
    {
      sure[e + 1] = makeBound(edges[e], -sureEdge, false);
    }
  }
  bool hitAny = false;
  if (!maskRows(cb, jLo, jHi, loose, nLoose, certainCone, sure, hitAny))
  {
    return;
  }
  if (hitAny)
  {
    ++necessary;
    bool anyOpen = false;
    for (int j = 0; j < ROWS && !anyOpen; ++j)
    {
      anyOpen = (candidate[j] & ~blocked[j]) != 0u;
    }
    open = anyOpen;
  }
}

void main()
{
  uint o = uWorkOffset + gl_GlobalInvocationID.x;
  if (o >= uWorkCount)
  {
    return;
  }
  uint s = work[2u * o];
  uint cell = work[2u * o + 1u];
  // loadSample() of the CPU path.
  P = dvec3(double(positions[3u * s]), double(positions[3u * s + 1u]),
        double(positions[3u * s + 2u])) + uShift;
  sampleNormal = dvec3(double(normals[3u * s]), double(normals[3u * s + 1u]),
    double(normals[3u * s + 2u]));
  double scale = max(length(P), uDiagonal);
  own = owners[uint(GEARS_OWNER_STRIDE) * s];
  tnearF = double(float(uEpsilon * scale));
  tieLimit = double(float(uTieFactor * uEpsilon * scale));
  errPos = uRelativeTolerance * scale;
  sampleZ = max(uFlip * dot(uAxisN, P - uCentre), 0.0LF);
  flagged = false;
  necessary = 0u;
  tests = 0u;

  open = start();
  if (open && !flagged)
  {
    uint first = cellStart[cell];
    uint last = cellStart[cell + 1u];
    for (uint e = first; e < last && open && !flagged; ++e)
    {
      visit(cellList[e]);
    }
    for (uint e = 0u; e < uGlobalCount && open && !flagged; ++e)
    {
      visit(globalList[e]);
    }
  }
  // Mesa llvmpipe silently ends every loop once the loops of one invocation group have run
  // 65535 iterations in all (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS), which would drop
  // blockers. After that point every loop runs once: a loop of uLoopProbe (2) iterations
  // that runs once says so, and the sample goes to the CPU path.
  uint probe = 0u;
  for (uint q = 0u; q < uLoopProbe; ++q)
  {
    ++probe;
  }
  if (probe != uLoopProbe)
  {
    flagged = true;
  }
  uint lit = 0u;
  for (int j = 0; j < ROWS; ++j)
  {
    facing[j] &= ~blocked[j];
    lit += uint(bitCount(facing[j]));
#if GEARS_KEEP_MASKS
    masks[o * uint(ROWS) + uint(j)] = facing[j];
#endif
  }
  results[3u * o] = flagged ? FLAGGED : lit;
  results[3u * o + 1u] = necessary;
  results[3u * o + 2u] = tests;
}
