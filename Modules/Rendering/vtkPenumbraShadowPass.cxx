#include "vtkPenumbraShadowPass.h"

#include "vtkCameraPass.h"
#include "vtkDepthPeelingPass.h"
#include "vtkImageProcessingPass.h"
#include "vtkOrderIndependentTranslucentPass.h"
#include "vtkHardwareSelector.h"
#include "vtkRenderStepsPass.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCollection.h"
#include "vtkCompositePolyDataMapper2.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkLightsPass.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpaquePass.h"
#include "vtkOpenGLPolyDataMapper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkOverlayPass.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraMapperDraws.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkProp.h"
#include "vtkProperty.h"
#include "vtkRenderPassCollection.h"
#include "vtkRenderState.h"
#include "vtkRenderer.h"
#include "vtkSequencePass.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkTimerLog.h"
#include "vtkTranslucentPass.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumetricPass.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include <cfloat>
#include <limits>

#include "vtkPenumbraVisibilityDec.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace
{
double Now()
{
  return vtkTimerLog::GetUniversalTime();
}

// Stands where VTK's vtkShadowMapBakerPass stands in existing pipelines; see
// GetShadowMapBakerPass().
class NoBakingPass : public vtkRenderPass
{
public:
  static NoBakingPass* New();
  vtkTypeMacro(NoBakingPass, vtkRenderPass);
  void Render(const vtkRenderState*) override { this->NumberOfRenderedProps = 0; }

protected:
  NoBakingPass() = default;
  ~NoBakingPass() override = default;
};
vtkStandardNewMacro(NoBakingPass);

// The renderer's own drawing, as vtkOpenGLRenderer::DeviceRender does it without a pass
// (inside the camera pass that stands before it): lights, then UpdateGeometry(), which
// draws opaque props (with hidden-line removal or SSAO when the renderer asks),
// translucent ones (order-independent transparency or depth peeling as set), FXAA, volumes
// and overlays. So a shadowed scene is drawn exactly as plain VTK draws it.
class RendererDrawingPass : public vtkRenderPass
{
public:
  static RendererDrawingPass* New();
  vtkTypeMacro(RendererDrawingPass, vtkRenderPass);
  void Render(const vtkRenderState* s) override
  {
    vtkRenderer* ren = s->GetRenderer();
    this->UpdateLightGeometry(ren);
    this->UpdateLights(ren);
    this->UpdateGeometry(ren, s->GetFrameBuffer());
    this->NumberOfRenderedProps = ren->GetNumberOfPropsRendered();
  }

protected:
  RendererDrawingPass() = default;
  ~RendererDrawingPass() override = default;
};
vtkStandardNewMacro(RendererDrawingPass);

int CountLightsOn(vtkRenderer* ren)
{
  int count = 0;
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  while (vtkLight* light = lights->GetNextLight(it))
  {
    count += light->GetSwitch() ? 1 : 0;
  }
  return count;
}

// The first vtkPenumbraShadowPass in a composition of VTK's passes (camera, sequence,
// render steps, image processing, translucency passes), or nullptr.
vtkPenumbraShadowPass* FindShadowPass(vtkRenderPass* pass, int depth = 0)
{
  if (!pass || depth > 16)
  {
    return nullptr;
  }
  if (auto* shadows = vtkPenumbraShadowPass::SafeDownCast(pass))
  {
    return shadows;
  }
  std::vector<vtkRenderPass*> inner;
  if (auto* camera = vtkCameraPass::SafeDownCast(pass))
  {
    inner.push_back(camera->GetDelegatePass());
  }
  else if (auto* sequence = vtkSequencePass::SafeDownCast(pass))
  {
    vtkRenderPassCollection* passes = sequence->GetPasses();
    passes->InitTraversal();
    while (vtkRenderPass* p = passes ? passes->GetNextRenderPass() : nullptr)
    {
      inner.push_back(p);
    }
  }
  else if (auto* processing = vtkImageProcessingPass::SafeDownCast(pass))
  {
    inner.push_back(processing->GetDelegatePass());
  }
  else if (auto* steps = vtkRenderStepsPass::SafeDownCast(pass))
  {
    inner = { steps->GetCameraPass(), steps->GetLightsPass(), steps->GetOpaquePass(),
      steps->GetTranslucentPass(), steps->GetVolumetricPass(), steps->GetOverlayPass(),
      steps->GetPostProcessPass() };
  }
  else if (auto* oit = vtkOrderIndependentTranslucentPass::SafeDownCast(pass))
  {
    inner.push_back(oit->GetTranslucentPass());
  }
  else if (auto* peeling = vtkDepthPeelingPass::SafeDownCast(pass))
  {
    inner.push_back(peeling->GetTranslucentPass());
  }
  for (vtkRenderPass* p : inner)
  {
    if (vtkPenumbraShadowPass* found = FindShadowPass(p, depth + 1))
    {
      return found;
    }
  }
  return nullptr;
}

// What VTK draws in its translucent pass, for a receiver: the props whose nearest
// translucent surface gets its own view samples and visibility.
bool IsTranslucentReceiver(vtkProp* prop)
{
  auto* actor = vtkActor::SafeDownCast(prop);
  return actor && actor->GetVisibility() && actor->HasTranslucentPolygonalGeometry() &&
    vtkPenumbraShadowKeys::ReceivesShadows(prop);
}

// "directional", "spot", "point", "area 4x4", "linear 8": how explanations name a light.
std::string LightKind(vtkLight* light)
{
  if (auto* area = vtkPenumbraAreaLight::SafeDownCast(light))
  {
    const int k = area->GetSamplesPerAxis();
    return area->GetShape() == vtkPenumbraAreaLight::Line
      ? "linear light, " + std::to_string(k) + " samples"
      : "area light, " + std::to_string(k) + "x" + std::to_string(k) + " samples";
  }
  if (!light->GetPositional())
  {
    return "directional light";
  }
  return light->GetConeAngle() < 90.0 ? "spot light" : "point light";
}

// Why `light` needs no shadow work for any of `samples`, or "" when some valid sample may be
// lit by it. The rules are the exact reference's (vtkPenumbraReference): a sample whose
// normal faces away from the light (N.L <= 0; for an area or linear light, from every point
// of the emitter, tested at its corners, which bound the light samples) and a sample outside
// a spot light's cone get visibility 0 without a ray, and VTK's own shading gives them no
// light from it either, so when that holds for every visible sample nothing needs shadowing.
// Whether the ray from p towards a directional light (`toLight`, `toPoint` null) or the
// segment from p to a positional light `toPoint` meets the box (slab test).
bool RayMeetsBox(
  const double p[3], const double toLight[3], const double* toPoint, const double box[6])
{
  double t0 = 0.0, t1 = toPoint ? 1.0 : std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
  {
    const double d = toPoint ? toPoint[a] - p[a] : toLight[a];
    if (d == 0.0)
    {
      if (p[a] < box[2 * a] || p[a] > box[2 * a + 1])
      {
        return false;
      }
      continue;
    }
    double ta = (box[2 * a] - p[a]) / d, tb = (box[2 * a + 1] - p[a]) / d;
    if (ta > tb)
    {
      std::swap(ta, tb);
    }
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1)
    {
      return false;
    }
  }
  return true;
}

