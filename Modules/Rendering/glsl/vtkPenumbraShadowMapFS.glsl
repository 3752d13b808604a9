//VTK::System::Dec
//VTK::Output::Dec
// Plain shadow map, fragment stage: writes the linear depth, clamped to [0, 1] (seed 004
// ch. 4.1.2). With `peel` set it keeps only surfaces behind the first layer (read from
// `firstLayer`) by more than `peelGap`: the second depth of Woo's midpoint maps (ch. 4.1.1).
in float lightDepthVS;

uniform int peel;
uniform sampler2D firstLayer;
uniform float peelGap;

void main()
{
  float depth = clamp(lightDepthVS, 0.0, 1.0);
  if (peel != 0 && depth <= texelFetch(firstLayer, ivec2(gl_FragCoord.xy), 0).r + peelGap)
  {
    discard;
  }
  gl_FragDepth = depth;
}
