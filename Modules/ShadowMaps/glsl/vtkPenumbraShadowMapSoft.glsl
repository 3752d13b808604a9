// Soft shadows of area and linear lights from one perspective map at the light's centre,
// shared by `pcss` (Fernando, "Percentage-Closer Soft Shadows", NVIDIA 2005) and
// `single-sample-soft` (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, ch. 11). Substituted into vtkPenumbraShadowMapCompare.glsl
// after its uniforms. areaMode is compiled as a constant (LookupVariant).
uniform int areaMode;        // 0 hard light, 1 PCSS, 2 single-sample soft
uniform vec3 lightU;         // half the light's extent along U (world)
uniform vec3 lightV;         // half along V (zero for a linear light)
uniform int searchTaps;      // PCSS: blocker-search taps per light axis (2 n on a segment);
                             // SSS: box taps per half side
uniform int filterTaps;      // PCF taps per light axis (2 n on a segment)
uniform float searchDepth;   // nearest blocker assumed at this fraction of the receiver's w
uniform float maxRadius;     // taps at most this far from the sample, in NDC
uniform int physical;        // SSS: 1 penumbra from the light's size, 0 the thesis's radii
uniform vec3 thesisRadius;   // SSS thesis mode: r_scale (texels / length), r_bias (texels),
                             // r_shrink (1 / length)
// SSS adaptive sampling (Brabec 2003, ch. 11.3): pass 1 searches at the corners of
// adaptiveBlock x adaptiveBlock pixel blocks, pass 2 interpolates the corners bilinearly
// where all four lie on the sample's prop and agree with its hard test, else searches.
uniform int adaptivePass;       // 0 off, 1 block corners, 2 interpolate or search
uniform int adaptiveBlock;      // pixels per block side
uniform ivec2 adaptiveImage;    // the G-buffer's size in pixels
uniform sampler2D coarseValues; // pass 2: per corner (value, prop, blocked, searched)
ivec2 penumbraPixel;            // set by the frame program: the pixel being looked up
float penumbraProp;             // and its prop
vec4 penumbraCorner = vec4(0.0); // pass 1's output for the pixel (w = 1: searched)

// The fraction of (a, b) in [-1, 1]^2 (b = 0 when beta is 0) with h0 + a alpha + b beta > 0:
// the part of a rectangle (or segment) on the positive side of a plane, in closed form (the
// sum of two uniform variables has a trapezoidal distribution). One function for the
// horizon term and for the straight-edge penumbra of the single-sample search.
float penumbraRamp(float x)
{
  return x > 0.0 ? 0.5 * x * x : 0.0;
}

float penumbraFractionAbove(float h0, float alpha, float beta)
{
  float a = abs(alpha);
  float b = abs(beta);
  if (a < b)
  {
    float t = a;
    a = b;
    b = t;
  }
  if (h0 >= a + b)
  {
    return 1.0;
  }
  if (h0 <= -(a + b))
  {
    return 0.0;
  }
  if (b <= 1e-6 * a)
  {
    return clamp(0.5 + 0.5 * h0 / a, 0.0, 1.0); // a segment (or a rectangle seen edge-on)
  }
  // P(a u + b v > -h0) = 1 - P(a u + b v <= -h0), inclusion-exclusion over the square.
  float t = -h0;
  float below = penumbraRamp(t + a + b) - penumbraRamp(t + a - b) - penumbraRamp(t - a + b) +
    penumbraRamp(t - a - b);
  return clamp(1.0 - below / (4.0 * a * b), 0.0, 1.0);
}

// The part of the light strictly above the receiver's tangent plane: the reference counts
// light points on or below it as occluded, so even a receiver without casters sees only
// that fraction.
float penumbraHorizon(vec3 p, vec3 n)
{
  return penumbraFractionAbove(dot(n, lightPosition - p), dot(n, lightU), dot(n, lightV));
}

