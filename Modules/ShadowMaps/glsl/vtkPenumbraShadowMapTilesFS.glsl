//VTK::System::Dec
//VTK::Output::Dec
// Per-view summary of the G-buffer for fitting light views (Brabec 2003, ch. 4.2) without
// touching every sample again when only a light moves: each fragment reduces a tile x tile
// block of samples with a surface to the bounding box of their positions and of their
// normals. It does not depend on any light, so it is computed once per view; the CPU then
// fits each directional or spot light's view to the tiles that may face it (a superset of
// its receivers).
// Out 0: position min xyz, number of samples; out 1: position max xyz;
// out 2: normal min xyz; out 3: normal max xyz.
in vec2 texCoord;

//PENUMBRA::TileSample

void main()
{
  const float big = 3.0e38;
  vec3 boxMin = vec3(big);
  vec3 boxMax = vec3(-big);
  vec3 normalMin = vec3(big);
  vec3 normalMax = vec3(-big);
  int count = 0;
  for (int j = 0; j < tile; ++j)
  {
    for (int i = 0; i < tile; ++i)
    {
      vec3 p;
      vec3 n;
      if (penumbraTileSample(i, j, p, n))
      {
        ++count;
        boxMin = min(boxMin, p);
        boxMax = max(boxMax, p);
        normalMin = min(normalMin, n);
        normalMax = max(normalMax, n);
      }
    }
  }
  if (texCoord.x < -1.0)
  {
    count = 0; // never true; keeps the quad's texture coordinates in the program
  }
  gl_FragData[0] = vec4(boxMin, float(count));
  gl_FragData[1] = vec4(boxMax, 0.0);
  gl_FragData[2] = vec4(normalMin, 0.0);
  gl_FragData[3] = vec4(normalMax, 0.0);
}
