//VTK::System::Dec
//VTK::Output::Dec
// Receiver extent for fitting the light views (Brabec 2003, ch. 4.2) on the G-buffer, so the
// samples never leave the GPU: each fragment reduces a tile x tile block of samples, and the
// CPU merges the few tiles. The samples that may face the light (and lie in a spot's cone)
// count, in float: per sample the cost of this pass is that of a full-screen pass.
// Out 0: box min xyz, farthest distance from the light; out 1: box max xyz, spot tangent;
// out 2: light-space min along axes 0-2 (directional), used-slot bit mask;
// out 3: light-space max, number of pending samples.
in vec2 texCoord;

uniform ivec2 sampleSize;
uniform int tile;
uniform vec3 fAxis0[3]; // directional: light-space axes; spot: right, up, axis
uniform vec3 fDirection; // directional: unit vector towards the light
uniform vec3 fPosition;  // positional: rebased
uniform float fCosCone;  // spot

//PENUMBRA::Classify
//PENUMBRA::Compare

void main()
{
  const float big = 3.0e38;
  vec3 boxMin = vec3(big);
  vec3 boxMax = vec3(-big);
  vec3 lo = vec3(big);
  vec3 hi = vec3(-big);
  float farthest = 0.0;
  float spotTan = 0.0;
  int used = 0;
  int pending = 0;
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
      if (position.w < 0.5 || normal.w < 0.0)
      {
        continue; // no surface, or no shadow work
      }
      // A superset of the pending samples, in float: the facing and cone tests with a margin
      // above float rounding (the extent only has to cover every pending sample, so a sample
      // float cannot decide counts).
      vec3 p = position.xyz;
      vec3 toLight = lightKind == 0 ? fDirection : fPosition - p;
      float margin = 1e-5 * (length(p) + length(fPosition) + length(toLight));
      if (dot(normal.xyz, toLight) < -margin)
      {
        continue;
      }
      vec3 q = p - fPosition;
      if (lightKind == 2 && dot(normalize(q), fAxis0[2]) < fCosCone - 1e-5)
      {
        continue;
      }
      ++pending;
      used |= 1 << penumbraSlot(p);
      boxMin = min(boxMin, p);
      boxMax = max(boxMax, p);
      vec3 d = vec3(dot(p, fAxis0[0]), dot(p, fAxis0[1]), dot(p, fAxis0[2]));
      lo = min(lo, d);
      hi = max(hi, d);
      farthest = max(farthest, length(q));
      float w = dot(q, fAxis0[2]);
      if (w > 0.0)
      {
        spotTan = max(spotTan, max(abs(dot(q, fAxis0[0])), abs(dot(q, fAxis0[1]))) / w);
      }
    }
  }
  if (texCoord.x < -1.0)
  {
    pending = 0;
  }
  gl_FragData[0] = vec4(boxMin, farthest);
  gl_FragData[1] = vec4(boxMax, spotTan);
  gl_FragData[2] = vec4(lo, float(used));
  gl_FragData[3] = vec4(hi, float(pending));
}
