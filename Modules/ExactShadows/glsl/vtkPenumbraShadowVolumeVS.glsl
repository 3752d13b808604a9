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
// pointW scales w: 1 for the xyzw streams and the mesh points; a positional light's w for its
// extruded copies, which the point tables keep as xyz (their w is that one value).
in vec4 vertexRebased;

uniform mat4 worldToClip;
uniform float capScale;
uniform float pointW;

void main()
{
  vec4 clip = worldToClip * vec4(vertexRebased.xyz, vertexRebased.w * pointW);
  clip.z *= capScale;
  gl_Position = clip;
}
