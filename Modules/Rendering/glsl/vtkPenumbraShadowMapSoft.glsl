// Soft shadows of area and linear lights from one perspective map at the light's centre,
// shared by `pcss` (Fernando, "Percentage-Closer Soft Shadows", NVIDIA 2005) and
// `single-sample-soft` (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, ch. 11). Substituted into vtkPenumbraShadowMapCompare.glsl
// after its uniforms. areaMode is compiled as a constant (LookupVariant).
uniform int areaMode;        // 0 hard light, 1 PCSS, 2 single-sample soft
uniform sampler2D depthMap;  // the map without compare (a sampler object on its own unit)
uniform vec3 lightU;         // half the light's extent along U (world)
uniform vec3 lightV;         // half along V (zero for a linear light)
uniform int searchTaps;      // PCSS: blocker-search taps per light axis; SSS: half box taps
uniform int filterTaps;      // PCF taps per light axis
uniform float searchDepth;   // nearest blocker assumed at this fraction of the receiver's w
uniform float maxRadius;     // taps at most this far from the sample, in NDC
uniform int physical;        // SSS: 1 penumbra from the light's size, 0 the thesis's radii
uniform vec3 thesisRadius;   // SSS thesis mode: r_scale (texels / length), r_bias (texels),
                             // r_shrink (1 / length)

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

// PCSS over the light's taps above the receiver's tangent plane: a stratified grid of light
// points (cell centres); the visible fraction is the horizon term times the share of the
// taps above the plane that the map leaves lit.
float penumbraPcss(vec2 st, float w, float threshold, float bias, vec3 plane, vec3 n, vec3 p)
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
  int rows = line ? 1 : searchTaps;
  float sum = 0.0;
  float found = 0.0;
  for (int j = 0; j < rows; ++j)
  {
    for (int i = 0; i < searchTaps; ++i)
    {
      vec2 ab = penumbraGridPoint(i, j, searchTaps, rows);
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
  if (found == float(rows * searchTaps))
  {
    return 0.0; // early out: the whole search region is blocked (the filter region is inside it)
  }
  // 2. Penumbra from the average blocker depth; 3. PCF over the light's image at that depth,
  //    counting only light points above the tangent plane.
  float wb = max(1e-6, (sum / found) / invFar);
  float scale = max(0.0, 1.0 / wb - 1.0 / w);
  rows = line ? 1 : filterTaps;
  float lit = 0.0;
  float above = 0.0;
  float total = 0.0;
  for (int j = 0; j < rows; ++j)
  {
    for (int i = 0; i < filterTaps; ++i)
    {
      vec2 ab = penumbraGridPoint(i, j, filterTaps, rows);
      vec2 t = penumbraTap(st, (ab.x * du + ab.y * dv) * scale);
      float l = texture(shadowMap, vec3(t, penumbraTapThreshold(t, plane, threshold, bias)));
      float up = h0 + dot(ab, vec2(alpha, beta)) > 0.0 ? 1.0 : 0.0;
      lit += l * up;
      above += up;
      total += l;
    }
  }
  return horizon * (above > 0.0 ? lit / above : total / float(rows * filterTaps));
}

// Single-sample soft shadows (Brabec 2003, ch. 11, Fig. 11.6): a sample the map leaves lit
// searches a box around it for the nearest blocker (outer penumbra, from 1 down to 0.5), a
// shadowed one for the nearest lit texel (inner penumbra, from 0 up to 0.5). The thesis's
// object IDs are replaced by the receiver-plane threshold: a texel counts as a blocker only
// in front of the receiver's tangent plane, which rejects the receiver's own surface (the
// tilted receiver of Fig. 11.5) and a convex object's other faces, and keeps the
// self-penumbrae the IDs lose. Physical mode: each blocker texel i at map distance r_i and
// depth d_i is taken as a straight edge across the direction e_i towards it, which hides
// the light points o with e_i . xy(o) (1 / d_i - 1 / w) > r_i: the visible fraction is
// penumbraFractionAbove(r_i / s_i, e_i . du, e_i . dv), minimised over the box; inside, the
// same with the distance to the nearest lit texel and the depth of the blocker over the
// sample. Thesis mode: f = r / r_max' with r_max = r_scale w + r_bias texels, scaled by
// r_shrink (w - d) at the blocker found.
float penumbraSingleSample(vec2 st, float w, float threshold, float bias, vec3 plane)
{
  vec2 du = (lightMatrix * vec4(lightU, 0.0)).xy;
  vec2 dv = (lightMatrix * vec4(lightV, 0.0)).xy;
  float texelsPerNdc = 0.5 * min(mapSize.x, mapSize.y);
  ivec2 size = ivec2(mapSize);
  vec2 f = (st * 0.5 + 0.5) * mapSize; // continuous texel position (subpixel accuracy)
  ivec2 centre = clamp(ivec2(floor(f)), ivec2(0), size - 1);
  float dc = texelFetch(depthMap, centre, 0).r;
  bool inner = dc < penumbraTapThreshold((vec2(centre) + 0.5) / mapSize, plane, threshold, bias);
  float wc = max(1e-6, dc / invFar);
  // Search reach in texels.
  float extent = length(du) + length(dv);
  float reach;
  if (physical != 0)
  {
    float s = inner ? 1.0 / wc - 1.0 / w : 1.0 / (searchDepth * w) - 1.0 / w;
    reach = extent * max(0.0, s) * texelsPerNdc;
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
  int n = min(searchTaps, int(ceil(reach)));
  float step = reach / float(n);
  float best = 1e30;   // smallest edge distance over penumbra half width
  float bestValue = inner ? 0.0 : 1.0;
  for (int j = -n; j <= n; ++j)
  {
    for (int i = -n; i <= n; ++i)
    {
      ivec2 texel = clamp(ivec2(floor(f + vec2(i, j) * step)), ivec2(0), size - 1);
      vec2 toTexel = vec2(texel) + 0.5 - f;
      // The edge lies half a texel before the texel's centre.
      float r = max(0.0, length(toTexel) - 0.5);
      if (r > reach)
      {
        continue;
      }
      vec2 t = (vec2(texel) + 0.5) / mapSize;
      float d = texelFetch(depthMap, texel, 0).r;
      bool blocked = d < penumbraTapThreshold(t, plane, threshold, bias);
      if (blocked == inner)
      {
        continue; // outer: looking for blockers; inner: looking for lit texels
      }
      float s = inner ? 1.0 / wc - 1.0 / w : 1.0 / max(1e-6, d / invFar) - 1.0 / w;
      if (s <= 0.0)
      {
        continue;
      }
      vec2 e = length(toTexel) > 0.0 ? normalize(toTexel) : vec2(1.0, 0.0);
      float q;
      float value;
      if (physical != 0)
      {
        float alpha = dot(e, du) * texelsPerNdc;
        float beta = dot(e, dv) * texelsPerNdc;
        float h = r / s;
        q = h / max(1e-12, abs(alpha) + abs(beta));
        value = penumbraFractionAbove(inner ? -h : h, alpha, beta);
      }
      else
      {
        float rmax = max(1e-6, reach * thesisRadius.z * (w - (inner ? wc : d / invFar)));
        q = r / rmax;
        value = inner ? clamp(0.5 * (1.0 - q), 0.0, 0.5) : clamp(0.5 * (1.0 + q), 0.5, 1.0);
      }
      if (q < best)
      {
        best = q;
        bestValue = value;
      }
    }
  }
  return bestValue;
}
