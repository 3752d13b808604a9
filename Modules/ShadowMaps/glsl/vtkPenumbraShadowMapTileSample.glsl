// One sample of the tile x tile block a tile program's fragment reduces: false for cells
// beyond the image, samples without a surface or shadow work (prop -1), and non-finite ones.
uniform sampler2D samplePositions; // xyz rebased, w = 1 where a surface was seen
uniform sampler2D sampleNormals;   // xyz facet normal toward the camera, w = prop (-1: none)
uniform ivec2 sampleSize;
uniform int tile;

bool penumbraSampleAt(ivec2 cell, out vec3 p, out vec3 n, out float prop)
{
  p = vec3(0.0);
  n = vec3(0.0);
  prop = -1.0;
  if (any(lessThan(cell, ivec2(0))) || cell.x >= sampleSize.x || cell.y >= sampleSize.y)
  {
    return false;
  }
  vec4 position = texelFetch(samplePositions, cell, 0);
  vec4 normal = texelFetch(sampleNormals, cell, 0);
  p = position.xyz;
  n = normal.xyz;
  prop = normal.w;
  return position.w >= 0.5 && normal.w >= 0.0 && !any(isnan(p)) && !any(isinf(p)) &&
    !any(isnan(n)) && !any(isinf(n));
}

bool penumbraTileSample(int i, int j, out vec3 p, out vec3 n)
{
  float prop;
  return penumbraSampleAt(ivec2(gl_FragCoord.xy) * tile + ivec2(i, j), p, n, prop);
}
