//VTK::System::Dec
//VTK::Output::Dec
// Dual-paraboloid shadow map, fragment stage (Brabec, "Shadow Techniques for Interactive and
// Real-Time Applications", PhD thesis, 2003, ch. 6): the depth is exact per pixel.
// The texel centre is mapped back to its direction d (inverse paraboloid) and the stored
// value is the distance along d to the plane of the triangle being drawn, over Far; the
// interpolated vertex distance (inexact inside a triangle) is only the fallback for planes
// seen edge-on. Midpoint peeling as in vtkPenumbraShadowMapFS.
flat in vec4 planeVS;
in float distanceVS;

uniform vec2 mapSize;
uniform float invMapScale;
uniform float invFar;
uniform int peel;
uniform sampler2D firstLayer;
uniform float peelGap;

void main()
{
  vec2 xy = (gl_FragCoord.xy / mapSize * 2.0 - 1.0) * invMapScale;
  float r2 = dot(xy, xy);
  vec3 d = vec3(2.0 * xy, 1.0 - r2) / (1.0 + r2);
  float denom = dot(planeVS.xyz, d);
  float dist = distanceVS;
  if (denom != 0.0)
  {
    float exact = planeVS.w / denom;
    if (exact > 0.5 * distanceVS && exact < 2.0 * distanceVS)
    {
      dist = exact;
    }
  }
  float depth = clamp(dist * invFar, 0.0, 1.0);
  if (peel != 0 && depth <= texelFetch(firstLayer, ivec2(gl_FragCoord.xy), 0).r + peelGap)
  {
    discard;
  }
  gl_FragDepth = depth;
}
