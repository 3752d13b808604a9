//VTK::System::Dec
//VTK::Output::Dec
// Plain shadow map, fragment stage: writes the linear depth, clamped to [0, 1] (Brabec, "Shadow
// Techniques for Interactive and Real-Time Applications", PhD thesis, 2003, §4.1.2). With `peel`
// set it keeps only surfaces behind the first layer (read from `firstLayer`) by more than
// `peelGap`: the second depth of Woo's midpoint maps (§4.1.1). With PENUMBRA_HARDWARE_DEPTH
// (orthographic views without peeling) the vertex stage's clip z already is the linear depth:
// nothing is written here, so the rasterizer can test depth before the fragment stage and skip
// most fragment work.
in float lightDepthVS;

uniform int peel;
uniform sampler2D firstLayer;
uniform float peelGap;

void main()
{
#ifndef PENUMBRA_HARDWARE_DEPTH
  float depth = clamp(lightDepthVS, 0.0, 1.0);
  if (peel != 0 && depth <= texelFetch(firstLayer, ivec2(gl_FragCoord.xy), 0).r + peelGap)
  {
    discard;
  }
  gl_FragDepth = depth;
#endif
}
