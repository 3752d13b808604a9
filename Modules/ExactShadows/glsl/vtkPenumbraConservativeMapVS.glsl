//VTK::System::Dec
// Conservative shadow map, vertex stage (Hertel, Hormann, Westermann, "A Hybrid GPU Rendering
// Pipeline for Alias-Free Hard Shadows", Eurographics 2009 Areas Papers, §4.1): caster vertices in
// the geometry's rebased frame go to the light's clip space; the geometry stage does the rest.
in vec3 vertexRebased;

// Rebased world -> light clip space. Perspective views put the distance along the view axis
// in w; orthographic views put the linear depth in [0, 1] in z and 1 in w.
uniform mat4 lightMatrix;

out vec4 clipVS;

void main()
{
  clipVS = lightMatrix * vec4(vertexRebased, 1.0);
  gl_Position = clipVS;
}