// Why a light needs no shadow work this frame, or "" when it may shadow a visible sample:
// no visible surface, every visible sample faces away or lies outside the cone, or (hard
// lights) no visible sample's ray to the light meets the casters' box (world coordinates,
// padded; null: no casters at all). `witness`: a sample found shadowable by an earlier call
// (tested first; -1 when none), set to the one found now.
std::string NothingToShadow(vtkLight* light, vtkPenumbraViewSamples* samples,
  const double* casterBox, const double* sampleBox, vtkIdType& witness)
{
  double pos[3], focal[3];
  light->GetTransformedPosition(pos);
  light->GetTransformedFocalPoint(focal);
  double axis[3] = { focal[0] - pos[0], focal[1] - pos[1], focal[2] - pos[2] };
  const double axisLength = vtkMath::Normalize(axis);
  std::vector<std::array<double, 3>> points; // positional emitter points (corners)
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  double u[3], v[3], n[3];
  if (area && area->GetAxes(u, v, n))
  {
    area->GetCentre(pos);
    const double hw = 0.5 * area->GetWidth();
    const double hh =
      area->GetShape() == vtkPenumbraAreaLight::Line ? 0.0 : 0.5 * area->GetHeight();
    for (double a : { -hw, hw })
    {
      for (double b : { -hh, hh })
      {
        points.push_back({ pos[0] + a * u[0] + b * v[0], pos[1] + a * u[1] + b * v[1],
          pos[2] + a * u[2] + b * v[2] });
      }
    }
  }
  else if (light->GetPositional())
  {
    points.push_back({ pos[0], pos[1], pos[2] });
  }
  const bool spot =
    !area && light->GetPositional() && light->GetConeAngle() < 90.0 && axisLength > 0;
  const double cosCone = std::cos(vtkMath::RadiansFromDegrees(light->GetConeAngle()));
  // A directional light shines along the axis from the position toward the focal point.
  const double toLight[3] = { -axis[0], -axis[1], -axis[2] };
  const float* normals = samples->GetNormals()->GetPointer(0);
  bool anyValid = false, anyInCone = false, anyLit = false;
  // Hard lights: a lit sample matters only if its ray to the light can meet a caster.
  const bool hard = points.size() <= 1;
  if (hard && casterBox && sampleBox)
  {
    // All the visible samples' rays at once: for a directional light, p + t L meets the
    // casters' box C for some p in the samples' box S iff t L meets C - S (a box); for a
    // positional light every segment lies in the box around S and the light.
    double box[6];
    for (int a = 0; a < 3; ++a)
    {
      box[2 * a] = points.empty() ? casterBox[2 * a] - sampleBox[2 * a + 1]
                                  : std::min(sampleBox[2 * a], points[0][a]);
      box[2 * a + 1] = points.empty() ? casterBox[2 * a + 1] - sampleBox[2 * a]
                                      : std::max(sampleBox[2 * a + 1], points[0][a]);
    }
    const double zero[3] = { 0, 0, 0 };
    const bool apart = points.empty()
      ? !RayMeetsBox(zero, toLight, nullptr, box)
      : (box[0] > casterBox[1] || box[1] < casterBox[0] || box[2] > casterBox[3] ||
          box[3] < casterBox[2] || box[4] > casterBox[5] || box[5] < casterBox[4]);
    if (apart)
    {
      return "no caster lies between it and any visible surface";
    }
  }
  auto mayBeShadowed = [&](const double p[3])
  {
    anyLit = true;
    return hard && casterBox &&
      RayMeetsBox(p, toLight, points.empty() ? nullptr : points[0].data(), casterBox);
  };
  // The arrays read directly (this scan runs per light and frame), as far as all are long.
  const int* props = samples->GetPropIndices()->GetPointer(0);
  const float* positions = samples->GetPositions()->GetPointer(0);
  double origin[3];
  samples->GetOrigin(origin);
  const vtkIdType count =
    std::min({ samples->GetNumberOfSamples(), samples->GetPropIndices()->GetNumberOfTuples(),
      samples->GetPositions()->GetNumberOfTuples(), samples->GetNormals()->GetNumberOfTuples() });
  // Whether sample i may be shadowed by the light (it is a witness that the light needs
  // shadow work).
  auto shadowable = [&](vtkIdType i)
  {
    if (props[i] < 0)
    {
      return false;
    }
    const double p[3] = { positions[3 * i] + origin[0], positions[3 * i + 1] + origin[1],
      positions[3 * i + 2] + origin[2] };
    anyValid = true;
    const float* nrm = normals + 3 * i;
    if (points.empty())
    {
      return nrm[0] * toLight[0] + nrm[1] * toLight[1] + nrm[2] * toLight[2] > 0.0 &&
        mayBeShadowed(p);
    }
    if (spot)
    {
      double d[3] = { p[0] - pos[0], p[1] - pos[1], p[2] - pos[2] };
      const double len = vtkMath::Norm(d);
      if (len > 0 && vtkMath::Dot(d, axis) < cosCone * len)
      {
        return false; // outside the cone
      }
      anyInCone = true;
    }
    for (const auto& q : points)
    {
      if (nrm[0] * (q[0] - p[0]) + nrm[1] * (q[1] - p[1]) + nrm[2] * (q[2] - p[2]) > 0.0)
      {
        return !hard || mayBeShadowed(p);
      }
    }
    return false;
  };
  // The last frame's witness first: one sample that may be shadowed is the whole answer,
  // and in a still or slowly changing frame it still is one; else the scan (up to every
  // sample: 3 ms a frame on the isosurface bench scene, whose spot light finds its first
  // witness late in pixel order).
  if (witness >= 0 && witness < count && shadowable(witness))
  {
    return "";
  }
  for (vtkIdType i = 0; i < count; ++i)
  {
    if (shadowable(i))
    {
      witness = i;
      return "";
    }
  }
  witness = -1;
  if (!anyValid)
  {
    return "no surface is visible";
  }
  if (anyLit)
  {
    return casterBox ? "no caster lies between it and any visible sample it lights"
                     : "nothing casts shadows";
  }
  return spot && !anyInCone ? "every visible sample lies outside its cone"
                            : "every visible sample faces away from it";
}

// Texture units left to VTK's own textures (colour, normal, PBR maps ...) in a receiver's
// shader; the rest can hold shadowed lights' visibility.
constexpr int ReservedTextureUnits = 8;

// Shader tags of the two sample layers and the prefixes of their visibility samplers.
// The suffix of light i's shader-lookup names in a receiver's shader.
std::string LookupSuffix(size_t i)
{
  return "_L" + std::to_string(i);
}

// Where the receivers' shader lookups run: just before VTK's lighting code.
const char* const ReceiveTag = "//PENUMBRA::Receive::Impl";

// Where the receivers' fragment surface is computed: VTK's uniform control flow.
const char* const SurfaceTag = "//PENUMBRA::Receive::Surface";

const char* const LayerTags[2] = { "//PENUMBRA::Visibility::Dec",
  "//PENUMBRA::TranslucentVisibility::Dec" };
const char* const LayerSamplers[2] = { "penumbraVisibility", "penumbraTranslucentVisibility" };
}

