// Per-sample facing and cone rules of vtkPenumbraReference on the G-buffer (the GPU twin of
// penumbra_light_views::ClassifyFacing), in double precision like the reference:
// -1 no surface, 0 facing away or outside a spot cone (shadowed), 1 lit without a map
// (light off, no casters), 2 pending (the map decides). lightKind, lightOff and anyCaster
// are compiled as constants (LookupVariant in vtkPenumbraShadowMapShadowsInternals.h).
uniform sampler2D samplePositions; // xyz rebased, w = 1 where a surface was seen
uniform sampler2D sampleNormals;   // xyz facet normal toward the camera, w = prop (-1: none)
uniform int lightKind;     // 0 directional, 1 point, 2 spot, 3 area or linear light (as a spot)
uniform int lightOff;
uniform int anyCaster;
uniform dvec3 classifyDirection; // directional: unit vector towards the light
uniform dvec3 classifyPosition;  // positional: rebased
uniform dvec3 classifyAxis;      // spot: unit axis away from the light
uniform double classifyCosCone;
uniform dvec3 classifyHalfU;     // area: half the light's extent along U (zero for a point)
uniform dvec3 classifyHalfV;     // area: half along V (zero for a line)

bool penumbraFinite(vec3 v)
{
  return !any(isnan(v)) && !any(isinf(v));
}

// The rules for one surface point p with facet normal n (rebased, toward the camera).
int penumbraClassifyPoint(vec3 p, vec3 n)
{
  if (!penumbraFinite(p) || !penumbraFinite(n))
  {
    return -1;
  }
  if (lightOff != 0)
  {
    return 1;
  }
  dvec3 dp = dvec3(p);
  dvec3 toLight = lightKind == 0 ? classifyDirection : classifyPosition - dp;
  // An area light shines on a sample while any part of it lies above the sample's tangent
  // plane (the reference's rule per light point); the visible fraction of it is
  // penumbraHorizon() of vtkPenumbraShadowMapSoft.glsl.
  double height = dot(dvec3(n), toLight);
  if (lightKind == 3)
  {
    height += abs(dot(dvec3(n), classifyHalfU)) + abs(dot(dvec3(n), classifyHalfV));
  }
  bool facing = height > 0.0LF;
  if (facing && lightKind >= 2)
  {
    dvec3 fromLight = -toLight;
    double len = length(fromLight);
    facing = len > 0.0LF && dot(fromLight / len, classifyAxis) >= classifyCosCone;
  }
  if (!facing)
  {
    return 0;
  }
  return anyCaster != 0 ? 2 : 1;
}

// The rules for the G-buffer sample at `cell` (its position and normal returned).
int penumbraClassify(ivec2 cell, out vec3 p, out vec3 n)
{
  vec4 position = texelFetch(samplePositions, cell, 0);
  vec4 normal = texelFetch(sampleNormals, cell, 0);
  p = position.xyz;
  n = normal.xyz;
  return position.w < 0.5 || normal.w < 0.0 ? -1 : penumbraClassifyPoint(p, n);
}
