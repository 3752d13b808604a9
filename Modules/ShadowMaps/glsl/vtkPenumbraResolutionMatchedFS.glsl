//VTK::System::Dec
//VTK::Output::Dec
// Resolution-matched shadow maps (Lefohn, Sengupta, Owens, "Resolution-Matched Shadow Maps",
// ACM TOG 26(4), 2007) on the G-buffer, one program per role:
// - RMSM_REQUEST (§3.3.2, Algorithm 2 steps 1-3): each pending sample's shadow level of
//   detail from Eq. 1 and the page of the virtual map it needs, written as key + 1 (0: no
//   request) into an RGBA32F target (with 2 x 2 analysis blocks the block's four samples'
//   pages) and the level into an R32F one; keys stay below 2^24, so they are exact
//   in float.
// - RMSM_REFINE (the shadow-edge refinement, see rmsmEdge()): each pending sample whose
//   2 x 2 taps at its requested level disagree lies at a shadow boundary, where alone the
//   texel size decides the answer; it requests the page refineLevels levels finer and is
//   looked up there. Writes key + 1 (0: no request) and the final level of every sample.
// - otherwise the lookup (§3.3.1): the level the sample requested (read from that target:
//   computing it again costs more than the rest of the lookup on llvmpipe), the page table's
//   entry for the sample's
//   page (the resident page at that level or the finest resident coarser one), and a depth
//   compare against the atlas texel with a slope-scaled bias at the resident level's texel,
//   written into the light's visibility channel (the facing rules decide the other samples).
in vec2 texCoord;

//PENUMBRA::Classify

uniform mat4 lightMatrix;  // the virtual map's view (rows of View): NDC s, t and depth
uniform int perspective;
uniform float invFar;      // perspective: depth = w / Far
uniform int baseLevel;     // coarsest level in the page table, always fully resident
uniform int finestLevel;   // log2 of the maximum effective resolution
uniform int minLevel;      // no request coarser than this (occluders thinner than a texel of
                           // a coarser level would vanish from the map)
uniform int lodBias;       // levels finer than the matched one
uniform int footprintWidth; // 1: texels as small as the footprint's smallest width
uniform int analysisStep;  // the request pass analyses one sample per step x step block (1, 2)

const int pageBits = 5; // 32 x 32 texel pages (§4: "a page size of 32^2 texels")
const float creaseCosine = 0.99; // normals more than ~8 degrees apart: another surface

// NDC s, t and the stored-depth value of a rebased point.
vec3 rmsmProject(vec3 p)
{
  vec4 clip = lightMatrix * vec4(p, 1.0);
  return perspective != 0 ? vec3(clip.xy / clip.w, clip.w * invFar) : clip.xyz;
}

// The map-coordinate change of one pixel step along `axis` (the screen-space derivative of
// §3.3.2), as a one-sided difference to the neighbour on the same prop with the smaller
// change, so that a silhouette on one side does not inflate it. False without such a
// neighbour.
bool rmsmStep(ivec2 cell, ivec2 axis, float prop, vec2 st, out vec2 delta)
{
  ivec2 size = textureSize(samplePositions, 0);
  bool found = false;
  delta = vec2(0.0);
  for (int side = -1; side <= 1; side += 2)
  {
    ivec2 c = cell + side * axis;
    if (any(lessThan(c, ivec2(0))) || any(greaterThanEqual(c, size)))
    {
      continue;
    }
    vec4 q = texelFetch(samplePositions, c, 0);
    if (q.w < 0.5 || texelFetch(sampleNormals, c, 0).w != prop)
    {
      continue;
    }
    vec2 d = float(side) * (rmsmProject(q.xyz).xy - st);
    delta = (!found || dot(d, d) < dot(delta, delta)) ? d : delta;
    found = true;
  }
  return found;
}

