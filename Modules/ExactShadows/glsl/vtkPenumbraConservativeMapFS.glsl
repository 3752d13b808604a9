//VTK::System::Dec
// Conservative shadow map, fragment stage (Hertel, Hormann, Westermann, "A Hybrid GPU Rendering
// Pipeline for Alias-Free Hard Shadows", Eurographics 2009 Areas Papers, §4.1, with its distance
// test corrected): keep the texel iff its centre is inside the polygon or within keepRadius of it
// (true point-to-segment distance, not the paper's broken edge/vertex rule), then write the
// polygon's conservative minimum depth over the texel square and the triangle id.
flat in uint gId;
flat in int gCount;
flat in vec2 gPoly[9];
flat in vec4 gPlane;
flat in vec2 gBound;
flat in int gNear;

uniform int perspective;
uniform float keepRadius;   // texels: half the diagonal plus a rounding margin
uniform float invFar;       // perspective: stored depth = w * invFar
uniform int peel;           // layers already stored: skip the triangles they hold here
uniform usampler2D layer1;
uniform usampler2D layer2;
uniform usampler2D layer3;

out uvec4 idOut;

const uint fullBit = 0x80000000u;

float cross2(vec2 a, vec2 b)
{
  return a.x * b.y - a.y * b.x;
}

// Edge a->b of the polygon (orientation s): accumulates the smallest signed distance to the
// edge lines (positive inside), the smallest point-to-segment distance and "inside so far".
void edge(vec2 a, vec2 b, vec2 c, float s, inout vec3 acc)
{
  vec2 e = b - a;
  vec2 w = c - a;
  float ee = dot(e, e);
  float len = sqrt(ee);
  float sd = len > 0.0 ? s * cross2(e, w) / len : 0.0;
  acc.x = min(acc.x, sd);
  acc.z = sd >= 0.0 ? acc.z : 0.0;
  // The segment distance only matters outside the edge line.
  if (sd < keepRadius)
  {
    float h = ee > 0.0 ? clamp(dot(w, e) / ee, 0.0, 1.0) : 0.0;
    acc.y = min(acc.y, length(w - h * e));
  }
}

void main()
{
  uint stored = gId + 1u;
  // Depth peeling by id (replaces the paper's inexact "own id -> lit" rule of §4.2): layer k
  // holds the nearest triangle that none of the layers before it holds.
  ivec2 texel = ivec2(gl_FragCoord.xy);
  if ((peel >= 1 && (texelFetch(layer1, texel, 0).r & ~fullBit) == stored) ||
    (peel >= 2 && (texelFetch(layer2, texel, 0).r & ~fullBit) == stored) ||
    (peel >= 3 && (texelFetch(layer3, texel, 0).r & ~fullBit) == stored))
  {
    discard;
  }
  if (gNear == 1)
  {
    gl_FragDepth = 0.0;
    idOut = uvec4(stored, 0u, 0u, 0u);
    return;
  }
  vec2 c = gl_FragCoord.xy;
  // Every array index below is a constant: llvmpipe turns dynamically indexed inputs into
  // slow per-fragment selects, and almost every primitive is a plain triangle.
  float area = cross2(gPoly[0], gPoly[1]) + cross2(gPoly[1], gPoly[2]);
  if (gCount > 3) area += cross2(gPoly[2], gPoly[3]);
  if (gCount > 4) area += cross2(gPoly[3], gPoly[4]);
  if (gCount > 5) area += cross2(gPoly[4], gPoly[5]);
  if (gCount > 6) area += cross2(gPoly[5], gPoly[6]);
  if (gCount > 7) area += cross2(gPoly[6], gPoly[7]);
  if (gCount > 8) area += cross2(gPoly[7], gPoly[8]);
  vec2 last = gCount == 3 ? gPoly[2] : (gCount == 4 ? gPoly[3] : (gCount == 5 ? gPoly[4] :
    (gCount == 6 ? gPoly[5] : (gCount == 7 ? gPoly[6] : (gCount == 8 ? gPoly[7] : gPoly[8])))));
  area += cross2(last, gPoly[0]);
  float s = area >= 0.0 ? 1.0 : -1.0;
  vec3 acc = vec3(1e30, 1e30, area != 0.0 ? 1.0 : 0.0); // min signed distance, min distance, inside
  edge(gPoly[0], gPoly[1], c, s, acc);
  if (gCount > 3) edge(gPoly[1], gPoly[2], c, s, acc);
  if (gCount > 4) edge(gPoly[2], gPoly[3], c, s, acc);
  if (gCount > 5) edge(gPoly[3], gPoly[4], c, s, acc);
  if (gCount > 6) edge(gPoly[4], gPoly[5], c, s, acc);
  if (gCount > 7) edge(gPoly[5], gPoly[6], c, s, acc);
  if (gCount > 8) edge(gPoly[6], gPoly[7], c, s, acc);
  if (gCount == 3) edge(gPoly[1], gPoly[2], c, s, acc);
  if (gCount == 4) edge(gPoly[2], gPoly[3], c, s, acc);
  if (gCount == 5) edge(gPoly[3], gPoly[4], c, s, acc);
  if (gCount == 6) edge(gPoly[4], gPoly[5], c, s, acc);
  if (gCount == 7) edge(gPoly[5], gPoly[6], c, s, acc);
  if (gCount == 8) edge(gPoly[6], gPoly[7], c, s, acc);
  if (gCount == 9) edge(gPoly[7], gPoly[8], c, s, acc);
  edge(last, gPoly[0], c, s, acc);
  bool inside = acc.z > 0.5;
  float minInside = acc.x;
  float nearest = acc.y;
  if (!inside && nearest > keepRadius)
  {
    discard;
  }
  bool full = inside && minInside > keepRadius;

  // Conservative depth: the plane's extreme over the texel square (§4.1), never beyond the
  // vertex extreme, minus the plane's tolerance; then a relative epsilon for storage.
  float halfSpan = 0.5 * (abs(gPlane.y) + abs(gPlane.z));
  float qc = gPlane.x + dot(gPlane.yz, c - gPoly[0]);
  float depth;
  if (perspective == 1)
  {
    float qcons = gBound.x; // largest 1/w: nearest point
    float qs = qc + halfSpan + gBound.y;
    if (gPlane.w > 0.5 && qs > 0.0)
    {
      qcons = min(qs, qcons);
    }
    depth = invFar / qcons;
  }
  else
  {
    depth = gBound.x;
    if (gPlane.w > 0.5)
    {
      depth = max(depth, qc - halfSpan - gBound.y);
    }
  }
  depth = depth - 1e-6 * abs(depth) - 1e-7;
  gl_FragDepth = clamp(depth, 0.0, 1.0);
  idOut = uvec4(full ? (stored | fullBit) : stored, 0u, 0u, 0u);
}
