//VTK::System::Dec
//VTK::Output::Dec
// Per-view summary of the G-buffer for fitting light views (Brabec 2003, ch. 4.2) without
// touching every sample again when only a light moves: each fragment reduces a tile x tile
// block of samples with a surface to the bounding box of their positions and of their
// normals. It does not depend on any light, so it is computed once per view; the CPU then
// fits each light's view to the tiles that may face it (a superset of the receivers).
// Out 0: position min xyz, number of samples; out 1: position max xyz;
// out 2: normal min xyz; out 3: normal max xyz.
in vec2 texCoord;

uniform sampler2D samplePositions; // xyz rebased, w = 1 where a surface was seen
uniform sampler2D sampleNormals;   // xyz facet normal toward the camera, w = prop (-1: none)
uniform ivec2 sampleSize;
uniform int tile;

void main()
{
  const float big = 3.0e38;
  vec3 boxMin = vec3(big);
  vec3 boxMax = vec3(-big);
  vec3 normalMin = vec3(big);
  vec3 normalMax = vec3(-big);
  int count = 0;
  ivec2 base = ivec2(gl_FragCoord.xy) * tile;
  for (int j = 0; j < tile; ++j)
  {
    for (int i = 0; i < tile; ++i)
    {
      ivec2 cell = base + ivec2(i, j);
      if (cell.x >= sampleSize.x || cell.y >= sampleSize.y)
      {
        continue;
      }
      vec4 position = texelFetch(samplePositions, cell, 0);
      vec4 normal = texelFetch(sampleNormals, cell, 0);
      if (position.w < 0.5 || normal.w < 0.0 || any(isnan(position.xyz)) ||
        any(isinf(position.xyz)) || any(isnan(normal.xyz)) || any(isinf(normal.xyz)))
      {
        continue; // no surface, or no shadow work
      }
      ++count;
      boxMin = min(boxMin, position.xyz);
      boxMax = max(boxMax, position.xyz);
      normalMin = min(normalMin, normal.xyz);
      normalMax = max(normalMax, normal.xyz);
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
