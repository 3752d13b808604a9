// A fragment's surface as the view samples record it (shared by the G-buffer of
// vtkPenumbraViewSamplesPass and the shadow lookups that run in the receivers' own shaders):
// the position relative to the rebasing origin in float32 and the facet normal turned toward
// the camera, both from vertexVC. One definition, so that a lookup made while shading sees
// exactly the sample the G-buffer holds. (GL_ARB_gpu_shader5 is enabled where VTK declares its
// version: vtkPenumbraViewSamplesPass::AddSurfaceDeclarations().)
uniform mat4 penumbraVCToRebased;   // view coordinates -> world minus origin (built in double)
uniform vec3 penumbraCameraRebased; // camera position, world minus origin
uniform int penumbraParallel;       // 1 for a parallel projection
uniform vec3 penumbraViewDirection; // direction of projection, world
uniform int penumbraSampleCount;          // samples per pixel of the framebuffer drawn into
uniform vec2 penumbraSampleOffsets[16];   // their offsets from the pixel centre, in pixels

// Where in the pixel this fragment's primitive is: the mean offset of the samples it covers
// (zero when it covers them all, or in a single-sampled framebuffer). A multisampled window
// shades a pixel its primitive covers only in part at the pixel centre, which can lie
// outside the primitive (beyond a plane's far edge, behind the other surface where two
// surfaces intersect); the covered samples lie inside it. (Centroid interpolation would say
// the same, but llvmpipe interpolates at the centre.)
vec2 penumbraCoveredOffset()
{
#ifdef GL_ARB_gpu_shader5
  int mask = gl_SampleMaskIn[0];
  int count = min(penumbraSampleCount, 16);
  if (count <= 1 || mask == (1 << count) - 1)
  {
    return vec2(0.0);
  }
  vec2 sum = vec2(0.0);
  float n = 0.0;
  for (int i = 0; i < count; ++i)
  {
    if ((mask & (1 << i)) != 0)
    {
      sum += penumbraSampleOffsets[i];
      n += 1.0;
    }
  }
  return n > 0.0 ? sum / n : vec2(0.0);
#else
  return vec2(0.0);
#endif
}

void penumbraSurface(vec4 vertexVC, out vec3 position, out vec3 normal)
{
  vec3 centre = (penumbraVCToRebased * vec4(vertexVC.xyz, 1.0)).xyz;
  // The facet normal from screen-space derivatives is the true plane of the triangle,
  // which is what decides whether light can reach it (not the shading normal).
  vec3 dx = dFdx(centre);
  vec3 dy = dFdy(centre);
  vec2 offset = penumbraCoveredOffset();
  position = centre + dx * offset.x + dy * offset.y;
  normal = normalize(cross(dx, dy));
  vec3 toEye = (penumbraParallel == 1) ? -penumbraViewDirection
                                       : (penumbraCameraRebased - position);
  if (dot(normal, toEye) < 0.0)
  {
    normal = -normal;
  }
}