struct vtkPenumbraShadowPass::Internals
{
  vtkSmartPointer<vtkPenumbraShadowTechnique> Technique;
  // The renderer's own drawing (RendererDrawingPass), the delegate unless one is set.
  vtkSmartPointer<vtkRenderPass> DefaultDelegate = vtkSmartPointer<RendererDrawingPass>::New();
  vtkSmartPointer<vtkRenderPass> Delegate;
  vtkSmartPointer<vtkRenderPass> Baker = vtkSmartPointer<NoBakingPass>::New();
  vtkSmartPointer<vtkPenumbraSceneGeometry> Geometry =
    vtkSmartPointer<vtkPenumbraSceneGeometry>::New();
  vtkSmartPointer<vtkPenumbraViewSamplesPass> SamplesPass =
    vtkSmartPointer<vtkPenumbraViewSamplesPass>::New();
  // Nearest translucent surface per pixel, sampled only when translucent receivers exist.
  vtkSmartPointer<vtkPenumbraViewSamplesPass> TranslucentSamplesPass;
  vtkSmartPointer<vtkPenumbraFrame> Frame = vtkSmartPointer<vtkPenumbraFrame>::New();
  bool HasTranslucentLayer = false;
  bool HasFrame = false; // Frame holds a frame rendered with shadows

  std::vector<vtkSmartPointer<vtkLight>> Lights; // switched-on, shader order
  int LightsOff = 0;                             // switched-off lights of the renderer

  // The technique for lights the pass's technique cannot shadow (SetFallbackTechnique()).
  vtkSmartPointer<vtkPenumbraShadowTechnique> Fallback;
  // Lights already told they are shadowed by the fallback (said once, not every frame).
  std::set<std::pair<vtkLight*, vtkPenumbraShadowTechnique*>> Warned;

  // Per light of the last computed frame: the technique that shadowed it and why, or why it
  // got no shadow work (GetExplanation()).
  struct Report
  {
    vtkSmartPointer<vtkPenumbraShadowTechnique> Technique;
    std::string Why, Skipped;
  };
  std::vector<Report> Reports;
  int NumberOfSkipped = 0;
  std::vector<vtkIdType> Witness; // per light: its last shadowable sample (NothingToShadow)

  // Per light: how the shaders scale its colour (empty: no light is shadowed): "" not at
  // all, "texture" by its visibility texture, else by its shader lookup of this key (see
  // vtkPenumbraFrame::ShaderLookup). Shader code depends on it.
  std::vector<std::string> Injected;
  vtkTimeStamp ShaderTime;

  // What the last frame's view samples (ViewKey()) and its visibility (ViewKey() and
  // LightsKey()) depended on: equal keys reuse them.
  std::vector<double> LastViewKey, LastLightsKey;
  bool LastReused = false;
  int LastSkipped = 0; // lights over the texture-unit budget in the last computed frame
  bool LastSampled = false;

  double ExtractionMs = 0, SamplesMs = 0, TechniqueMs = 0, ShadingMs = 0;

  void SetInjected(std::vector<std::string> injected)
  {
    if (injected != this->Injected)
    {
      this->Injected.swap(injected);
      this->ShaderTime.Modified();
    }
  }

  static bool CastsLight(vtkLight* light) { return penumbra_rules::LightEmits(light); }

  // Light i's shader lookup when the receivers' shaders make it (see Injected).
  vtkPenumbraFrame::ShaderLookup* InjectedLookup(size_t i) const
  {
    return i < this->Injected.size() && this->Injected[i].compare(0, 7, "lookup:") == 0
      ? this->Frame->GetShaderLookup(static_cast<int>(i))
      : nullptr;
  }

  // A reused frame (nothing changed) reads visibility textures: the shader lookups are
  // written into them once (the same values), so that repeated frames cost a texture read
  // per fragment instead of a lookup.
  void BakeShaderLookups()
  {
    std::vector<std::string> injected = this->Injected;
    for (size_t i = 0; i < injected.size(); ++i)
    {
      if (this->InjectedLookup(i) && this->Frame->GetVisibilityTexture(0, static_cast<int>(i)))
      {
        injected[i] = "texture";
      }
    }
    this->SetInjected(injected);
  }

  void CollectLights(vtkRenderer* ren);
  std::vector<double> ViewKey(const vtkRenderState* s, vtkPenumbraShadowPass* pass);
  std::vector<double> LightsKey();
  void RenderSamples(const vtkRenderState* s);
  // A new view: what a frame needs of it before any sample exists (whether translucent
  // receivers make a second layer, the camera for the receivers' shader lookups, and the
  // props to render the samples with when they are first asked for).
  void PrepareSamples(const vtkRenderState* s);
  void RenderPreparedSamples();
  vtkWeakPointer<vtkRenderer> SampleRenderer;
  std::vector<vtkSmartPointer<vtkProp>> SampleProps;
  void ComputeVisibility(vtkPenumbraShadowPass* pass);
  vtkPenumbraShadowTechnique* Choose(vtkPenumbraShadowPass* pass, size_t i);
  void SkipUnreachedLights(bool readsSamples);

  // The casters' bounding box in world coordinates, padded for rounding; null without
  // casters. Kept while the geometry and its flags are unchanged.
  std::array<double, 6> Casters{};
  bool HasCasters = false;
  std::vector<double> CastersKey;
  const double* CasterBox()
  {
    const std::vector<double> key = { static_cast<double>(this->Geometry->GetGeometryTime()),
      static_cast<double>(this->Geometry->GetFlagsTime()) };
    if (key != this->CastersKey)
    {
      this->CastersKey = key;
      this->HasCasters = false;
      double lo[3] = { DBL_MAX, DBL_MAX, DBL_MAX }, hi[3] = { -DBL_MAX, -DBL_MAX, -DBL_MAX };
      vtkDoubleArray* vertices = this->Geometry->GetVertices();
      const vtkIdType n = vertices ? this->Geometry->GetNumberOfTriangles() : 0;
      for (vtkIdType t = 0; t < n; ++t)
      {
        if (!this->Geometry->IsOccluder(t))
        {
          continue;
        }
        this->HasCasters = true;
        const double* v = vertices->GetPointer(9 * t);
        for (int c = 0; c < 9; ++c)
        {
          lo[c % 3] = std::min(lo[c % 3], v[c]);
          hi[c % 3] = std::max(hi[c % 3], v[c]);
        }
      }
      double origin[3];
      this->Geometry->GetOrigin(origin);
      double scale = 0.0;
      for (int a = 0; a < 3; ++a)
      {
        scale = std::max(
          { scale, std::abs(lo[a] + origin[a]), std::abs(hi[a] + origin[a]), hi[a] - lo[a] });
      }
      const double pad = 1e-6 * scale;
      for (int a = 0; a < 3 && this->HasCasters; ++a)
      {
        this->Casters[2 * a] = lo[a] + origin[a] - pad;
        this->Casters[2 * a + 1] = hi[a] + origin[a] + pad;
      }
    }
    return this->HasCasters ? this->Casters.data() : nullptr;
  }

  // Props drawn that cast nothing or less than they draw (the geometry's casting notes),
  // said once per prop, note and technique.
  std::set<std::tuple<vtkProp*, std::string, vtkPenumbraShadowTechnique*>> Noted;
  void SayCastingNotes(vtkPenumbraShadowPass* pass)
  {
    vtkPenumbraSceneGeometry* g = this->Geometry;
    for (int i = 0; i < g->GetNumberOfCastingNotes(); ++i)
    {
      const std::string note = g->GetCastingNote(i);
      if (this->Noted.insert({ g->GetCastingNoteProp(i), note, this->Technique }).second)
      {
        vtkWarningWithObjectMacro(pass, << note << " (in every technique; the frame is shadowed with "
                                        << this->Technique->GetTechniqueName() << ")");
      }
    }
  }

