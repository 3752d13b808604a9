//VTK::System::Dec
// Stencil shadow volumes, vertex stage (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, ch. 3, 8): volume vertices in the geometry's
// rebased frame; a positional light's extruded copies are homogeneous with a small w (far
// beyond every sample, see PositionalFarW; GL_DEPTH_CLAMP keeps them).
// worldToClip uses a reversed depth (near = 1, far / infinity = 0, glClipControl zero-to-one)
// so that float32 depth keeps the same relative precision at every distance.
// capScale < 1 pushes light caps back by that relative eye depth: a sample lying on a caster's
// own lit surface must see that cap behind it, i.e. outside the caster's volume (the
// reference never lets a sample's own triangle block it).
in vec4 vertexRebased;

uniform mat4 worldToClip;
uniform float capScale;

void main()
{
  vec4 clip = worldToClip * vertexRebased;
  clip.z *= capScale;
  gl_Position = clip;
}
