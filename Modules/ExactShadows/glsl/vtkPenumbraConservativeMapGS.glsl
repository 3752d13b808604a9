//VTK::System::Dec
// Conservative shadow map, geometry stage (Hertel, Hormann, Westermann, "A Hybrid GPU Rendering
// Pipeline for Alias-Free Hard Shadows", Eurographics 2009 Areas Papers, §4.1, with these fixes):
// 1. clip the triangle in homogeneous space to the view's frustum sides (slightly widened),
//    so projected coordinates stay small and exact enough for the distance test;
// 2. perspective views: a triangle reaching the tip region w < nearW (close to the light)
//    cannot be projected safely; it is emitted as a full-map quad at depth 0, which is
//    conservative (the classifier then tests it exactly or traces the sample);
// 3. otherwise the clipped polygon is enlarged to T' (edges moved outward by the texel
//    diagonal l), cut to its bounding box grown by l (the spikes at acute vertices); an
//    ill-conditioned T' falls back to that box.
// The fragment stage keeps exactly the texels whose centre lies within keepRadius of the
// polygon (true point-to-segment distance, which corrects the paper's edge/vertex rule) and writes
// its conservative depth (§4.1).
layout(triangles) in;
layout(triangle_strip, max_vertices = 12) out;

in vec4 clipVS[];

uniform vec2 mapSize;       // texels per side
uniform int perspective;    // 1: w = distance along the view axis; 0: z = linear depth
uniform float nearW;        // perspective only: the tip region w < nearW is unsafe
uniform float frustumSlack; // side planes |x|, |y| <= frustumSlack * w

flat out uint gId;
flat out int gCount;
flat out vec2 gPoly[9];     // the (clipped) triangle in map texel units
flat out vec4 gPlane;       // depth quantity at gPoly[0], d/dx, d/dy per texel, 1 if usable
flat out vec2 gBound;       // vertex extreme of the depth quantity, tolerance of the plane
flat out int gNear;

// Outputs are undefined after EmitVertex(), so every vertex sets all of them from these.
uint sId;
int sCount;
vec2 sPoly[9];
vec4 sPlane;
vec2 sBound;
int sNear;

void emitAt(vec2 texel)
{
  gId = sId;
  gCount = sCount;
  for (int i = 0; i < 9; ++i)
  {
    gPoly[i] = sPoly[i];
  }
  gPlane = sPlane;
  gBound = sBound;
  gNear = sNear;
  gl_Position = vec4(texel / mapSize * 2.0 - 1.0, 0.0, 1.0);
  EmitVertex();
}

// Clips the convex polygon p[0..n) against the half space dot(plane, v) >= 0.
int clipPolygon(inout vec4 p[12], int n, vec4 plane)
{
  vec4 outp[12];
  int m = 0;
  for (int i = 0; i < n; ++i)
  {
    vec4 a = p[i];
    vec4 b = p[(i + 1) % n];
    float da = dot(plane, a);
    float db = dot(plane, b);
    if (da >= 0.0 && m < 12)
    {
      outp[m++] = a;
    }
    if ((da >= 0.0) != (db >= 0.0) && m < 12)
    {
      outp[m++] = mix(a, b, da / (da - db));
    }
  }
  for (int i = 0; i < m; ++i)
  {
    p[i] = outp[i];
  }
  return m;
}

// Step 1: the input triangle into `poly`, clipped to the view's side planes; returns its vertex
// count (below 3: nothing left to draw).
int clipToSides(out vec4 poly[12])
{
  for (int i = 0; i < 3; ++i)
  {
    poly[i] = clipVS[i];
  }
  // Trivial reject (all vertices outside one side plane; most triangles for a cube face)
  // and trivial accept before the general clipper: llvmpipe runs this stage per primitive.
  vec4 side[4] = vec4[4](vec4(-1.0, 0.0, 0.0, frustumSlack), vec4(1.0, 0.0, 0.0, frustumSlack),
    vec4(0.0, -1.0, 0.0, frustumSlack), vec4(0.0, 1.0, 0.0, frustumSlack));
  bool allInside = true;
  for (int k = 0; k < 4; ++k)
  {
    vec3 d = vec3(dot(side[k], clipVS[0]), dot(side[k], clipVS[1]), dot(side[k], clipVS[2]));
    if (all(lessThan(d, vec3(0.0))))
    {
      return 0;
    }
    allInside = allInside && all(greaterThanEqual(d, vec3(0.0)));
  }
  int n = 3;
  if (!allInside)
  {
    for (int k = 0; k < 4; ++k)
    {
      n = clipPolygon(poly, n, side[k]);
    }
  }
  return n;
}