// Receiver-plane depth: the linear depth (w) of the sample's tangent plane along the map ray
// through st, from 1 / w affine in the map coordinates over a plane. `plane` holds the
// gradient (xy) and offset (z) of 1 / w; zero or negative where the ray misses the plane.
vec3 penumbraReceiverPlane(vec3 p, vec3 n)
{
  // Rows 0, 1 and 3 of the view: c = (s w, t w, w) = L x + o.
  mat3 lt = mat3(vec3(lightMatrix[0][0], lightMatrix[1][0], lightMatrix[2][0]),
    vec3(lightMatrix[0][1], lightMatrix[1][1], lightMatrix[2][1]),
    vec3(lightMatrix[0][3], lightMatrix[1][3], lightMatrix[2][3]));
  vec3 a = inverse(lt) * n; // n . x = a . (c - o)
  vec4 clip = lightMatrix * vec4(p, 1.0);
  float k = dot(a, clip.xyw);
  return abs(k) > 0.0 ? a / k : vec3(0.0, 0.0, 1.0 / clip.w);
}

// The compare threshold of a tap at st: blockers must lie in front of the receiver and of
// its tangent plane there (a receiver-plane depth bias: a tilted receiver never shadows
// itself, a steep one needs no slope bias growing with the tap's distance); `bias` is the
// constant bias plus a texel's slope-free rounding margin.
float penumbraTapThreshold(vec2 uv, vec3 plane, float threshold, float bias)
{
  // The map holds depths at texel centres: compare with the plane there (uv in [0, 1]).
  vec2 st = (floor(uv * mapSize) + 0.5) / mapSize * 2.0 - 1.0;
  float inverseW = dot(plane, vec3(st, 1.0));
  return inverseW > 0.0 ? min(threshold, invFar / inverseW - bias) : threshold;
}

// Where a blocker at light-view depth wb (along the axis) hides light point centre + off
// from a receiver at depth w: st + xy(off) (1 / wb - 1 / w), xy(off) the off vector through
// the map's rows (similar triangles; exact for off in the light's plane).
vec2 penumbraTap(vec2 st, vec2 offset)
{
  float len = length(offset);
  offset *= len > maxRadius ? maxRadius / len : 1.0;
  return clamp((st + offset) * 0.5 + 0.5, 0.5 / mapSize, 1.0 - 0.5 / mapSize);
}

// Light point (a, b) in [-1, 1]^2 of tap (i, j): the centre of its cell in a columns x rows
// grid (one row: b = 0, a linear light).
vec2 penumbraGridPoint(int i, int j, int columns, int rows)
{
  return vec2((float(i) + 0.5) / float(columns), (float(j) + 0.5) / float(rows)) * 2.0 - 1.0;
}

// Pass 2 of the adaptive sampling: the bilinear interpolation of the pixel's block corners
// when all four were searched, lie on the pixel's prop and share its hard test (the
// thesis's ID and hard-shadow test; a corner off the image is clamped to its last pixel).
bool penumbraInterpolate(bool blocked, out float value)
{
  ivec2 block = penumbraPixel / adaptiveBlock;
  ivec2 last = textureSize(coarseValues, 0) - 1;
  float c[4];
  for (int k = 0; k < 4; ++k)
  {
    vec4 corner = texelFetch(coarseValues, min(block + ivec2(k & 1, k >> 1), last), 0);
    if (corner.w < 0.5 || corner.y != penumbraProp || (corner.z > 0.5) != blocked)
    {
      return false;
    }
    c[k] = corner.x;
  }
  vec2 p0 = vec2(block * adaptiveBlock);
  vec2 p1 = vec2(min((block + 1) * adaptiveBlock, adaptiveImage - 1));
  vec2 t = clamp((vec2(penumbraPixel) - p0) / max(p1 - p0, vec2(1.0)), 0.0, 1.0);
  value = mix(mix(c[0], c[1], t.x), mix(c[2], c[3], t.x), t.y);
  return true;
}

