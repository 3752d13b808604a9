/**
 * @file    vtkPenumbraLightViews.h
 * @brief   A light as the map-based techniques see it from the view samples: the light
 *          reduced to the reference's conventions, the frame's inputs, the per-sample facing
 *          / cone pass, the light cameras fitted to the samples, the samples' shadow rays and
 *          the light's uniforms. The casters are in vtkPenumbraCasterBuffers.h, the GL state
 *          of the techniques' passes in vtkPenumbraGLPassState.h.
 *
 * Not wrapped and not installed: both techniques must make the same decisions as
 * vtkPenumbraReference for facing-away samples and spot cones, so that their errors measure
 * only what the shadow map itself gets wrong; keeping that code in one place keeps them
 * agreeing.
 */

#ifndef vtkPenumbraLightViews_h
#define vtkPenumbraLightViews_h

#include "vtkPenumbraSceneTriangles.h"  // For penumbra::SceneTriangles
#include "vtkPenumbraVisibilityRules.h" // For penumbra_rules::Hit
#include "vtkType.h"
#include "vtk_glew.h"

#include <string>
#include <vector>

class vtkFloatArray;
class vtkLight;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkPenumbraViewSamples;
class vtkShaderProgram;

namespace penumbra_light_views
{
/**
 * One light camera. Rows map the geometry's rebased frame to the clip space the vertex stage
 * produces: orthographic views give (s, t, linear depth, 1), perspective ones
 * (s * w, t * w, 0, w) with w the distance along the view axis.
 */
struct View
{
  bool Perspective = false;
  double Row[4][4] = {};
  double Far = 1.0;     // perspective: stored depth = w / Far
  double NearW = 0.0;   // perspective: apex region the conservative geometry stage handles
  double TanHalf = 1.0; // perspective: tangent of the half field of view

  double Dot(int r, const double p[3]) const
  {
    return this->Row[r][0] * p[0] + this->Row[r][1] * p[1] + this->Row[r][2] * p[2] +
      this->Row[r][3];
  }

  /**
   * Map coordinates in [-1, 1] and the stored-depth value of a point; false when the point
   * is not in front of a perspective view.
   */
  bool Project(const double p[3], double& s, double& t, double& depth) const;

  /** Column-major float copy of Row, for a GLSL mat4 uniform. */
  void ToFloatMatrix(float matrix[16]) const;
};

/** An orthonormal right/up pair for a forward axis. */
void Basis(const double f[3], double r[3], double u[3]);

/** A perspective view from `apex` along unit `f`; Far reaches the farthest corner of `box`. */
View PerspectiveView(const double apex[3], const double f[3], double tanHalf, const double box[6]);

/** An orthographic view travelling along unit `f` that encloses `box` (slightly padded). */
View OrthographicView(const double f[3], const double box[6]);

/**
 * A light reduced exactly as vtkPenumbraReference reduces it (same expressions, so facing
 * and cone decisions are bit for bit the reference's). Positions are in the geometry's
 * rebased frame.
 */
struct LightSetup
{
  enum class Kind
  {
    Directional,
    Point,
    Spot
  };
  Kind Type = Kind::Point;
  double Direction[3] = { 0, 0, 0 }; // directional: unit vector towards the light
  double Position[3] = { 0, 0, 0 };  // positional: rebased position
  double Axis[3] = { 0, 0, 0 };      // spot: unit axis away from the light
  double CosCone = -1.0;
  // Area and linear lights (read as a spot at their centre): half extents along U and V
  // (V zero for a line); the facing rule is then "any part above the tangent plane".
  bool Area = false;
  double HalfU[3] = { 0, 0, 0 };
  double HalfV[3] = { 0, 0, 0 };
  double Cone = 180.0; // degrees, VTK's half-angle
  bool Off = false;    // switched off or zero intensity: lit everywhere, no map

