//VTK::System::Dec
//VTK::Output::Dec
// Shadow-map lookup straight from the G-buffer into a light's channel of the frame's
// visibility texture: no sample leaves the GPU. One draw per map slot; the first draw also
// writes the samples the facing rules decide (writeDecided), pending samples of other slots
// are discarded. slot = -1: no map (no pending sample), pending samples are lit.
in vec2 texCoord;

uniform int writeDecided;

//PENUMBRA::Classify
//PENUMBRA::Compare

void main()
{
  vec3 p;
  vec3 n;
  // The adaptive sampling's first pass draws one fragment per block corner.
  ivec2 cell = ivec2(gl_FragCoord.xy);
  cell = adaptivePass == 1 ? min(cell * adaptiveBlock, adaptiveImage - 1) : cell;
  penumbraPixel = cell;
  penumbraProp = texelFetch(sampleNormals, cell, 0).w;
  int state = penumbraClassify(cell, p, n);
  float v;
  if (state == 2 && slot >= 0)
  {
    if (penumbraSlot(p) != slot)
    {
      discard;
    }
    v = penumbraCompare(p, normalize(n));
  }
  else
  {
    if (writeDecided == 0)
    {
      discard;
    }
    // An area light without casters still shows only its part above the tangent plane.
    v = state == 0 ? 0.0 : (state < 0 ? -1.0 : (lightKind == 3 ? penumbraHorizon(p, normalize(n)) : 1.0));
  }
  // Never true; keeps the quad's texture-coordinate attribute active in the program.
  if (texCoord.x < -1.0)
  {
    v = 0.0;
  }
  gl_FragData[0] = adaptivePass == 1 ? penumbraCorner : vec4(v);
}