// Eq. 1: A = |dX x dY|, the area of the parallelogram the pixel covers in [0, 1]^2 map
// units (NDC steps halved), and the level k = -log2(sqrt(A)) whose texels are that size
// (footprintWidth 0); or, with footprintWidth 1, texels as small as the parallelogram's
// smallest width A / max(|dX|, |dY|), so that an anisotropic footprint is not under-sampled
// across its short axis (the paper's own caveat: dX and dY are not the filter ellipse's
// axes). Rounded up (a texel never larger than that), made lodBias levels finer and clamped
// to [baseLevel, finestLevel]. With one axis only (a one-pixel strip) the footprint is taken
// as square; with none, or A = 0 (seen edge-on), the finest level.
int rmsmLevel(ivec2 cell, vec2 st)
{
  float prop = texelFetch(sampleNormals, cell, 0).w;
  vec2 a;
  vec2 b;
  bool hasA = rmsmStep(cell, ivec2(1, 0), prop, st, a);
  bool hasB = rmsmStep(cell, ivec2(0, 1), prop, st, b);
  a = hasA ? a : vec2(-b.y, b.x);
  b = hasB ? b : vec2(-a.y, a.x);
  float area = 0.25 * abs(a.x * b.y - a.y * b.x);
  float size = footprintWidth != 0 ? area / max(0.5 * max(length(a), length(b)), 1e-30)
                                   : sqrt(area);
  float k = -log2(max(size, exp2(-float(finestLevel + 1))));
  return clamp(int(ceil(k)) + lodBias, max(baseLevel, minLevel), finestLevel);
}

// The texel of level k (2^k per side) holding NDC point st.
ivec2 rmsmTexel(vec2 st, int k)
{
  int side = 1 << k;
  return clamp(ivec2(floor((st * 0.5 + 0.5) * float(side))), ivec2(0), ivec2(side - 1));
}

// key + 1 of the page of level k holding NDC point st: the pages of the levels before k
// (4^(j - 5) per level j, from baseLevel on), then row by row.
float rmsmKey(vec2 st, int k)
{
  ivec2 page = rmsmTexel(st, k) >> pageBits;
  // Exact in float (below 2^24); an integer division is not vectorized on llvmpipe.
  int offset =
    int(round(float((1 << (2 * (k - pageBits))) - (1 << (2 * (baseLevel - pageBits)))) / 3.0));
  return float(offset + (page.y << (k - pageBits)) + page.x + 1);
}

#ifdef RMSM_REQUEST

void main()
{
  // One analysed sample per analysisStep^2 block (§3.3.5, "reduce the resolution of the
  // analysis"); its derivatives still come from its adjacent pixels. With 2 x 2 blocks the
  // other three samples request their own pages at the block's level, so every sample's page
  // is requested, only the level is shared. A block sample on another prop or on a surface
  // turned away from the analysed one (a crease, a contact, a silhouette) has a footprint of
  // its own, often much smaller (a wall next to the ground under a grazing light): its level
  // is computed too and the block takes the finest.
  // The analysed sample is the block's first pending one (the others may face the light
  // when it does not).
  ivec2 origin = ivec2(gl_FragCoord.xy) * analysisStep;
  ivec2 last = textureSize(samplePositions, 0) - 1;
  int samples = analysisStep * analysisStep;
  vec3 p;
  vec3 n;
  ivec2 cell = origin;
  int state = penumbraClassify(cell, p, n);
  for (int i = 1; i < samples && state != 2; ++i)
  {
    cell = min(origin + ivec2(i & 1, i >> 1), last);
    state = penumbraClassify(cell, p, n);
  }
  vec4 keys = vec4(0.0);
  float level = 0.0;
  if (state == 2)
  {
    int k = rmsmLevel(cell, rmsmProject(p).xy);
    float prop = texelFetch(sampleNormals, cell, 0).w;
    vec2 st[4];
    bool valid[4];
    for (int i = 0; i < samples; ++i)
    {
      ivec2 c = min(origin + ivec2(i & 1, i >> 1), last);
      vec4 q = texelFetch(samplePositions, c, 0);
      vec4 qn = texelFetch(sampleNormals, c, 0);
      vec3 o = rmsmProject(q.xyz);
      st[i] = o.xy;
      valid[i] = q.w >= 0.5 && (perspective == 0 || o.z > 0.0) && !any(isnan(o.xy));
      if (valid[i] && c != cell &&
        (qn.w != prop || dot(normalize(qn.xyz), normalize(n)) < creaseCosine))
      {
        k = max(k, rmsmLevel(c, o.xy));
      }
    }
    level = float(k);
    for (int i = 0; i < samples; ++i)
    {
      keys[i] = valid[i] ? rmsmKey(st[i], k) : 0.0;
    }
  }
  // Never true; keeps the quad's texture-coordinate attribute active in the program.
  if (texCoord.x < -1.0)
  {
    level = 0.0;
  }
  gl_FragData[0] = keys;
  gl_FragData[1] = vec4(level);
}
#else
uniform sampler2D requests;   // the levels for these samples (or their blocks)
uniform int levelStep;        // pixels per side of a block sharing one level (1 or 2)
uniform int refineLevels;     // RMSM_REFINE: levels finer at shadow edges
uniform isampler2D pageTable; // mip m = level finestLevel - m: (level - base) << 24 | slot
uniform sampler2D atlas;      // the resident pages' depths, 32 x 32 texels each
uniform int slotsPerRowBits;  // log2 of the atlas slots per row (shifts: integer division
                              // is not vectorized on llvmpipe)