  /** Reads `light`; false with `error` set for non-finite or degenerate lights. */
  bool Read(vtkLight* light, const double geometryOrigin[3], std::string& error);
};

/**
 * One call's checked inputs: the sample arrays (raw pointers, valid while the samples
 * live), the scene triangles, the frames' origins and the light.
 */
struct FrameInputs
{
  vtkIdType NumberOfSamples = 0;
  const float* Positions = nullptr; // relative to the samples' origin
  const float* Normals = nullptr;
  const int* Props = nullptr;
  const vtkIdType* Triangles = nullptr;
  vtkIdType NumberOfTriangles = 0;
  const penumbra::SceneTriangles* SceneTriangles = nullptr; // the geometry's (GetTriangles())
  double GeometryOrigin[3] = { 0, 0, 0 };
  double Shift[3] = { 0, 0, 0 }; // samples' frame -> geometry's frame
  LightSetup Light;
  vtkOpenGLRenderWindow* Window = nullptr;

  /**
   * Checks every input of a map-based technique's ComputeVisibility: all present, an OpenGL
   * window, a hard light (area and linear lights need other techniques, unless `allowArea`:
   * then Light holds an area light read as a plain positional vtkLight, for its switch and
   * intensity), arrays that exist and agree in size, finite origins, a usable light. False
   * with `error` set otherwise (nothing is written).
   */
  bool Read(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility, std::string& error,
    bool allowArea = false);

  /// Whether caster triangle `t` never blocks sample `s` (penumbra_rules::IsOwnCaster).
  bool OwnCaster(vtkIdType t, vtkIdType s) const
  {
    // A sample of unknown triangle excludes nothing; a drawn triangle owns itself (the usual
    // case, answered without looking the owner up).
    const vtkIdType own = this->Triangles[s];
    return own >= 0 &&
      (own == t || penumbra_rules::IsOwnCaster(this->SceneTriangles->GetOwner(t), own));
  }

  /// Triangle `t`'s corners in the geometry's frame (rebased, double).
  void Triangle(vtkIdType t, double v[9]) const { this->SceneTriangles->Get(t, v); }
};

/**
 * Per-sample pass shared by the techniques: background -> -1; light off -> 1; facing away
 * or outside a spot cone -> 0 (the reference's rule); no casters -> 1; otherwise
 * `pending[s] = 1` and visibility 1 until a map says otherwise. `shift` moves sample
 * positions into the geometry's frame. `pendingList` (optional) receives the pending
 * samples, ascending, listed by the same parallel pass instead of a later serial scan.
 */
struct FacingCounts
{
  vtkIdType Lit = 0;
  vtkIdType Shadowed = 0;
  vtkIdType Pending = 0;
};
FacingCounts ClassifyFacing(const LightSetup& light, vtkIdType n, const float* pos,
  const float* nrm, const int* props, const double shift[3], bool anyCaster, float* vis,
  unsigned char* pending, unsigned char pendingValue, unsigned char decidedValue,
  std::vector<vtkIdType>* pendingList = nullptr);

/**
 * A box kept across frames so that what is fitted to it outlives small changes of the box it
 * must hold (a camera that moves a little). Anything fitted to a box that holds the samples
 * is as valid for them as what is fitted to their own box: light views cover them, culled
 * volumes reach them. Hold(box) keeps the current box while it Serves `box`, else replaces it
 * by `box` grown on every side by Margin times its largest side.
 */
struct KeptBox
{
  double Margin = 0.0;
  double Box[6] = { 0, 0, 0, 0, 0, 0 };
  bool Valid = false;

