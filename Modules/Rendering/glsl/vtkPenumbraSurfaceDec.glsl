// A fragment's surface as the view samples record it (shared by the G-buffer of
// vtkPenumbraViewSamplesPass and the shadow lookups that run in the receivers' own shaders):
// the position relative to the rebasing origin in float32 and the facet normal turned toward
// the camera, both from vertexVC. One definition, so that a lookup made while shading sees
// exactly the sample the G-buffer holds.
uniform mat4 penumbraVCToRebased;   // view coordinates -> world minus origin (built in double)
uniform vec3 penumbraCameraRebased; // camera position, world minus origin
uniform int penumbraParallel;       // 1 for a parallel projection
uniform vec3 penumbraViewDirection; // direction of projection, world

void penumbraSurface(vec4 vertexVC, out vec3 position, out vec3 normal)
{
  position = (penumbraVCToRebased * vec4(vertexVC.xyz, 1.0)).xyz;
  // The facet normal from screen-space derivatives is the true plane of the triangle,
  // which is what decides whether light can reach it (not the shading normal).
  normal = normalize(cross(dFdx(position), dFdy(position)));
  vec3 toEye = (penumbraParallel == 1) ? -penumbraViewDirection
                                       : (penumbraCameraRebased - position);
  if (dot(normal, toEye) < 0.0)
  {
    normal = -normal;
  }
}