uniform float tanHalf;        // perspective: tangent of the half field of view
uniform float footprintScale; // orthographic: world size of a texel at level 0
uniform float depthPerLengthOrtho; // orthographic: |row 2|
uniform vec3 lightPosition;   // rebased
uniform vec3 toLightDirection; // directional: unit vector towards the light
uniform float constantBias;
uniform float slopeBias;      // in texel footprints of the level compared against, on top
                              // of the receiver plane (curvature); twice that with the 2 x 2
                              // filter, whose taps reach one texel
uniform float maxTangent;

// The sample's NDC s, t and its receiver plane's stored-depth change per NDC unit of s and t
// (set by rmsmSlopeTerm() before any tap).
vec2 rmsmSt = vec2(0.0);
vec2 rmsmGrad = vec2(0.0);

// Receiver plane depth bias: each texel is compared with the depth of the sample's receiver
// plane at the texel's centre, not with the sample's own depth. A slope-scaled bias has to
// cover the receiver's depth change across a whole texel, and under a light that grazes the
// receiver that tolerance lets light leak a texel or more past an occluder's edge (false lit
// several pixels from the shadow at coarse levels, where the edge refinement sees four
// agreeing texels); the plane leaves only curvature and rounding to the bias. The stored
// depth value of that plane at the centre of texel t of level kp:
float rmsmPlaneDepth(ivec2 t, int kp, float z)
{
  vec2 centre = (vec2(t) + 0.5) * exp2(1.0 - float(kp)) - 1.0;
  return z + dot(rmsmGrad, centre - rmsmSt);
}

// One texel of level k compared with depth z: the page table's entry for its page names
// the resident page serving it (that level or the finest resident coarser one), whose texel
// is read from the atlas; the slope term (the bias per texel footprint at level 0) is scaled
// to the resident level's texel.
float rmsmTap(ivec2 texel, int k, float z, float slopeTerm)
{
  int entry = texelFetch(pageTable, texel >> pageBits, finestLevel - k).r;
  int resident = baseLevel + (entry >> 24);
  int slot = entry & 0xFFFFFF;
  ivec2 t = texel >> (k - resident);
  ivec2 origin = ivec2(slot & ((1 << slotsPerRowBits) - 1), slot >> slotsPerRowBits) << pageBits;
  float stored = texelFetch(atlas, origin + (t & ((1 << pageBits) - 1)), 0).r;
  return stored >= rmsmPlaneDepth(t, resident, z) - constantBias -
      slopeTerm * exp2(-float(resident))
    ? 1.0
    : 0.0;
}

