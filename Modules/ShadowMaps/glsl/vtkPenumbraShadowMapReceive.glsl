// Shadow-map lookup inside a receiver's own fragment shader (the way VTK's
// vtkShadowMapPass shades): the fragment's surface (penumbraSurface), the facing and cone
// rules, and the map compare, with no G-buffer pass and no visibility texture. The same
// functions as the G-buffer lookup (vtkPenumbraShadowMapFrameFS.glsl) on the same surface
// values, so the shaded image shows the visibility the benchmark measures. Every global
// name below gets the light's suffix when it is injected (one copy per shadowed light).
//PENUMBRA::Classify
//PENUMBRA::Compare

// p, n: the fragment's surface (penumbraSurface), computed once for every light.
float penumbraReceive(vec3 p, vec3 n)
{
  int state = penumbraClassifyPoint(p, n);
  if (state == 2 && slot >= 0)
  {
    return penumbraCompare(p, normalize(n));
  }
  return state == 0 ? 0.0 : 1.0;
}
