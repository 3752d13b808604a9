//VTK::System::Dec
//VTK::Output::Dec
// Shadow-map lookup of a compacted list of pending view samples (the CPU-samples entry point
// vtkPenumbraShadowMapShadows::ComputeVisibility): one fragment per sample, drawn once per
// map slot; fragments whose sample projects into another slot are discarded.
in vec2 texCoord;

uniform sampler2D samplePositions; // xyz: position in the geometry's rebased frame
uniform sampler2D sampleNormals;   // xyz: facet normal toward the camera
uniform int sampleCount;
uniform int listWidth;

//PENUMBRA::Compare

void main()
{
  ivec2 cell = ivec2(gl_FragCoord.xy);
  int index = cell.y * listWidth + cell.x;
  if (index >= sampleCount)
  {
    discard;
  }
  vec3 p = texelFetch(samplePositions, cell, 0).xyz;
  vec3 normal = normalize(texelFetch(sampleNormals, cell, 0).xyz);
  if (penumbraSlot(p) != slot)
  {
    discard;
  }
  // Only red is stored (R32F); texCoord is written so that the quad's texture-coordinate
  // attribute stays active in the linked program.
  gl_FragData[0] = vec4(penumbraCompare(p, normal), texCoord, 1.0);
}