// PCSS over the light's taps above the receiver's tangent plane: a stratified grid of light
// points (cell centres); the visible fraction is the horizon term times the share of the
// taps above the plane that the map leaves lit.
float penumbraPcssTaps(vec2 st, float w, float threshold, float bias, vec3 plane, vec3 n, vec3 p);

// PCSS with the adaptive sampling of vtkPenumbraShadowMapShadows (block corners first, then
// bilinear interpolation where they agree; the hard test is the sample's own texel).
float penumbraPcss(vec2 st, float w, float threshold, float bias, vec3 plane, vec3 n, vec3 p)
{
  float value;
  bool blocked = false;
  if (adaptivePass != 0)
  {
    vec2 uv = st * 0.5 + 0.5;
    blocked = texture(depthMap, uv).r < penumbraTapThreshold(uv, plane, threshold, bias);
    if (adaptivePass == 2 && penumbraInterpolate(blocked, value))
    {
      return value;
    }
  }
  value = penumbraPcssTaps(st, w, threshold, bias, plane, n, p);
  penumbraCorner = vec4(value, penumbraProp, blocked ? 1.0 : 0.0, 1.0);
  return value;
}

float penumbraPcssTaps(vec2 st, float w, float threshold, float bias, vec3 plane, vec3 n, vec3 p)
{
  vec2 du = (lightMatrix * vec4(lightU, 0.0)).xy;
  vec2 dv = (lightMatrix * vec4(lightV, 0.0)).xy;
  bool line = dot(lightV, lightV) == 0.0;
  float h0 = dot(n, lightPosition - p);
  float alpha = dot(n, lightU);
  float beta = dot(n, lightV);
  float horizon = penumbraFractionAbove(h0, alpha, beta);
  // 1. Blocker search over the region the light subtends, on a stratified grid of light
  //    points (cell centres), with blockers down to searchDepth * w.
  float reach = 1.0 / (searchDepth * w) - 1.0 / w;
  // A segment gets twice the taps per axis: its one axis carries the whole penumbra.
  int columns = line ? 2 * searchTaps : searchTaps;
  int rows = line ? 1 : searchTaps;
  float sum = 0.0;
  float found = 0.0;
  for (int j = 0; j < rows; ++j)
  {
    for (int i = 0; i < columns; ++i)
    {
      vec2 ab = penumbraGridPoint(i, j, columns, rows);
      vec2 t = penumbraTap(st, (ab.x * du + ab.y * dv) * reach);
      float d = texture(depthMap, t).r;
      if (d < penumbraTapThreshold(t, plane, threshold, bias))
      {
        sum += d;
        found += 1.0;
      }
    }
  }
  if (found == 0.0)
  {
    return horizon; // early out: nothing between the light and the receiver
  }
  if (found == float(rows * columns))
  {
    return 0.0; // early out: the whole search region is blocked (the filter region is inside it)
  }
  // 2. Penumbra from the average blocker depth; 3. PCF over the light's image at that depth,
  //    counting only light points above the tangent plane.
  float wb = max(1e-6, (sum / found) / invFar);
  float scale = max(0.0, 1.0 / wb - 1.0 / w);
  columns = line ? 2 * filterTaps : filterTaps;
  rows = line ? 1 : filterTaps;
  float lit = 0.0;
  float above = 0.0;
  float total = 0.0;
  for (int j = 0; j < rows; ++j)
  {
    for (int i = 0; i < columns; ++i)
    {
      vec2 ab = penumbraGridPoint(i, j, columns, rows);
      vec2 t = penumbraTap(st, (ab.x * du + ab.y * dv) * scale);
      float l = penumbraLitAt(t, penumbraTapThreshold(t, plane, threshold, bias));
      float up = h0 + dot(ab, vec2(alpha, beta)) > 0.0 ? 1.0 : 0.0;
      lit += l * up;
      above += up;
      total += l;
    }
  }
  return horizon * (above > 0.0 ? lit / above : total / float(rows * columns));
}

