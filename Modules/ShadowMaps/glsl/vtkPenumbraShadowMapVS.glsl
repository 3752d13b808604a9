//VTK::System::Dec
// Plain shadow map, vertex stage (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, §4.1): caster vertices in the geometry's rebased
// frame go to the light's clip space. The stored depth is linear (orthographic: the fitted
// depth in [0, 1]; perspective: the distance along the view axis over Far) and travels as a
// perspective-correct varying, so it is exact per fragment, not per vertex (unlike
// the thesis's per-vertex z' = z_l w trick). Clip z is constant: depth clamping is on and the
// fragment stage writes gl_FragDepth, so casters before the near plane are clamped, not clipped
// (§4.1.2).
in vec3 vertexRebased;

uniform mat4 lightMatrix;
uniform int perspective;
uniform float invFar;

out float lightDepthVS;

void main()
{
  vec4 clip = lightMatrix * vec4(vertexRebased, 1.0);
  if (perspective != 0)
  {
    lightDepthVS = clip.w * invFar;
    gl_Position = vec4(clip.xy, 0.0, clip.w);
  }
  else
  {
    lightDepthVS = clip.z;
#ifdef PENUMBRA_HARDWARE_DEPTH
    gl_Position = vec4(clip.xy, 2.0 * clip.z - 1.0, 1.0); // depth = clip.z, clamped
#else
    gl_Position = vec4(clip.xy, 0.0, 1.0);
#endif
  }
}