  // Why the last frame needed no shadow work although lights shine ("" when it did).
  std::string Idle;

  // Whether some extracted triangle receives shadows on a prop that is lit (an unlit prop
  // receives no light, so no shadow). Kept while the geometry and its flags are unchanged.
  bool Receivers = false;
  std::vector<double> ReceiversKey;
  bool AnyReceiver()
  {
    const std::vector<double> key = { static_cast<double>(this->Geometry->GetGeometryTime()),
      static_cast<double>(this->Geometry->GetFlagsTime()) };
    if (key == this->ReceiversKey)
    {
      return this->Receivers;
    }
    this->ReceiversKey = key;
    this->Receivers = false;
    vtkPenumbraSceneGeometry* g = this->Geometry;
    for (int p = 0; p < g->GetNumberOfProps() && !this->Receivers; ++p)
    {
      auto* actor = vtkActor::SafeDownCast(g->GetProp(p));
      if (actor && !actor->GetProperty()->GetLighting())
      {
        continue;
      }
      const vtkIdType first = g->GetPropTriangleOffset(p);
      const vtkIdType count = g->GetPropTriangleCount(p);
      const unsigned char* flags = g->GetFlags()->GetPointer(0);
      for (vtkIdType t = first; t < first + count && !this->Receivers; ++t)
      {
        this->Receivers = (flags[t] & vtkPenumbraSceneGeometry::RECEIVES_SHADOWS) != 0;
      }
    }
    return this->Receivers;
  }

  // The visible samples' bounding box in world coordinates, once per view; null when no
  // sample has a surface.
  std::array<double, 6> Samples{};
  bool HasSamples = false;
  vtkMTimeType SamplesKey = 0;
  const double* SampleBox(vtkPenumbraViewSamples* samples)
  {
    if (this->Frame->GetSamplesTime() != this->SamplesKey)
    {
      this->SamplesKey = this->Frame->GetSamplesTime();
      this->HasSamples = false;
      double lo[3] = { DBL_MAX, DBL_MAX, DBL_MAX }, hi[3] = { -DBL_MAX, -DBL_MAX, -DBL_MAX };
      for (vtkIdType i = 0; i < samples->GetNumberOfSamples(); ++i)
      {
        double p[3];
        if (samples->GetWorldPosition(i, p))
        {
          this->HasSamples = true;
          for (int a = 0; a < 3; ++a)
          {
            lo[a] = std::min(lo[a], p[a]);
            hi[a] = std::max(hi[a], p[a]);
          }
        }
      }
      for (int a = 0; a < 3; ++a)
      {
        this->Samples[2 * a] = lo[a];
        this->Samples[2 * a + 1] = hi[a];
      }
    }
    return this->HasSamples ? this->Samples.data() : nullptr;
  }
};

void vtkPenumbraShadowPass::Internals::CollectLights(vtkRenderer* ren)
{
  this->Lights.clear();
  this->LightsOff = 0;
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  while (vtkLight* light = lights->GetNextLight(it))
  {
    if (light->GetSwitch())
    {
      this->Lights.emplace_back(light);
    }
    else
    {
      ++this->LightsOff;
    }
  }
}

// What the view samples depend on: by value where VTK modifies objects without changing them
// (cameras, props), by MTime where a time is the only witness (geometry, flags, settings).
std::vector<double> vtkPenumbraShadowPass::Internals::ViewKey(
  const vtkRenderState* s, vtkPenumbraShadowPass* pass)
{
  std::vector<double> key;
  vtkRenderer* ren = s->GetRenderer();
  int size[4];
  ren->GetTiledSizeAndOrigin(&size[0], &size[1], &size[2], &size[3]);
  key.insert(key.end(), size, size + 4);
  vtkCamera* cam = ren->GetActiveCamera();
  const double aspect = size[1] > 0 ? static_cast<double>(size[0]) / size[1] : 1.0;
  for (vtkMatrix4x4* m : { cam->GetModelViewTransformMatrix(),
         cam->GetCompositeProjectionTransformMatrix(aspect, -1, 1) })
  {
    key.insert(key.end(), &m->Element[0][0], &m->Element[0][0] + 16);
  }
  key.push_back(static_cast<double>(this->Geometry->GetGeometryTime()));
  key.push_back(static_cast<double>(this->Geometry->GetFlagsTime()));
  // What of the props the view samples show beyond their triangles (which GeometryTime
  // covers): which props are drawn, which are translucent receivers (the second layer), and
  // whether they are lit and how they are drawn (unlit props give no samples).
  for (int i = 0; i < s->GetPropArrayCount(); ++i)
  {
    vtkProp* prop = s->GetPropArray()[i];
    key.push_back(reinterpret_cast<std::uintptr_t>(prop));
    key.push_back(prop->GetVisibility());
    key.push_back(IsTranslucentReceiver(prop));
    if (auto* actor = vtkActor::SafeDownCast(prop))
    {
      vtkProperty* property = actor->GetProperty();
      key.push_back(property->GetLighting());
      key.push_back(property->GetRepresentation());
      key.push_back(property->GetBackfaceCulling());
      key.push_back(property->GetFrontfaceCulling());
    }
  }
  key.push_back(static_cast<double>(pass->GetMTime()));
  key.push_back(reinterpret_cast<std::uintptr_t>(ren->GetRenderWindow()));
  return key;
}

// What the visibility depends on beyond the view: every switched-on light (by value and
// MTime) and the technique with its settings.
std::vector<double> vtkPenumbraShadowPass::Internals::LightsKey()
{
  std::vector<double> key;
  for (auto& light : this->Lights)
  {
    double p[3], f[3];
    light->GetTransformedPosition(p);
    light->GetTransformedFocalPoint(f);
    key.insert(key.end(), p, p + 3);
    key.insert(key.end(), f, f + 3);
    key.push_back(static_cast<double>(light->GetMTime()));
    key.push_back(reinterpret_cast<std::uintptr_t>(light.Get()));
  }
  key.push_back(reinterpret_cast<std::uintptr_t>(this->Technique.Get()));
  key.push_back(static_cast<double>(this->Technique ? this->Technique->GetMTime() : 0));
  key.push_back(reinterpret_cast<std::uintptr_t>(this->Fallback.Get()));
  key.push_back(static_cast<double>(this->Fallback ? this->Fallback->GetMTime() : 0));
  return key;
}

void vtkPenumbraShadowPass::Internals::PrepareSamples(const vtkRenderState* s)
{
  // Translucent receivers: their nearest surface per pixel is a second sample layer
  // (translucent props are drawn after the opaque ones, over them, and need their own
  // visibility; the opaque samples hold the surface behind them).
  this->HasTranslucentLayer = false;
  this->SampleRenderer = s->GetRenderer();
  this->SampleProps.clear();
  for (int i = 0; i < s->GetPropArrayCount(); ++i)
  {
    this->SampleProps.emplace_back(s->GetPropArray()[i]);
    this->HasTranslucentLayer =
      this->HasTranslucentLayer || IsTranslucentReceiver(s->GetPropArray()[i]);
  }
  if (this->HasTranslucentLayer && !this->TranslucentSamplesPass)
  {
    this->TranslucentSamplesPass = vtkSmartPointer<vtkPenumbraViewSamplesPass>::New();
    this->TranslucentSamplesPass->TranslucentOn();
  }
  this->SamplesPass->SetGeometry(this->Geometry);
  this->SamplesPass->UpdateView(s->GetRenderer());
}

