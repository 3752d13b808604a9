//VTK::System::Dec
//VTK::Output::Dec
// Resolution estimate of RESM (Ferko 2013, "resolution estimation shadow mapping"): for
// every sample that can be lit (surface, facing the light, inside a spot cone), the
// Jacobian J of its map coordinates (NDC of the fitted light view) with respect to screen
// pixels, from its right/upper (else left/lower) neighbour on the same plane; a texel must
// project back onto at most one pixel, which needs 2 sqrt(a_t^2 + b_t^2) / |det J| texels
// across the map along s and 2 sqrt(a_s^2 + b_s^2) / |det J| along t (J = [a b], columns:
// d(s,t)/dx, d(s,t)/dy). Each fragment reduces a tile x tile block to the largest need of
// the samples on every `step`-th row and column (the analysis at a lower resolution, as
// Brabec et al. 2000 fit theirs; the neighbours stay the adjacent pixels).
// The CPU twin is EstimateSamples() in vtkPenumbraShadowMapFit.cxx.
// Out 0: largest need along s, along t, number of estimated samples, 0.
in vec2 texCoord;

uniform mat4 lightMatrix;
uniform int perspective;
uniform int lightKind;        // 0 directional, 1 point, 2 spot
uniform vec3 estimateDirection; // directional: unit vector towards the light
uniform vec3 estimatePosition;  // positional: rebased
uniform vec3 estimateAxis;      // spot: unit axis away from the light
uniform float estimateCosCone;
uniform int step;              // analyse every step-th sample per axis

//PENUMBRA::TileSample

vec2 penumbraMapCoordinates(vec3 p)
{
  vec4 clip = lightMatrix * vec4(p, 1.0);
  return perspective != 0 ? clip.xy / clip.w : clip.xy;
}

bool penumbraCanBeLit(vec3 p, vec3 n)
{
  vec3 toLight = lightKind == 0 ? estimateDirection : estimatePosition - p;
  if (dot(n, toLight) <= 0.0)
  {
    return false;
  }
  return lightKind != 2 || dot(normalize(-toLight), estimateAxis) >= estimateCosCone;
}

// The step of the map coordinates for one pixel along `axis`, from a neighbour on the
// sample's own plane (same prop, within 1e-3 of the step's length of the plane).
bool penumbraStep(ivec2 cell, ivec2 axis, vec3 p, vec3 n, float prop, vec2 st, out vec2 step)
{
  step = vec2(0.0);
  for (int side = 1; side >= -1; side -= 2)
  {
    vec3 q;
    vec3 m;
    float qProp;
    if (penumbraSampleAt(cell + side * axis, q, m, qProp) && qProp == prop)
    {
      vec3 d = q - p;
      if (abs(dot(n, d)) <= 1e-3 * length(n) * length(d) && dot(d, d) > 0.0)
      {
        step = float(side) * (penumbraMapCoordinates(q) - st);
        return true;
      }
    }
  }
  return false;
}

void main()
{
  vec2 need = vec2(0.0);
  int count = 0;
  for (int j = 0; j < tile; j += step)
  {
    for (int i = 0; i < tile; i += step)
    {
      ivec2 cell = ivec2(gl_FragCoord.xy) * tile + ivec2(i, j);
      vec3 p;
      vec3 n;
      float prop;
      if (!penumbraSampleAt(cell, p, n, prop) || !penumbraCanBeLit(p, n))
      {
        continue;
      }
      vec2 st = penumbraMapCoordinates(p);
      vec2 a;
      vec2 b;
      if (!penumbraStep(cell, ivec2(1, 0), p, n, prop, st, a) ||
        !penumbraStep(cell, ivec2(0, 1), p, n, prop, st, b))
      {
        continue;
      }
      float det = abs(a.x * b.y - b.x * a.y);
      if (!(det > 0.0))
      {
        continue;
      }
      ++count;
      need = max(need, 2.0 * vec2(length(vec2(a.y, b.y)), length(vec2(a.x, b.x))) / det);
    }
  }
  if (texCoord.x < -1.0)
  {
    count = 0; // never true; keeps the quad's texture coordinates in the program
  }
  gl_FragData[0] = vec4(need, float(count), 0.0);
  gl_FragData[1] = vec4(0.0);
  gl_FragData[2] = vec4(0.0);
  gl_FragData[3] = vec4(0.0);
}