// Step 2 (perspective views): a polygon reaching the tip region is drawn as a full-map quad at
// depth 0; true when it was.
bool emitTipQuad(vec4 poly[12], int n)
{
  bool tip = false;
  for (int i = 0; i < n; ++i)
  {
    tip = tip || poly[i].w < nearW;
  }
  if (tip)
  {
    sNear = 1;
    sCount = 0;
    sPlane = vec4(0.0);
    for (int i = 0; i < 9; ++i)
    {
      sPoly[i] = vec2(0.0);
    }
    sBound = vec2(0.0);
    emitAt(vec2(-2.0, -2.0));
    emitAt(vec2(mapSize.x + 2.0, -2.0));
    emitAt(vec2(-2.0, mapSize.y + 2.0));
    emitAt(vec2(mapSize.x + 2.0, mapSize.y + 2.0));
    EndPrimitive();
  }
  return tip;
}

// Texel coordinates and the depth quantity, which is affine in texel space: the linear
// depth z for orthographic views, q = 1 / w for perspective ones.
void projectToMap(vec4 poly[12], int n, out vec2 t[9], out float q[9], out float qmin,
  out float qmax)
{
  qmin = 1e30;
  qmax = -1e30;
  for (int i = 0; i < n; ++i)
  {
    t[i] = (poly[i].xy / poly[i].w * 0.5 + 0.5) * mapSize;
    q[i] = perspective == 1 ? 1.0 / poly[i].w : poly[i].z;
    qmin = min(qmin, q[i]);
    qmax = max(qmax, q[i]);
  }
  for (int i = 0; i < 9; ++i)
  {
    sPoly[i] = i < n ? t[i] : t[0];
  }
  sCount = n;
}

// Depth plane from the best-shaped fan triangle; only trusted when well conditioned, the
// vertex extreme alone is always conservative (Hertel et al. 2009, §4.1).
void fitDepthPlane(vec2 t[9], float q[9], int n, float qmin, float qmax)
{
  int best = 1;
  float bestArea = 0.0;
  for (int i = 1; i + 1 < n; ++i)
  {
    vec2 e1 = t[i] - t[0];
    vec2 e2 = t[i + 1] - t[0];
    float a = abs(e1.x * e2.y - e1.y * e2.x);
    if (a > bestArea)
    {
      bestArea = a;
      best = i;
    }
  }
  sPlane = vec4(q[0], 0.0, 0.0, 0.0);
  {
    vec2 e1 = t[best] - t[0];
    vec2 e2 = t[best + 1] - t[0];
    float det = e1.x * e2.y - e1.y * e2.x;
    float longest = max(length(e1), max(length(e2), length(t[best + 1] - t[best])));
    if (longest > 0.0 && abs(det) / longest >= 1.0)
    {
      float d1 = q[best] - q[0];
      float d2 = q[best + 1] - q[0];
      sPlane = vec4(q[0], (d1 * e2.y - d2 * e1.y) / det, (d2 * e1.x - d1 * e2.x) / det, 1.0);
    }
  }
  sBound = vec2(perspective == 1 ? qmax : qmin,
    0.02 * (qmax - qmin) + 1e-6 * max(abs(qmax), abs(qmin)));
}

// Box: the polygon's bounds grown by the texel diagonal `l`, cut to the map plus a margin;
// false when nothing of it is left.
bool growBox(vec2 t[9], int n, float l, out vec2 lo, out vec2 hi)
{
  lo = t[0];
  hi = t[0];
  for (int i = 1; i < n; ++i)
  {
    lo = min(lo, t[i]);
    hi = max(hi, t[i]);
  }
  lo = max(lo - vec2(l), vec2(-2.0));
  hi = min(hi + vec2(l), mapSize + vec2(2.0));
  return !(lo.x >= hi.x || lo.y >= hi.y);
}