void vtkPenumbraShadowPass::Internals::RenderPreparedSamples()
{
  if (!this->SampleRenderer)
  {
    return;
  }
  // Also called after Render() (a read-back), when another window's context may be current.
  this->SampleRenderer->GetRenderWindow()->MakeCurrent();
  const double t = Now();
  std::vector<vtkProp*> props;
  for (const auto& prop : this->SampleProps)
  {
    props.push_back(prop);
  }
  vtkRenderState state(this->SampleRenderer);
  state.SetPropArrayAndCount(props.data(), static_cast<int>(props.size()));
  this->RenderSamples(&state);
  this->LastSampled = true;
  this->SamplesMs += 1000.0 * (Now() - t);
}

void vtkPenumbraShadowPass::Internals::RenderSamples(const vtkRenderState* s)
{
  auto* win = vtkOpenGLRenderWindow::SafeDownCast(s->GetRenderer()->GetRenderWindow());
  this->SamplesPass->SetGeometry(this->Geometry);
  this->SamplesPass->Render(s);
  if (this->HasTranslucentLayer)
  {
    this->TranslucentSamplesPass->SetGeometry(this->Geometry);
    this->TranslucentSamplesPass->Render(s);
  }
  win->WaitForCompletion();
}

// The technique that shadows light i this frame: the pass's technique's choice, or the
// fallback for a light it cannot shadow (said once per light, as a warning).
vtkPenumbraShadowTechnique* vtkPenumbraShadowPass::Internals::Choose(
  vtkPenumbraShadowPass* pass, size_t i)
{
  vtkLight* light = this->Lights[i];
  Report& report = this->Reports[i];
  vtkPenumbraShadowTechnique* chosen = this->Technique->SelectTechnique(light, report.Why);
  if (!chosen || !chosen->CanShadow(light))
  {
    if (!this->Fallback)
    {
      // Exact soft shadows at the light's own k (Wang, Wang, Shi, Popescu, "GEARS: A General
      // and Efficient Algorithm for Rendering Shadows", Computer Graphics Forum 33(6), 2014).
      this->Fallback = vtkSmartPointer<vtkPenumbraGearsShadows>::New();
    }
    const std::string refused =
      chosen ? chosen->GetTechniqueName() : this->Technique->GetTechniqueName();
    chosen = this->Fallback;
    report.Why = refused + " cannot shadow it; shadowed by " +
      chosen->GetTechniqueNameFor(light) + " instead";
    if (this->Warned.insert({ light, chosen }).second)
    {
      vtkWarningWithObjectMacro(
        pass, "Light " << i << " (" << LightKind(light) << "): " << report.Why);
    }
  }
  report.Technique = chosen;
  return chosen;
}

// Lights no visible sample can receive (all face away, all outside the cone) get no shadow
// work. Tested only where the samples are on the CPU anyway (a technique of this frame reads
// them back, or an earlier frame of this view did): a GPU-only frame reads nothing back.
void vtkPenumbraShadowPass::Internals::SkipUnreachedLights(bool readsSamples)
{
  if (!readsSamples && !this->Frame->GetSamplesReadBack())
  {
    return;
  }
  vtkPenumbraViewSamples* samples = nullptr;
  for (size_t i = 0; i < this->Lights.size(); ++i)
  {
    Report& report = this->Reports[i];
    if (!report.Skipped.empty() || !report.Technique)
    {
      continue;
    }
    samples = samples ? samples : this->Frame->GetSamples();
    if (!samples)
    {
      return;
    }
    this->Witness.resize(this->Lights.size(), -1);
    report.Skipped = NothingToShadow(
      this->Lights[i], samples, this->CasterBox(), this->SampleBox(samples), this->Witness[i]);
    if (!report.Skipped.empty())
    {
      report.Technique = nullptr;
      ++this->NumberOfSkipped;
    }
  }
}

void vtkPenumbraShadowPass::Internals::ComputeVisibility(vtkPenumbraShadowPass* pass)
{
  vtkPenumbraFrame* frame = this->Frame;
  this->Reports.assign(this->Lights.size(), Report());
  this->NumberOfSkipped = 0;
  // Each light's technique first: whether any of them reads the samples back decides whether
  // the pass may look at the samples to skip lights.
  bool readsSamples = false;
  for (size_t i = 0; i < this->Lights.size(); ++i)
  {
    if (!Internals::CastsLight(this->Lights[i]))
    {
      this->Reports[i].Skipped = "it casts no light (zero intensity or black)";
      ++this->NumberOfSkipped;
      continue;
    }
    readsSamples = this->Choose(pass, i)->ReadsSamples() || readsSamples;
  }
  this->SkipUnreachedLights(readsSamples);

  // Each shadowed light's visibility takes a texture unit in the receivers' shaders; VTK's
  // own textures keep a few.
  GLint units = 16;
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
  const int budget = std::max(1, static_cast<int>(units) - ReservedTextureUnits);
  int skipped = 0;
  // The lights each technique shadows, as the frame numbers its shadowed lights; in the
  // order the techniques first appear, so a frame's work is deterministic.
  std::vector<std::pair<vtkPenumbraShadowTechnique*, std::vector<int>>> groups;
  for (size_t i = 0; i < this->Lights.size(); ++i)
  {
    Report& report = this->Reports[i];
    if (!report.Technique)
    {
      continue;
    }
    if (frame->GetNumberOfShadowedLights() >= budget)
    {
      ++skipped;
      report.Technique = nullptr;
      report.Skipped = "over the texture-unit budget of this OpenGL implementation";
      continue;
    }
    const int k = frame->GetNumberOfShadowedLights();
    frame->AddShadowedLight(this->Lights[i], static_cast<int>(i));
    auto group = std::find_if(groups.begin(), groups.end(),
      [&](const auto& g) { return g.first == report.Technique.Get(); });
    if (group == groups.end())
    {
      groups.emplace_back(report.Technique.Get(), std::vector<int>());
      group = groups.end() - 1;
    }
    group->second.push_back(k);
  }
  this->NumberOfSkipped += skipped;
  if (skipped > 0 && skipped != this->LastSkipped)
  {
    vtkErrorWithObjectMacro(pass, << skipped
                                  << " lights rendered without shadows: this OpenGL "
                                     "implementation gives a shader "
                                  << units << " texture units, so at most " << budget
                                  << " lights can be shadowed");
  }
  this->LastSkipped = skipped;
  for (auto& group : groups)
  {
    frame->SetActiveLights(group.second);
    group.first->ComputeFrame(frame);
  }
  frame->ClearActiveLights();
  frame->Finish();
  std::vector<std::string> injected(this->Lights.size());
  bool any = false;
  for (int k = 0; k < frame->GetNumberOfShadowedLights(); ++k)
  {
    if (frame->HasVisibility(k))
    {
      const int index = frame->GetLightIndex(k);
      vtkPenumbraFrame::ShaderLookup* lookup = frame->GetShaderLookup(index);
      injected[static_cast<size_t>(index)] = lookup ? "lookup:" + lookup->GetKey() : "texture";
      any = true;
    }
    else
    {
      vtkErrorWithObjectMacro(pass,
        "Light " << frame->GetLightIndex(k) << " rendered without shadows: the technique failed");
    }
  }
  this->SetInjected(any ? injected : std::vector<std::string>());
}

