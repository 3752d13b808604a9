//VTK::System::Dec
//VTK::Output::Dec
// Receiver extent for fitting the light views (Brabec 2003, ch. 4.2) on the G-buffer, so the
// samples never leave the GPU: each fragment reduces a tile x tile block of samples, and the
// CPU merges the few tiles. Only pending samples (facing the light, in the cone) count.
// Out 0: box min xyz, farthest distance from the light; out 1: box max xyz, spot tangent;
// out 2: light-space min along axes 0-2 (directional), used-slot bit mask;
// out 3: light-space max, number of pending samples.
in vec2 texCoord;

uniform ivec2 sampleSize;
uniform int tile;
uniform dvec3 axis0; // directional: light-space axes; spot: right, up, axis
uniform dvec3 axis1;
uniform dvec3 axis2;

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
      vec3 p;
      vec3 n;
      if (penumbraClassify(cell, p, n) != 2)
      {
        continue;
      }
      ++pending;
      used |= 1 << penumbraSlot(p);
      boxMin = min(boxMin, p);
      boxMax = max(boxMax, p);
      dvec3 dp = dvec3(p);
      if (lightKind == 0)
      {
        vec3 d = vec3(dot(dp, axis0), dot(dp, axis1), dot(dp, axis2));
        lo = min(lo, d);
        hi = max(hi, d);
      }
      else
      {
        dvec3 q = dp - classifyPosition;
        farthest = max(farthest, float(length(q)));
        double w = dot(q, axis2);
        if (lightKind == 2 && w > 0.0LF)
        {
          spotTan = max(spotTan, float(max(abs(dot(q, axis0)), abs(dot(q, axis1))) / w));
        }
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
