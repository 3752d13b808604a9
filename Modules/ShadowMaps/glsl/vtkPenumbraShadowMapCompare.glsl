// Shadow-map comparison shared by the lookups (Brabec 2003, ch. 4-5): the slot a sample
// falls into (one view, a cube face, a paraboloid hemisphere), its projection, linear depth
// and slope-scaled bias, and the depth compare of nearest texels (LEQUAL: lit where the
// reference depth is at most the stored one; PCF averages the compared taps, Fast PCF
// weights the 2 x 2 adjacent ones). The compare is a texelFetch of the raw depth and a
// test: the same texel and answer as a sampler2DShadow lookup with nearest filtering, at a
// fraction of its cost on llvmpipe. The same projection, slot choice and bias as the
// CPU lookup of vtkPenumbraShadowMapShadows, in float. The lookup programs compile slotMode,
// perspective, radius, bilinear and areaMode as constants (LookupVariant in
// vtkPenumbraShadowMapShadowsInternals.h): the branches a light does not take cost nothing.
uniform int slotMode;      // 0 one view, 1 cube faces, 2 paraboloid hemispheres
uniform int slot;          // the slot this draw looks up
uniform mat4 lightMatrix;  // perspective/orthographic views (rows of View)
uniform int perspective;
uniform float invFar;      // perspective: depth = w / Far; paraboloid: distance / Far
uniform float tanHalf;
uniform float footprintScale; // orthographic: 2 / (|row 0| size)
uniform float depthPerLengthOrtho; // orthographic: |row 2|
uniform vec3 lightPosition; // rebased; cube and paraboloid centre
uniform vec3 toLightDirection; // directional: unit vector towards the light
uniform float mapScale;    // paraboloid coordinates -> NDC
uniform vec2 mapSize;      // texels (non-square only for one-view lights)
uniform float constantBias;
uniform float slopeBias;   // SlopeBias * (1 + radius)
uniform float maxTangent;
uniform int radius;        // PCF radius in texels, 0 without PCF
uniform int bilinear;      // 1: Fast PCF, the 2 x 2 adjacent taps weighted bilinearly (ch. 5.2)
uniform sampler2D depthMap; // the map's raw depth (a sampler object turns its compare off)

// 1 where a receiver at depth `reference` is lit by the map's texel `texel` (LEQUAL), else 0.
float penumbraLit(ivec2 texel, float reference)
{
  return reference <= texelFetch(depthMap, texel, 0).r ? 1.0 : 0.0;
}

// The same at texture coordinates `coord` ([0, 1]^2): the texel nearest filtering reads.
float penumbraLitAt(vec2 coord, float reference)
{
  ivec2 last = ivec2(mapSize) - 1;
  return penumbraLit(clamp(ivec2(floor(coord * mapSize)), ivec2(0), last), reference);
}
//PENUMBRA::Soft

int penumbraSlot(vec3 p)
{
  vec3 v = p - lightPosition;
  if (slotMode == 1)
  {
    int best = 0;
    for (int c = 1; c < 3; ++c)
    {
      best = abs(v[c]) > abs(v[best]) ? c : best;
    }
    return 2 * best + (v[best] < 0.0 ? 1 : 0);
  }
  if (slotMode == 2)
  {
    return v.z >= 0.0 ? 0 : 1;
  }
  return 0;
}

float penumbraCompare(vec3 p, vec3 normal)
{
  vec3 v = p - lightPosition;
  vec2 st;
  float depth;
  float footprint;
  float depthPerLength;
  vec3 toLight;
  if (slotMode == 2)
  {
    float distance = length(v);
    vec3 q = v / distance;
    vec2 xy = q.xy / (1.0 + abs(q.z)); // both hemispheres (ParaboloidFromDirection)
    st = xy * mapScale;
    depth = distance * invFar;
    depthPerLength = invFar;
    footprint = distance * 2.0 / (1.0 + dot(xy, xy)) * 2.0 / (mapSize.x * mapScale);
    toLight = -q;
  }
  else
  {
    vec4 clip = lightMatrix * vec4(p, 1.0);
    if (perspective != 0)
    {
      st = clip.xy / clip.w;
      depth = clip.w * invFar;
      depthPerLength = invFar;
      footprint = 2.0 * tanHalf * clip.w / min(mapSize.x, mapSize.y);
      toLight = normalize(lightPosition - p);
    }
    else
    {
      st = clip.xy;
      depth = clip.z;
      depthPerLength = depthPerLengthOrtho;
      footprint = footprintScale;
      toLight = toLightDirection;
    }
  }
  if (slotMode == 0 && any(greaterThan(abs(st), vec2(1.0))))
  {
    // Outside the map: no receiver it was fitted for lies there (every view sample is
    // inside the fit, with a margin). Only a multisampled window's partly covered edge
    // pixels look up such points, which have no view sample of their own: unshadowed, as
    // the visibility textures leave pixels without a sample.
    return 1.0;
  }
  if (areaMode != 0)
  {
    // Area and linear lights: every tap is compared at its texel's centre with the
    // receiver's tangent plane there, so the slope term needs no tangent; the sample may
    // face away from the light's centre (part of the light is still above its plane).
    float bias = constantBias + slopeBias * footprint * depthPerLength;
    vec3 plane = penumbraReceiverPlane(p, normal);
    float w = depth / invFar;
    return areaMode == 1 ? penumbraPcss(st, w, depth - bias, bias, plane, normal, p)
                         : penumbraHorizon(p, normal) *
        penumbraSingleSample(st, w, depth - bias, bias, plane);
  }
  float cosine = max(1e-9, dot(normal, toLight));
  float tangent = min(maxTangent, sqrt(max(0.0, 1.0 - cosine * cosine)) / cosine);
  float threshold = depth - constantBias - slopeBias * footprint * tangent * depthPerLength;
  ivec2 size = ivec2(mapSize);
  if (bilinear != 0)
  {
    // The same taps and weights as BilinearLookup() on the CPU.
    vec2 f = (st * 0.5 + 0.5) * mapSize - 0.5;
    vec2 b = floor(f);
    vec2 w = f - b;
    ivec2 i0 = ivec2(b);
    float l[4];
    for (int k = 0; k < 4; ++k)
    {
      ivec2 i = clamp(i0 + ivec2(k & 1, k >> 1), ivec2(0), size - 1);
      l[k] = penumbraLit(i, threshold);
    }
    return mix(mix(l[0], l[1], w.x), mix(l[2], l[3], w.x), w.y);
  }
  ivec2 texel = clamp(ivec2(floor((st * 0.5 + 0.5) * mapSize)), ivec2(0), size - 1);
  float lit = 0.0;
  float taps = 0.0;
  for (int dy = -radius; dy <= radius; ++dy)
  {
    for (int dx = -radius; dx <= radius; ++dx)
    {
      // PCF stays inside the map, as on the CPU.
      lit += penumbraLit(clamp(texel + ivec2(dx, dy), ivec2(0), size - 1), threshold);
      taps += 1.0;
    }
  }
  return lit / taps;
}