namespace
{
// Block visibilities live on vtkCompositePolyDataMapper2, which the scene module cannot see:
// registered here, when this library is loaded, so hidden blocks cast no shadows.
vtkCompositeDataDisplayAttributes* CompositeDisplayAttributes(vtkMapper* mapper)
{
  auto* composite = vtkCompositePolyDataMapper2::SafeDownCast(mapper);
  return composite ? composite->GetCompositeDataDisplayAttributes() : nullptr;
}
const bool DisplayAttributesRegistered =
  (vtkPenumbraSceneGeometry::SetDisplayAttributesAccessor(&CompositeDisplayAttributes), true);
}

vtkStandardNewMacro(vtkPenumbraShadowPass);
vtkInformationKeyMacro(vtkPenumbraShadowPass, INSTALLED, ObjectBase);

vtkPenumbraShadowPass::vtkPenumbraShadowPass()
  : Impl(new Internals)
{
  this->Impl->Delegate = this->Impl->DefaultDelegate;
}

vtkPenumbraShadowPass::~vtkPenumbraShadowPass()
{
  // The frame may outlive the pass (GetFrame()); its on-demand samples render through it.
  this->Impl->Frame->ForgetPendingSamples();
}

void vtkPenumbraShadowPass::SetTechnique(vtkPenumbraShadowTechnique* technique)
{
  if (this->Impl->Technique != technique)
  {
    this->Impl->Technique = technique;
    this->Modified();
  }
}

vtkPenumbraShadowTechnique* vtkPenumbraShadowPass::GetTechnique()
{
  return this->Impl->Technique;
}

void vtkPenumbraShadowPass::SetFallbackTechnique(vtkPenumbraShadowTechnique* technique)
{
  if (this->Impl->Fallback != technique)
  {
    this->Impl->Fallback = technique;
    this->Modified();
  }
}

vtkPenumbraShadowTechnique* vtkPenumbraShadowPass::GetFallbackTechnique()
{
  return this->Impl->Fallback;
}

vtkPenumbraShadowTechnique* vtkPenumbraShadowPass::GetLightTechnique(int index)
{
  const auto& reports = this->Impl->Reports;
  return this->Impl->HasFrame && index >= 0 && static_cast<size_t>(index) < reports.size()
    ? reports[static_cast<size_t>(index)].Technique.Get()
    : nullptr;
}

const char* vtkPenumbraShadowPass::GetLightTechniqueName(int index)
{
  vtkPenumbraShadowTechnique* t = this->GetLightTechnique(index);
  return t ? t->GetTechniqueNameFor(this->GetLight(index)) : "";
}

int vtkPenumbraShadowPass::GetNumberOfSkippedLights()
{
  return this->Impl->HasFrame ? this->Impl->NumberOfSkipped : 0;
}

int vtkPenumbraShadowPass::GetNumberOfLightsOff()
{
  return this->Impl->LightsOff;
}

std::string vtkPenumbraShadowPass::GetExplanation()
{
  const Internals& impl = *this->Impl;
  std::ostringstream out;
  if (!impl.Technique)
  {
    out << "no technique: every light is unshadowed\n";
  }
  else if (!impl.Idle.empty())
  {
    out << "no shadow work in the last frame: " << impl.Idle << "\n";
  }
  else if (!impl.HasFrame)
  {
    out << "no shadow work in the last frame (no light casts light, or nothing was visible)\n";
  }
  for (size_t i = 0; impl.HasFrame && i < impl.Lights.size() && i < impl.Reports.size(); ++i)
  {
    const Internals::Report& r = impl.Reports[i];
    out << "light " << i << " (" << LightKind(impl.Lights[i]) << "): ";
    if (r.Technique)
    {
      out << r.Technique->GetTechniqueNameFor(impl.Lights[i]) << " - " << r.Why << "\n";
    }
    else
    {
      out << "skipped, no shadow work - "
          << (r.Skipped.empty() ? "the technique failed" : r.Skipped) << "\n";
    }
  }
  out << "skipped lights: " << this->GetNumberOfSkippedLights()
      << "; lights off: " << impl.LightsOff << " (no shadow work)\n";
  return out.str();
}

void vtkPenumbraShadowPass::SetDelegatePass(vtkRenderPass* pass)
{
  vtkRenderPass* delegate = pass ? pass : this->Impl->DefaultDelegate.Get();
  if (this->Impl->Delegate != delegate)
  {
    this->Impl->Delegate = delegate;
    this->Modified();
  }
}

bool vtkPenumbraShadowPass::GetDrawsWithRenderer()
{
  return this->Impl->Delegate == this->Impl->DefaultDelegate;
}

vtkRenderPass* vtkPenumbraShadowPass::GetDelegatePass()
{
  return this->Impl->Delegate;
}

vtkPenumbraSceneGeometry* vtkPenumbraShadowPass::GetGeometry()
{
  return this->Impl->Geometry;
}

vtkRenderPass* vtkPenumbraShadowPass::GetShadowMapBakerPass()
{
  return this->Impl->Baker;
}

vtkPenumbraViewSamplesPass* vtkPenumbraShadowPass::GetViewSamplesPass()
{
  this->Impl->Frame->EnsureSamples();
  return this->Impl->SamplesPass;
}

vtkPenumbraViewSamples* vtkPenumbraShadowPass::GetViewSamples()
{
  this->Impl->Frame->EnsureSamples();
  return this->Impl->SamplesPass->GetSamples();
}

int vtkPenumbraShadowPass::GetNumberOfLights()
{
  return static_cast<int>(this->Impl->Lights.size());
}

vtkLight* vtkPenumbraShadowPass::GetLight(int index)
{
  return (index >= 0 && index < this->GetNumberOfLights())
    ? this->Impl->Lights[static_cast<size_t>(index)].Get()
    : nullptr;
}

vtkFloatArray* vtkPenumbraShadowPass::GetVisibility(int index)
{
  return this->Impl->HasFrame ? this->Impl->Frame->GetVisibility(0, index) : nullptr;
}

vtkFloatArray* vtkPenumbraShadowPass::GetLightFactor(int index)
{
  return this->Impl->HasFrame ? this->Impl->Frame->GetLightFactor(0, index) : nullptr;
}

vtkPenumbraViewSamples* vtkPenumbraShadowPass::GetTranslucentViewSamples()
{
  this->Impl->Frame->EnsureSamples();
  return this->Impl->HasFrame && this->Impl->HasTranslucentLayer
    ? this->Impl->TranslucentSamplesPass->GetSamples()
    : nullptr;
}

vtkFloatArray* vtkPenumbraShadowPass::GetTranslucentVisibility(int index)
{
  return this->Impl->HasFrame ? this->Impl->Frame->GetVisibility(1, index) : nullptr;
}

vtkPenumbraFrame* vtkPenumbraShadowPass::GetFrame()
{
  return this->Impl->HasFrame ? this->Impl->Frame.Get() : nullptr;
}

