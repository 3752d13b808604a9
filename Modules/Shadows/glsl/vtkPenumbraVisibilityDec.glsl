// Penumbra shadowed lighting, declarations (inserted right after the mapper's light
// uniforms). Each shadowed light's colour is redefined as colour x visibility at this pixel,
// so VTK's own diffuse and specular terms (Phong) and radiance (PBR) are shadowed without
// rewriting the lighting code. Each shadowed light has its own R32F visibility texture (a
// sampler per light). Per-light #defines follow this block.
uniform ivec2 penumbraViewportOrigin; // window pixel of visibility texel (0, 0)
ivec2 penumbraTexel()
{
  return ivec2(gl_FragCoord.xy) - penumbraViewportOrigin;
}
// Background samples carry -1 (no surface, no shadow work): unshadowed.
float penumbraShadow(float visibility)
{
  return visibility < 0.0 ? 1.0 : visibility;
}