// Single-sample soft shadows (Brabec 2003, ch. 11, Fig. 11.6): a sample the map leaves lit
// searches a box around it for the nearest blocker (outer penumbra, from 1 down to 0.5), a
// shadowed one for the nearest lit texel (inner penumbra, from 0 up to 0.5). The thesis's
// object IDs are replaced by the receiver-plane threshold: a texel counts as a blocker only
// in front of the receiver's tangent plane, which rejects the receiver's own surface (the
// tilted receiver of Fig. 11.5) and a convex object's other faces, and keeps the
// self-penumbrae the IDs lose.
//
// The box is scanned on a grid of at most (2 searchTaps + 1)^2 texels (every texel while it
// is narrower, the thesis's linear AABB scan); the best candidate is then refined to
// subpixel accuracy (the thesis's §11.3): a bisection along the direction to it finds the
// edge, a second bisection 20 degrees off finds a second edge point, and the distance r is
// taken perpendicular to the edge line through both.
//
// Physical mode: the edge hides the light points o with e . xy(o) (1 / d - 1 / w) > r (e
// the edge's normal in the map, d the blocker's depth at the edge): the visible fraction is
// penumbraFractionAbove(+-r / s, e . du, e . dv), s = 1 / d - 1 / w, exact for a straight
// edge. Thesis mode: f = 0.5 (1 +- r / r_max') with r_max = r_scale w + r_bias texels and
// r_max' = r_max r_shrink (w - d).

// True when the map at continuous texel position `pos` is in the other state than the
// sample (inner: lit, outer: blocked); `depth` receives its stored depth.
bool penumbraOpposite(vec2 pos, bool inner, vec3 plane, float threshold, float bias,
  out float depth)
{
  ivec2 texel = clamp(ivec2(floor(pos)), ivec2(0), ivec2(mapSize) - 1);
  depth = texelFetch(depthMap, texel, 0).r;
  bool blocked = depth < penumbraTapThreshold((vec2(texel) + 0.5) / mapSize, plane, threshold, bias);
  return blocked != inner;
}

// Bisection on [0, hi] along unit e from f (the sample's state at 0, the other at hi): the
// distance to the state change, to a quarter texel; `depth` the stored depth just past it.
float penumbraEdge(vec2 f, vec2 e, float hi, bool inner, vec3 plane, float threshold,
  float bias, inout float depth)
{
  float lo = 0.0;
  for (int k = 0; k < 16 && hi - lo > 0.25; ++k)
  {
    float mid = 0.5 * (lo + hi);
    float d;
    if (penumbraOpposite(f + e * mid, inner, plane, threshold, bias, d))
    {
      hi = mid;
      depth = d;
    }
    else
    {
      lo = mid;
    }
  }
  return 0.5 * (lo + hi);
}

float penumbraSearch(vec2 f, bool inner, float dc, float w, float threshold, float bias,
  vec3 plane);

float penumbraSingleSample(vec2 st, float w, float threshold, float bias, vec3 plane)
{
  vec2 f = (st * 0.5 + 0.5) * mapSize; // continuous texel position (subpixel accuracy)
  float dc;
  bool inner = penumbraOpposite(f, false, plane, threshold, bias, dc); // blocked
  float value;
  if (adaptivePass == 2 && penumbraInterpolate(inner, value))
  {
    return value;
  }
  value = penumbraSearch(f, inner, dc, w, threshold, bias, plane);
  penumbraCorner = vec4(value, penumbraProp, inner ? 1.0 : 0.0, 1.0);
  return value;
}