bool vtkPenumbraShadowPass::GetLastFrameReused()
{
  return this->Impl->LastReused;
}

bool vtkPenumbraShadowPass::GetLastFrameRenderedSamples()
{
  return this->Impl->LastSampled;
}

double vtkPenumbraShadowPass::GetExtractionTimeMs()
{
  return this->Impl->ExtractionMs;
}

double vtkPenumbraShadowPass::GetSamplesTimeMs()
{
  return this->Impl->SamplesMs;
}

double vtkPenumbraShadowPass::GetTechniqueTimeMs()
{
  return this->Impl->TechniqueMs;
}

double vtkPenumbraShadowPass::GetShadingTimeMs()
{
  return this->Impl->ShadingMs;
}

void vtkPenumbraShadowPass::Render(const vtkRenderState* s)
{
  Internals& impl = *this->Impl;
  this->NumberOfRenderedProps = 0;
  vtkRenderer* ren = s->GetRenderer();
  auto* win = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!impl.Delegate || !win)
  {
    vtkErrorMacro("vtkPenumbraShadowPass needs a delegate pass and an OpenGL render window");
    return;
  }
  if (ren->GetSelector())
  {
    // A hardware-selection (picking) render draws ids, not shading: no shadow work, and
    // the selection shaders get none of ours.
    impl.Delegate->Render(s);
    this->NumberOfRenderedProps = impl.Delegate->GetNumberOfRenderedProps();
    return;
  }

  // VTK creates its automatic headlight when it first loads the lights
  // (vtkOpenGLRenderer::UpdateLights(), in the delegate): created here with the same rule,
  // so that the first frame is shadowed too.
  if (ren->GetAutomaticLightCreation() && CountLightsOn(ren) == 0)
  {
    ren->CreateLight();
  }
  // Light positions must be final (headlights follow the camera) before shadows are cast.
  this->UpdateLightGeometry(ren);
  impl.CollectLights(ren);
  bool anyShadowed = false;
  for (auto& light : impl.Lights)
  {
    anyShadowed = anyShadowed || (impl.Technique && Internals::CastsLight(light));
  }

  impl.ExtractionMs = impl.SamplesMs = impl.TechniqueMs = 0.0;
  impl.LastReused = false;
  impl.LastSampled = false;
  double t = Now();
  bool geometryOk = false;
  if (anyShadowed)
  {
    geometryOk = impl.Geometry->Update(ren) != 0;
    if (!geometryOk)
    {
      vtkErrorMacro("Shadows disabled for this frame: " << impl.Geometry->GetErrorMessage());
    }
    impl.SayCastingNotes(this);
  }
  impl.ExtractionMs = 1000.0 * (Now() - t);
  // A scene without casters, or without a lit surface to receive (2D annotations, volumes,
  // unlit props), gets no shadow work at all: it is drawn as without shadows.
  impl.Idle.clear();
  if (anyShadowed && geometryOk)
  {
    impl.Idle = !impl.CasterBox() ? "nothing casts shadows"
      : !impl.AnyReceiver()       ? "no lit surface receives shadows"
                                  : "";
  }

  int w = 0, h = 0, x = 0, y = 0;
  ren->GetTiledSizeAndOrigin(&w, &h, &x, &y);
  if (anyShadowed && geometryOk && impl.Idle.empty() && w > 0 && h > 0)
  {
    std::vector<double> viewKey = impl.ViewKey(s, this);
    std::vector<double> lightsKey = impl.LightsKey();
    // The view samples are the same as long as the view is: a light that moves, a technique
    // that changes, reuse them (no G-buffer, no read-back).
    const bool sameView = impl.HasFrame && viewKey == impl.LastViewKey;
    impl.LastReused = this->ReuseUnchangedFrames && sameView && lightsKey == impl.LastLightsKey;
    if (!impl.LastReused)
    {
      // A new view's samples are rendered when a technique (or a read-back) first asks for
      // them: the receivers' shader lookups need none.
      impl.LastSampled = false;
      impl.SamplesMs = 0.0;
      if (!sameView)
      {
        impl.PrepareSamples(s);
      }
      t = Now();
      Internals* internals = &impl;
      impl.Frame->Begin(ren, impl.Geometry, impl.SamplesPass,
        impl.HasTranslucentLayer ? impl.TranslucentSamplesPass.Get() : nullptr,
        static_cast<int>(impl.Lights.size()), !sameView,
        [internals] { internals->RenderPreparedSamples(); });
      impl.HasFrame = true;
      impl.ComputeVisibility(this);
      win->WaitForCompletion();
      impl.TechniqueMs = 1000.0 * (Now() - t) - impl.SamplesMs;
      impl.LastViewKey.swap(viewKey);
      impl.LastLightsKey.swap(lightsKey);
    }
    else
    {
      impl.BakeShaderLookups();
    }
  }
  else
  {
    impl.HasFrame = false;
    impl.LastViewKey.clear();
    impl.SetInjected({});
  }

  t = Now();
  // What the receivers' shaders read: each light's visibility textures, or what its shader
  // lookup reads.
  std::vector<vtkTextureObject*> textures;
  std::vector<vtkPenumbraFrame::ShaderLookup*> lookups;
  for (size_t i = 0; i < impl.Injected.size(); ++i)
  {
    if (impl.Injected[i].empty())
    {
      continue;
    }
    if (vtkPenumbraFrame::ShaderLookup* lookup = impl.InjectedLookup(i))
    {
      lookups.push_back(lookup);
      lookup->Activate();
      continue;
    }
    for (int layer = 0; layer < 2; ++layer)
    {
      if (vtkTextureObject* tex = impl.Frame->GetVisibilityTexture(layer, static_cast<int>(i)))
      {
        textures.push_back(tex);
        tex->Activate();
      }
    }
  }
  this->PreRender(s);
  impl.Delegate->Render(s);
  this->NumberOfRenderedProps = impl.Delegate->GetNumberOfRenderedProps();
  this->PostRender(s);
  for (vtkTextureObject* tex : textures)
  {
    tex->Deactivate();
  }
  for (vtkPenumbraFrame::ShaderLookup* lookup : lookups)
  {
    lookup->Deactivate();
  }
  win->WaitForCompletion();
  impl.ShadingMs = 1000.0 * (Now() - t);
}

vtkMTimeType vtkPenumbraShadowPass::GetShaderStageMTime()
{
  return this->Impl->ShaderTime.GetMTime();
}

bool vtkPenumbraShadowPass::PreReplaceShaderValues(
  std::string&, std::string&, std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop)
{
  // Translucent props read the translucent layer's visibility: the opaque samples hold the
  // surface behind them.
  if (!this->Impl->Injected.empty() && vtkOpenGLPolyDataMapper::SafeDownCast(mapper) &&
    vtkPenumbraShadowKeys::ReceivesShadows(prop))
  {
    const int layer = IsTranslucentReceiver(prop) ? 1 : 0;
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::Light::Dec",
      std::string("//VTK::Light::Dec\n") + LayerTags[layer] + "\n", false);
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::UniformFlow::Impl",
      std::string("//VTK::UniformFlow::Impl\n") + SurfaceTag + "\n", false);
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::Light::Impl",
      std::string(ReceiveTag) + "\n//VTK::Light::Impl", false);
  }
  return true;
}