// The slope term of the bias, per texel footprint at level 0 (rmsmTap scales it to the
// resident level's texel).
float rmsmSlopeTerm(vec3 p, vec3 m, vec3 normal)
{
  vec3 toLight = perspective != 0 ? normalize(lightPosition - p) : toLightDirection;
  float footprint = perspective != 0 ? 2.0 * tanHalf * (m.z / invFar) : footprintScale;
  float depthPerLength = perspective != 0 ? invFar : depthPerLengthOrtho;
  float cosine = max(1e-9, dot(normal, toLight));
  float tangent = min(maxTangent, sqrt(max(0.0, 1.0 - cosine * cosine)) / cosine);
  // The plane through p with the sample's normal, its depth as a function of the map's s and
  // t from the projection's Jacobian (rows ds, dt, dz per world displacement d; in the plane
  // n . d = 0).
  rmsmSt = m.xy;
  rmsmGrad = vec2(0.0);
  {
    vec4 clip = lightMatrix * vec4(p, 1.0);
    vec3 r0 = vec3(lightMatrix[0][0], lightMatrix[1][0], lightMatrix[2][0]);
    vec3 r1 = vec3(lightMatrix[0][1], lightMatrix[1][1], lightMatrix[2][1]);
    vec3 r2 = vec3(lightMatrix[0][2], lightMatrix[1][2], lightMatrix[2][2]);
    vec3 r3 = vec3(lightMatrix[0][3], lightMatrix[1][3], lightMatrix[2][3]);
    vec3 ds = perspective != 0 ? (r0 - clip.x / clip.w * r3) / clip.w : r0;
    vec3 dt = perspective != 0 ? (r1 - clip.y / clip.w * r3) / clip.w : r1;
    vec3 dz = perspective != 0 ? r3 * invFar : r2;
    mat3 a = transpose(mat3(ds, dt, normal));
    if (abs(determinant(a)) > 0.0)
    {
      mat3 inv = inverse(a);
      rmsmGrad = vec2(dot(dz, inv[0]), dot(dz, inv[1]));
      // At most the slope of maxTangent: the depth change over a level-0 texel (2 NDC units).
      float cap = 0.5 * maxTangent * footprint * depthPerLength;
      float len = length(rmsmGrad);
      rmsmGrad *= len > cap ? cap / len : 1.0;
    }
  }
  return slopeBias * footprint * tangent * depthPerLength;
}

// The four compared texels of level k around NDC point m.xy (each resolved through the page
// table, so taps across a page border read their own page) and the bilinear weights. When
// all four lie in one page resident at level k (all but a sixteenth of the samples), one
// page-table fetch and one textureGather read them: on llvmpipe each fetch costs about as
// much as the rest of the lookup.
vec4 rmsmTaps(vec3 m, int k, float slopeTerm, out vec2 w)
{
  int side = 1 << k;
  vec2 u = (m.xy * 0.5 + 0.5) * float(side) - 0.5;
  vec2 b = floor(u);
  w = u - b;
  ivec2 t0 = ivec2(b);
  if (all(greaterThanEqual(t0, ivec2(0))) && all(lessThan(t0 + 1, ivec2(side))) &&
    all(equal(t0 >> pageBits, (t0 + 1) >> pageBits)))
  {
    int entry = texelFetch(pageTable, t0 >> pageBits, finestLevel - k).r;
    if (baseLevel + (entry >> 24) == k)
    {
      int slot = entry & 0xFFFFFF;
      ivec2 a = (ivec2(slot & ((1 << slotsPerRowBits) - 1), slot >> slotsPerRowBits) << pageBits) +
        (t0 & ((1 << pageBits) - 1));
      // The texel corner a + 1 gathers (a.x, a.y + 1), (a.x + 1, a.y + 1), (a.x + 1, a.y),
      // (a.x, a.y) into x, y, z, w.
      vec4 d = textureGather(atlas, vec2(a + 1) / vec2(textureSize(atlas, 0))).wzxy;
      vec4 planes = vec4(rmsmPlaneDepth(t0, k, m.z), rmsmPlaneDepth(t0 + ivec2(1, 0), k, m.z),
        rmsmPlaneDepth(t0 + ivec2(0, 1), k, m.z), rmsmPlaneDepth(t0 + ivec2(1, 1), k, m.z));
      return vec4(greaterThanEqual(d, planes - constantBias - slopeTerm * exp2(-float(k))));
    }
  }
  vec4 l;
  for (int i = 0; i < 4; ++i)
  {
    ivec2 texel = clamp(ivec2(b) + ivec2(i & 1, i >> 1), ivec2(0), ivec2(side - 1));
    l[i] = rmsmTap(texel, k, m.z, slopeTerm);
  }
  return l;
}