// The search of one sample at continuous texel position f, blocked (inner) or not, dc the
// depth stored at its texel.
float penumbraSearch(vec2 f, bool inner, float dc, float w, float threshold, float bias,
  vec3 plane)
{
  vec2 du = (lightMatrix * vec4(lightU, 0.0)).xy;
  vec2 dv = (lightMatrix * vec4(lightV, 0.0)).xy;
  float texelsPerNdc = 0.5 * min(mapSize.x, mapSize.y);
  float wc = max(1e-6, dc / invFar);
  // Search reach in texels.
  float reach;
  if (physical != 0)
  {
    float s = inner ? 1.0 / wc - 1.0 / w : 1.0 / (searchDepth * w) - 1.0 / w;
    reach = (length(du) + length(dv)) * max(0.0, s) * texelsPerNdc;
  }
  else
  {
    reach = thesisRadius.x * w + thesisRadius.y;
  }
  reach = min(reach, maxRadius * texelsPerNdc);
  if (reach < 0.5)
  {
    return inner ? 0.0 : 1.0; // a point-like light: the hard shadow
  }
  // 1. Coarse scan: the candidate whose penumbra it is deepest inside.
  int n = min(searchTaps, int(ceil(reach)));
  float step = reach / float(n);
  float best = 1e30;
  vec2 bestOffset = vec2(0.0);
  for (int j = -n; j <= n; ++j)
  {
    for (int i = -n; i <= n; ++i)
    {
      vec2 offset = floor(f + vec2(i, j) * step) + 0.5 - f;
      float r = length(offset);
      float d;
      if (r > reach + 0.5 || !penumbraOpposite(f + offset, inner, plane, threshold, bias, d))
      {
        continue;
      }
      float s = inner ? 1.0 / wc - 1.0 / w : 1.0 / max(1e-6, d / invFar) - 1.0 / w;
      vec2 e = r > 0.0 ? offset / r : vec2(1.0, 0.0);
      float q = physical != 0
        ? r / max(1e-12, s * (abs(dot(e, du)) + abs(dot(e, dv))) * texelsPerNdc)
        : r / max(1e-6, reach * thesisRadius.z * (w - (inner ? wc : d / invFar)));
      if (s > 0.0 && q < best)
      {
        best = q;
        bestOffset = offset;
      }
    }
  }
  if (best >= 1e30)
  {
    return inner ? 0.0 : 1.0; // nothing in reach: umbra or fully lit
  }
  // 2. Refinement: two edge points by bisection, the distance perpendicular to their line.
  float r1 = length(bestOffset);
  vec2 e1 = r1 > 0.0 ? bestOffset / r1 : vec2(1.0, 0.0);
  float d1 = dc;
  float depth = dc;
  penumbraOpposite(f + bestOffset, inner, plane, threshold, bias, d1);
  float edge1 = penumbraEdge(f, e1, r1, inner, plane, threshold, bias, d1);
  vec2 normal = e1;
  float r = edge1;
  for (int side = -1; side <= 1; side += 2)
  {
    float angle = 0.35 * float(side);
    vec2 e2 = vec2(cos(angle) * e1.x - sin(angle) * e1.y, sin(angle) * e1.x + cos(angle) * e1.y);
    float far2 = 3.0 * max(edge1, 1.0);
    if (penumbraOpposite(f + e2 * far2, inner, plane, threshold, bias, depth))
    {
      float edge2 = penumbraEdge(f, e2, far2, inner, plane, threshold, bias, depth);
      vec2 along = e2 * edge2 - e1 * edge1;
      if (length(along) > 0.25)
      {
        vec2 m = normalize(vec2(-along.y, along.x));
        m = dot(m, e1) < 0.0 ? -m : m;
        normal = m;
        r = max(0.0, dot(e1 * edge1, m));
      }
      break;
    }
  }
  float s = inner ? 1.0 / wc - 1.0 / w : 1.0 / max(1e-6, d1 / invFar) - 1.0 / w;
  if (physical != 0)
  {
    float h = r / max(1e-12, s);
    return penumbraFractionAbove(
      inner ? -h : h, dot(normal, du) * texelsPerNdc, dot(normal, dv) * texelsPerNdc);
  }
  float rmax = max(1e-6, reach * thesisRadius.z * (w - (inner ? wc : d1 / invFar)));
  return inner ? clamp(0.5 * (1.0 - r / rmax), 0.0, 0.5) : clamp(0.5 * (1.0 + r / rmax), 0.5, 1.0);
}