bool vtkPenumbraShadowPass::PostReplaceShaderValues(
  std::string&, std::string&, std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop)
{
  int layer = 0;
  while (layer < 2 && fragmentShader.find(LayerTags[layer]) == std::string::npos)
  {
    ++layer;
  }
  if (layer == 2)
  {
    return true;
  }
  const std::string tag = LayerTags[layer];
  // Only surfaces drawn as triangles receive: lines and points are lit as VTK lights them
  // (vtkPenumbraMapperDraws.h), and so is every light this shader does not shade with.
  const bool surface = penumbra_draws::DrawsSurface(mapper, prop);
  const bool position = penumbra_draws::HasViewPosition(fragmentShader);
  // After VTK's light uniforms: rename each shadowed light's colour to colour x visibility.
  // A macro naming itself is not expanded again, so `lightColorN` inside it is the uniform.
  std::string dec = vtkPenumbraVisibilityDec;
  std::string lookups, visibilities;
  const Internals& impl = *this->Impl;
  for (size_t i = 0; surface && i < impl.Injected.size(); ++i)
  {
    const std::string color = "lightColor" + std::to_string(i);
    if (impl.Injected[i].empty() || !penumbra_draws::LightsWith(fragmentShader, i))
    {
      continue; // light i is unshadowed, or this shader does not light with it
    }
    if (vtkPenumbraFrame::ShaderLookup* lookup = impl.InjectedLookup(i))
    {
      if (!position)
      {
        continue; // no surface to look up: no view sample either (unshadowed)
      }
      // Evaluated once before VTK's lighting (which reads the colour twice).
      const std::string suffix = LookupSuffix(i);
      lookups += lookup->GetSource(suffix);
      visibilities += "  float penumbraVisibility" + suffix + " = penumbraReceive" + suffix +
        "(penumbraP, penumbraN);\n";
      dec += "#define " + color + " (" + color + " * penumbraVisibility" + suffix + ")\n";
      continue;
    }
    const std::string sampler = LayerSamplers[layer] + std::to_string(i);
    dec += "uniform sampler2D " + sampler + ";\n";
    dec += "#define " + color + " (" + color + " * penumbraShadow(texelFetch(" + sampler +
      ", penumbraTexel(), 0).r))\n";
  }
  std::string surfaceCall;
  if (!lookups.empty())
  {
    dec = lookups + dec;
    surfaceCall = vtkPenumbraViewSamplesPass::GetSurfaceCall();
    // The lookups' facing rules are in double precision, like the reference's.
    if (fragmentShader.find("GL_ARB_gpu_shader_fp64") == std::string::npos)
    {
      vtkShaderProgram::Substitute(fragmentShader, "//VTK::System::Dec",
        "//VTK::System::Dec\n#extension GL_ARB_gpu_shader_fp64 : require\n", false);
    }
    // A template without VTK's uniform-flow tag computes the surface before the lookups.
    if (fragmentShader.find(SurfaceTag) == std::string::npos)
    {
      visibilities = surfaceCall + visibilities;
    }
  }
  if (!lookups.empty())
  {
    vtkPenumbraViewSamplesPass::AddSurfaceDeclarations(fragmentShader, tag, dec);
  }
  vtkShaderProgram::Substitute(fragmentShader, tag, surface ? dec : "", false);
  vtkShaderProgram::Substitute(fragmentShader, SurfaceTag, surfaceCall, false);
  vtkShaderProgram::Substitute(fragmentShader, ReceiveTag, visibilities, false);
  return true;
}

bool vtkPenumbraShadowPass::SetShaderParameters(
  vtkShaderProgram* program, vtkAbstractMapper*, vtkProp*, vtkOpenGLVertexArrayObject*)
{
  Internals& impl = *this->Impl;
  if (impl.Injected.empty())
  {
    return true;
  }
  if (program->IsUniformUsed("penumbraVCToRebased"))
  {
    impl.SamplesPass->SetSurfaceUniforms(program);
    for (size_t i = 0; i < impl.Injected.size(); ++i)
    {
      if (vtkPenumbraFrame::ShaderLookup* lookup = impl.InjectedLookup(i))
      {
        lookup->SetUniforms(program, LookupSuffix(i));
      }
    }
  }
  if (!program->IsUniformUsed("penumbraViewportOrigin"))
  {
    return true;
  }
  // The visibility texel of a pixel is its offset from the current viewport's corner; this
  // holds for the window and for the translucency passes' own framebuffers alike.
  GLint viewport[4] = { 0, 0, 0, 0 };
  glGetIntegerv(GL_VIEWPORT, viewport);
  const int origin[2] = { viewport[0], viewport[1] };
  program->SetUniform2i("penumbraViewportOrigin", origin);
  for (int layer = 0; layer < 2; ++layer)
  {
    for (size_t i = 0; i < impl.Injected.size(); ++i)
    {
      const std::string name = LayerSamplers[layer] + std::to_string(i);
      if (impl.Injected[i] != "texture" || !program->IsUniformUsed(name.c_str()))
      {
        continue; // (asking a shader lookup for its texture would run its pass mid-draw)
      }
      vtkTextureObject* tex = impl.Frame->GetVisibilityTexture(layer, static_cast<int>(i));
      if (tex)
      {
        program->SetUniformi(name.c_str(), tex->GetTextureUnit());
      }
    }
  }
  return true;
}

void vtkPenumbraShadowPass::ReleaseGraphicsResources(vtkWindow* w)
{
  Internals& impl = *this->Impl;
  if (impl.Delegate)
  {
    impl.Delegate->ReleaseGraphicsResources(w);
  }
  impl.SamplesPass->ReleaseGraphicsResources(w);
  if (impl.TranslucentSamplesPass)
  {
    impl.TranslucentSamplesPass->ReleaseGraphicsResources(w);
  }
  if (impl.Technique)
  {
    impl.Technique->ReleaseGraphicsResources(w);
  }
  if (impl.Fallback)
  {
    impl.Fallback->ReleaseGraphicsResources(w);
  }
  impl.Frame->Release(w);
  impl.HasFrame = false;
  impl.LastViewKey.clear();
  impl.SetInjected({});
}

void vtkPenumbraShadowPass::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent
     << "Technique: " << (this->Impl->Technique ? this->Impl->Technique->GetClassName() : "(none)")
     << "\n";
  os << indent << "Lights: " << this->Impl->Lights.size() << "\n";
} //------------------------------------------------------------------------------
vtkPenumbraShadowPass* vtkPenumbraShadowPass::GetInstalled(vtkRenderer* renderer)
{
  vtkInformation* info = renderer ? renderer->GetInformation() : nullptr;
  if (info && info->Has(INSTALLED()))
  {
    return vtkPenumbraShadowPass::SafeDownCast(info->Get(INSTALLED()));
  }
  return renderer ? FindShadowPass(renderer->GetPass()) : nullptr;
}

vtkPenumbraShadowPass* vtkPenumbraShadowPass::FindIn(vtkRenderPass* pass)
{
  return FindShadowPass(pass);
}

void vtkPenumbraShadowPass::SetInstalled(vtkRenderer* renderer, vtkPenumbraShadowPass* pass)
{
  if (!renderer)
  {
    return;
  }
  if (pass)
  {
    renderer->GetInformation()->Set(INSTALLED(), pass);
  }
  else
  {
    renderer->GetInformation()->Remove(INSTALLED());
  }
}