// The level a sample is looked up at: its own (or its block's) from the request or refine
// pass, clamped to the table (0: it requested nothing, the base level serves it).
int rmsmLevelOf(ivec2 cell)
{
  return clamp(int(texelFetch(requests, cell / levelStep, 0).r), baseLevel, finestLevel);
}

#ifdef RMSM_REFINE
// Shadow-edge refinement. A point-sampled map answers wrongly only where an occluder's edge
// passes between the sample and the centre of its texel, and then the four texels around the
// sample straddle that edge: their compares disagree. Those samples (a thin band along the
// shadow boundaries) take the page refineLevels levels finer, which shrinks the band's width
// by 2^refineLevels; elsewhere the matched level is already exact. This is the edge test of
// the iterative adaptive shadow maps Lefohn et al. 2007 start from (§2, Algorithm 1 step 6),
// applied once on top of the resolution-matched requests. The taps' slope term is doubled,
// as for the 2 x 2 filter (they reach one texel away), so that a slanted receiver alone does
// not look like an edge.
// Only samples with a requested level (pending when the requests were made) are tested; the
// facing rules are not evaluated again.
void main()
{
  ivec2 cell = ivec2(gl_FragCoord.xy);
  float key = 0.0;
  float requested = texelFetch(requests, cell / levelStep, 0).r;
  int k = clamp(int(requested), baseLevel, finestLevel);
  vec4 position = texelFetch(samplePositions, cell, 0);
  vec3 p = position.xyz;
  vec3 n = texelFetch(sampleNormals, cell, 0).xyz;
  if (requested > 0.0 && k < finestLevel && position.w >= 0.5 && penumbraFinite(p) &&
    penumbraFinite(n))
  {
    vec3 m = rmsmProject(p);
    vec2 w;
    vec4 l = rmsmTaps(m, k, 2.0 * rmsmSlopeTerm(p, m, normalize(n)), w);
    float lit = l.x + l.y + l.z + l.w;
    if (lit > 0.0 && lit < 4.0)
    {
      k = min(k + refineLevels, finestLevel);
      key = rmsmKey(m.xy, k);
    }
  }
  if (texCoord.x < -1.0)
  {
    key = 0.0;
  }
  gl_FragData[0] = vec4(key);
  gl_FragData[1] = vec4(float(k));
}
#else
float rmsmCompare(ivec2 cell, vec3 p, vec3 normal)
{
  vec3 m = rmsmProject(p);
  // Pages nobody requested are served by the finest resident coarser page.
  int k = rmsmLevelOf(cell);
  float slopeTerm = rmsmSlopeTerm(p, m, normal);
#ifdef RMSM_BILINEAR
  // 2 x 2 PCF at level k (the paper blends two such lookups at adjacent levels).
  vec2 w;
  vec4 l = rmsmTaps(m, k, 2.0 * slopeTerm, w);
  return mix(mix(l.x, l.y, w.x), mix(l.z, l.w, w.x), w.y);
#else
  return rmsmTap(rmsmTexel(m.xy, k), k, m.z, slopeTerm);
#endif
}

void main()
{
  ivec2 cell = ivec2(gl_FragCoord.xy);
  vec3 p;
  vec3 n;
  int state = penumbraClassify(cell, p, n);
  float v = state == 2 ? rmsmCompare(cell, p, normalize(n))
                       : (state == 0 ? 0.0 : (state < 0 ? -1.0 : 1.0));
  if (texCoord.x < -1.0)
  {
    v = 0.0;
  }
  gl_FragData[0] = vec4(v);
}
#endif
#endif
