//VTK::System::Dec
//VTK::Output::Dec
// Receiver extent of a point light's cube faces or hemispheres (Brabec 2003, ch. 4.2, 6) on
// the G-buffer, so the samples never leave the GPU: each fragment reduces a tile x tile block
// of the samples that may face the light (in float, with a margin above float rounding: the
// extent only has to cover every receiver), and the CPU merges the few tiles. Each sample's
// slot needs its own direction from the light, so this runs per light (directional and spot
// lights fit to the per-view tile boxes of vtkPenumbraShadowMapTilesFS instead).
// Out 0: box min xyz, farthest distance from the light; out 1: box max xyz;
// out 2: used-slot bit mask in w; out 3: number of samples in w.
in vec2 texCoord;

//PENUMBRA::TileSample
//PENUMBRA::Compare

void main()
{
  const float big = 3.0e38;
  vec3 boxMin = vec3(big);
  vec3 boxMax = vec3(-big);
  float farthest = 0.0;
  int used = 0;
  int pending = 0;
  for (int j = 0; j < tile; ++j)
  {
    for (int i = 0; i < tile; ++i)
    {
      vec3 p;
      vec3 n;
      if (!penumbraTileSample(i, j, p, n))
      {
        continue;
      }
      vec3 toLight = lightPosition - p;
      float margin = 1e-5 * (length(p) + length(lightPosition) + length(toLight));
      if (dot(n, toLight) < -margin)
      {
        continue; // faces away from the light
      }
      ++pending;
      used |= 1 << penumbraSlot(p);
      boxMin = min(boxMin, p);
      boxMax = max(boxMax, p);
      farthest = max(farthest, length(toLight));
    }
  }
  if (texCoord.x < -1.0)
  {
    pending = 0; // never true; keeps the quad's texture coordinates in the program
  }
  gl_FragData[0] = vec4(boxMin, farthest);
  gl_FragData[1] = vec4(boxMax, 0.0);
  gl_FragData[2] = vec4(0.0, 0.0, 0.0, float(used));
  gl_FragData[3] = vec4(0.0, 0.0, 0.0, float(pending));
}
