//VTK::System::Dec
//VTK::Output::Dec
// Woo's midpoint map (Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD
// thesis, 2003, §4.1.1) on the GPU: the depth written is the mean of the
// first two depth-peeled layers (the far value 1 where there is no second surface), so the
// GPU lookup compares against the same map the CPU lookup builds.
in vec2 texCoord;
uniform sampler2D firstLayer;
uniform sampler2D secondLayer;

void main()
{
  ivec2 texel = ivec2(gl_FragCoord.xy);
  // No colour buffer is attached; texCoord is written so that the quad's texture-coordinate
  // attribute stays active in the linked program.
  gl_FragData[0] = vec4(texCoord, 0.0, 1.0);
  gl_FragDepth =
    0.5 * (texelFetch(firstLayer, texel, 0).r + texelFetch(secondLayer, texel, 0).r);
}