  /**
   * Whether `kept` (grown by `margin`) may stand for `box`: it holds `box`, and is not so much
   * larger (after a zoom in) that its largest side exceeds (1 + 4 margin) times box's.
   */
  static bool Serves(const double kept[6], const double box[6], double margin);
  /** `box` grown on every side by `margin` times its largest side. */
  static void Grow(const double box[6], double margin, double grown[6]);
  /** The kept box after making it serve `box`. */
  const double* Hold(const double box[6]);
};

/**
 * The light cameras that cover the samples with `state[s] == pendingValue`: directional
 * lights one orthographic view along the light fitted to their box; spot lights with a cone
 * of at most 60 degrees one perspective view circumscribing the cone (a degree to spare);
 * wider spots and point lights six 90-degree cube faces. `sampleView[s]` receives the view
 * of each such sample (its dominant axis for cube faces), -1 for the others. A shadow ray
 * projects to its own sample's map point, so views fitted to the samples lose no caster that
 * could block one of them. No views when no sample is pending. `pending`, when given, lists
 * exactly those samples, so the state of the others is not scanned. With `kept` the views
 * are fitted to the kept box made to hold the samples' box (KeptBox::Hold), so they stay the
 * same while the samples move a little.
 */
void FitViews(const LightSetup& light, vtkIdType n, const float* pos, const double shift[3],
  const unsigned char* state, unsigned char pendingValue, std::vector<View>& views,
  std::vector<signed char>& sampleView, const std::vector<vtkIdType>* pending = nullptr,
  KeptBox* kept = nullptr);

/**
 * A view sample's shadow ray as vtkPenumbraReference casts it: origin P (rebased), unit
 * direction D towards the light, end TMax (infinite for directional lights), the tie band's
 * limit and the rounding margin ErrPos of penumbra_rules::SegmentTest. Ok is false for a
 * sample on a positional light (no direction).
 */
struct ShadowRay
{
  double P[3];
  double D[3];
  double TMax;
  double TieLimit;
  double ErrPos;
  bool Ok;
};
ShadowRay MakeShadowRay(
  const LightSetup& light, const double p[3], double diagonal, double epsilon, double tieFactor);

/**
 * penumbra_rules::SegmentTest of `ray` against `triangle`, with a ray on an edge (OnEdge)
 * left to the tracer (Unknown): only Clear may shadow a sample, only Miss may leave it lit.
 */
penumbra_rules::Hit TestShadowRay(
  const ShadowRay& ray, const penumbra_rules::ExactTriangle& triangle);

/**
 * The same against triangle `id` (9 rebased coordinates at `tri`); a triangle without area
 * after rounding is left to the tracer too (Unknown).
 */
penumbra_rules::Hit TestShadowRay(const ShadowRay& ray, const double* tri, vtkIdType id);

/**
 * The uniforms of the per-sample facing rules (vtkPenumbraShadowMapClassify.glsl) from the
 * light exactly as the reference reduces it: directions, position and cone in double.
 */
void SetClassifyUniforms(
  vtkShaderProgram* program, const LightSetup& setup, const std::string& suffix = "");

/**
 * The float uniforms of the lookups' slope bias: `lightPosition` (rebased) and
 * `toLightDirection` (directional lights: unit vector towards the light).
 */
void SetLightUniforms(
  vtkShaderProgram* program, const LightSetup& setup, const std::string& suffix = "");

/**
 * `source` (GLSL declarations) with `suffix` appended to every name it declares at global
 * scope (uniforms, constants, functions; not `penumbraSurface` and `main`), wherever the name
 * appears: several copies of one snippet, one per light, can then live in one shader.
 */
std::string SuffixGlobals(const std::string& source, const std::string& suffix);

/**
 * The entry of `light` in a per-light cache whose entries (T) hold a vtkWeakPointer<vtkLight>
 * named Light: its existing entry, else the entry of a deleted light, else a new one; an
 * entry taken over or created is reset to T() first.
 */
template <class T>
T& LightCacheEntry(std::vector<T>& cache, vtkLight* light)
{
  T* entry = nullptr;
  for (auto& e : cache)
  {
    entry = e.Light == light ? &e : entry;
  }
  for (auto& e : cache)
  {
    entry = (!entry && !e.Light) ? &e : entry;
  }
  if (!entry)
  {
    cache.emplace_back();
    entry = &cache.back();
  }
  if (entry->Light != light)
  {
    *entry = T();
    entry->Light = light;
  }
  return *entry;
}
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraLightViews.h