// Step 3: T' of Hertel et al. 2009, §4.1, for the (possibly clipped, always convex) polygon:
// vertex i is where the lines of edges i-1 and i, each moved out by l, meet. Nearly parallel
// neighbouring edges (spikes, duplicate clip vertices) fall back to the box: false then.
bool enlarge(vec2 t[9], int n, float l, out vec4 tp[12])
{
  float area = 0.0;
  for (int i = 0; i < n; ++i)
  {
    vec2 a = t[i];
    vec2 b = t[(i + 1) % n];
    area += a.x * b.y - a.y * b.x;
  }
  float s = area > 0.0 ? 1.0 : -1.0;
  vec2 nrm[9];
  float c[9];
  bool ok = area != 0.0;
  for (int i = 0; i < n; ++i)
  {
    vec2 e = t[(i + 1) % n] - t[i];
    float len = length(e);
    ok = ok && len > 0.0;
    nrm[i] = len > 0.0 ? s * vec2(e.y, -e.x) / len : vec2(0.0);
    c[i] = dot(nrm[i], t[i]) + l;
  }
  for (int i = 0; i < n && ok; ++i)
  {
    int h = (i + n - 1) % n;
    vec2 na = nrm[h];
    vec2 nb = nrm[i];
    float d = na.x * nb.y - na.y * nb.x;
    ok = abs(d) > 1e-3;
    vec2 v = ok ? vec2(c[h] * nb.y - c[i] * na.y, na.x * c[i] - nb.x * c[h]) / d : vec2(0.0);
    ok = ok && all(lessThan(abs(v), vec2(1e6)));
    tp[i] = vec4(v, 0.0, 1.0);
  }
  return ok;
}

// T' cut to the grown box (the spikes at acute vertices, which the paper accepts), drawn as
// a strip.
void emitCut(vec4 tp[12], int n, vec2 lo, vec2 hi)
{
  int m = n;
  m = clipPolygon(tp, m, vec4(1.0, 0.0, 0.0, -lo.x));
  m = clipPolygon(tp, m, vec4(-1.0, 0.0, 0.0, hi.x));
  m = clipPolygon(tp, m, vec4(0.0, 1.0, 0.0, -lo.y));
  m = clipPolygon(tp, m, vec4(0.0, -1.0, 0.0, hi.y));
  if (m < 3)
  {
    return;
  }
  // Convex polygon as a strip: 0, 1, m-1, 2, m-2, ...
  int a = 1;
  int b = m - 1;
  emitAt(tp[0].xy);
  for (int k = 1; k < m; ++k)
  {
    if ((k & 1) == 1)
    {
      emitAt(tp[a].xy);
      ++a;
    }
    else
    {
      emitAt(tp[b].xy);
      --b;
    }
  }
  EndPrimitive();
}

void main()
{
  vec4 poly[12];
  int n = clipToSides(poly);
  if (n < 3)
  {
    return;
  }
  // The primitive's index in the draw; the CPU turns it into the caster's triangle id.
  sId = uint(gl_PrimitiveIDIn);
  if (perspective == 1 && emitTipQuad(poly, n))
  {
    return;
  }
  sNear = 0;

  vec2 t[9];
  float q[9];
  float qmin;
  float qmax;
  projectToMap(poly, n, t, q, qmin, qmax);
  fitDepthPlane(t, q, n, qmin, qmax);

  float l = length(vec2(1.0));
  vec2 lo;
  vec2 hi;
  if (!growBox(t, n, l, lo, hi))
  {
    return;
  }

  vec4 tp[12];
  if (enlarge(t, n, l, tp))
  {
    emitCut(tp, n, lo, hi);
    return;
  }
  emitAt(lo);
  emitAt(vec2(hi.x, lo.y));
  emitAt(vec2(lo.x, hi.y));
  emitAt(hi);
  EndPrimitive();
}
