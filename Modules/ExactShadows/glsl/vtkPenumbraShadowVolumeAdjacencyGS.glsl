//VTK::System::Dec
// GPU silhouettes and extrusion in one geometry stage (Brabec, "Shadow Techniques for Interactive
// and Real-Time Applications", PhD thesis, 2003, ch. 9, done as one geometry shader with
// adjacency): each triangle of a closed, outward-oriented component arrives with its
// three neighbours' opposite vertices (GL_TRIANGLES_ADJACENCY). A light-facing triangle emits
// its light cap (pushed back by capScale, see the volume vertex stage), its dark cap, and a
// side quad for every edge whose neighbour is not light-facing.
//
// Facing must be one decision per face, shared by both invocations that look at it (so caps
// and sides agree): it is evaluated with the face rotated so that its smallest vertex index comes
// first, so both invocations run the same expression on the same inputs. Ties count as back-facing.
layout(triangles_adjacency) in;
layout(triangle_strip, max_vertices = 18) out;

in vec3 positionGS[];
flat in int indexGS[];

uniform mat4 worldToClip;
uniform float capScale;
// xyz: rebased light position (w = 1) or unit direction toward a directional light (w = 0).
uniform vec4 light;
// Prism length for directional lights (beyond every sample and caster).
uniform float extrusion;
// Positional lights: w of the extruded copy L + (v - L) / farW (PositionalFarW on the CPU).
uniform float farW;

float facing(vec3 a, vec3 b, vec3 c, int ia, int ib, int ic)
{
  vec3 t;
  if (ib < ia && ib < ic)
  {
    t = a; a = b; b = c; c = t;
  }
  else if (ic < ia && ic < ib)
  {
    t = c; c = b; b = a; a = t;
  }
  vec3 n = cross(b - a, c - a);
  return light.w == 0.0 ? dot(n, light.xyz) : dot(n, light.xyz - a);
}

vec4 extruded(vec3 v)
{
  return light.w == 0.0 ? vec4(v - extrusion * light.xyz, 1.0) : vec4(v - light.xyz + farW * light.xyz, farW);
}

void emit(vec4 p, float zScale)
{
  vec4 clip = worldToClip * p;
  clip.z *= zScale;
  gl_Position = clip;
  EmitVertex();
}

void side(vec3 u, vec3 w)
{
  emit(vec4(u, 1.0), 1.0);
  emit(extruded(u), 1.0);
  emit(vec4(w, 1.0), 1.0);
  emit(extruded(w), 1.0);
  EndPrimitive();
}

void main()
{
  vec3 v0 = positionGS[0], v1 = positionGS[2], v2 = positionGS[4];
  int i0 = indexGS[0], i1 = indexGS[2], i2 = indexGS[4];
  if (!(facing(v0, v1, v2, i0, i1, i2) > 0.0))
  {
    return;
  }
  emit(vec4(v0, 1.0), capScale);
  emit(vec4(v1, 1.0), capScale);
  emit(vec4(v2, 1.0), capScale);
  EndPrimitive();
  emit(extruded(v0), 1.0);
  emit(extruded(v2), 1.0);
  emit(extruded(v1), 1.0);
  EndPrimitive();
  // The neighbour across edge (u, w) is (w, u, opposite) in its own winding.
  if (!(facing(v1, v0, positionGS[1], i1, i0, indexGS[1]) > 0.0))
  {
    side(v0, v1);
  }
  if (!(facing(v2, v1, positionGS[3], i2, i1, indexGS[3]) > 0.0))
  {
    side(v1, v2);
  }
  if (!(facing(v0, v2, positionGS[5], i0, i2, indexGS[5]) > 0.0))
  {
    side(v2, v0);
  }
}
