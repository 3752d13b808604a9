//VTK::System::Dec
// Dual-paraboloid shadow map, vertex stage (Brabec, "Shadow Techniques for Interactive and
// Real-Time Applications", PhD thesis, 2003, ch. 6). Vertices arrive relative to the
// light in the hemisphere's frame (+z = the hemisphere's axis), already clipped to z >= 0 and
// tessellated on the CPU, so the straight rasterized edges follow the curved images of the
// triangle edges closely and nothing near the z -> -1 singularity is ever mapped.
in vec3 vertexLight;
in vec4 trianglePlane; // n.x = c for points x relative to the light, n unit

uniform float mapScale; // paraboloid coordinates -> NDC

flat out vec4 planeVS;
out float distanceVS;

void main()
{
  float len = length(vertexLight);
  vec3 v = len > 0.0 ? vertexLight / len : vec3(0.0, 0.0, 1.0);
  vec2 xy = v.xy / (1.0 + max(v.z, 0.0));
  planeVS = trianglePlane;
  distanceVS = len;
  gl_Position = vec4(xy * mapScale, 0.0, 1.0);
}
