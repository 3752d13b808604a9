/**
 * @file   vtkPenumbraShadowPassInternals.h
 * @brief  The state of a vtkPenumbraShadowPass shared by its files: the pass and its
 *         composition (vtkPenumbraShadowPass.cxx), the lights and their techniques
 *         (vtkPenumbraShadowPassLights.cxx), and the receivers' shader code
 *         (vtkPenumbraShadowPassShaders.cxx). Private to the module.
 */

#ifndef vtkPenumbraShadowPassInternals_h
#define vtkPenumbraShadowPassInternals_h

#include "vtkPenumbraShadowPass.h"

#include "vtkActor.h"
#include "vtkDoubleArray.h"
#include "vtkLight.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraRemoteShadows.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkProperty.h"
#include "vtkRenderPass.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWeakPointer.h"

#include <array>
#include <cfloat>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

class vtkProp;
class vtkRenderState;

namespace penumbra_shadow_pass
{
// Whether VTK draws `prop` in its translucent pass as a receiver: the props whose nearest
// translucent surface gets its own view samples and visibility.
bool IsTranslucentReceiver(vtkProp* prop);

// "directional light", "spot light", "area light, 4x4 samples" ...: how explanations name a
// light.
std::string LightKind(vtkLight* light);

// Texture units left to VTK's own textures (colour, normal, PBR maps ...) in a receiver's
// shader; the rest can hold shadowed lights' visibility.
constexpr int ReservedTextureUnits = 8;

// The suffix of light i's shader-lookup names in a receiver's shader.
inline std::string LookupSuffix(size_t i)
{
  return "_L" + std::to_string(i);
}

// Where the receivers' shader lookups run: just before VTK's lighting code.
constexpr const char* ReceiveTag = "//PENUMBRA::Receive::Impl";

// Where the receivers' fragment surface is computed: VTK's uniform control flow.
constexpr const char* SurfaceTag = "//PENUMBRA::Receive::Surface";

// Shader tags of the two sample layers and the prefixes of their visibility samplers.
constexpr const char* LayerTags[2] = { "//PENUMBRA::Visibility::Dec",
  "//PENUMBRA::TranslucentVisibility::Dec" };
constexpr const char* LayerSamplers[2] = { "penumbraVisibility", "penumbraTranslucentVisibility" };
}

struct vtkPenumbraShadowPass::Internals
{
  vtkSmartPointer<vtkPenumbraShadowTechnique> Technique;
  // The renderer's own drawing (RendererDrawingPass), the delegate unless one is set.
  vtkSmartPointer<vtkRenderPass> DefaultDelegate;
  vtkSmartPointer<vtkRenderPass> Delegate;
  vtkSmartPointer<vtkRenderPass> Baker; // a no-op (GetShadowMapBakerPass())
  vtkSmartPointer<vtkPenumbraSceneGeometry> Geometry =
    vtkSmartPointer<vtkPenumbraSceneGeometry>::New();
  vtkSmartPointer<vtkPenumbraViewSamplesPass> SamplesPass =
    vtkSmartPointer<vtkPenumbraViewSamplesPass>::New();
  // Nearest translucent surface per pixel, sampled only when translucent receivers exist.
  vtkSmartPointer<vtkPenumbraViewSamplesPass> TranslucentSamplesPass;
  vtkSmartPointer<vtkPenumbraFrame> Frame = vtkSmartPointer<vtkPenumbraFrame>::New();
  bool HasTranslucentLayer = false;
  bool HasFrame = false; // Frame holds a frame rendered with shadows

  std::vector<vtkSmartPointer<vtkLight>> Lights; // switched-on, shader order, as shadowed
  int LightsOff = 0;                             // switched-off lights of the renderer

  // A positional light with a radius (vtkPenumbraShadowKeys::LIGHT_RADIUS) is shadowed as
  // its disc (vtkPenumbraAreaLight::SetFromLightRadius), kept while the light is unchanged.
  struct Standin
  {
    vtkSmartPointer<vtkPenumbraAreaLight> Disc;
    vtkMTimeType LightTime = 0, InfoTime = 0;
  };
  std::map<vtkLight*, Standin> Standins;
  std::set<vtkLight*> WarnedRadius; // lights told their radius is not used (said once)
  vtkLight* AsShadowed(
    vtkPenumbraShadowPass* pass, vtkLight* light, std::map<vtkLight*, Standin>& kept);

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
  // Whether light `index`'s technique combines the processes' casters itself this frame
  // (vtkPenumbraShadowTechnique::CompositesAcrossProcesses() in a frame with
  // vtkPenumbraFrame::GetProcesses()): every process then shadows it, and no ray resolves it.
  bool ComposesAcrossProcesses(size_t index) const
  {
    const Report& report = this->Reports[index];
    return this->Frame->GetProcesses() && report.Technique &&
      report.Technique->CompositesAcrossProcesses();
  }
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

  void CollectLights(vtkPenumbraShadowPass* pass, vtkRenderer* ren);
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
  // Distributed renders (SetRemoteShadows()): once a frame, the other processes' shadows on
  // the lit samples of `frame`'s hard lights (nullptr: nothing shadowed here, but the other
  // processes' rays are still answered).
  vtkSmartPointer<vtkPenumbraRemoteShadows> Remote;
  bool RemoteResolved = false;
  std::set<vtkLight*> WarnedRemote; // area lights told they see only local casters (once)
  void ResolveRemote(vtkPenumbraShadowPass* pass, vtkPenumbraFrame* frame);
  vtkPenumbraShadowTechnique* Choose(vtkPenumbraShadowPass* pass, size_t i);
  void SkipUnreachedLights(bool readsSamples);

  // The casters' bounding box in world coordinates, padded for rounding; null without
  // casters. Kept while the geometry and its flags are unchanged.
  std::array<double, 6> Casters{};
  bool HasCasters = false;
  penumbra::CastersStamp CasterBoxMade;
  const double* CasterBox()
  {
    if (this->CasterBoxMade.Changed(this->Geometry))
    {
      this->CasterBoxMade.Remember(this->Geometry);
      this->HasCasters = false;
      double lo[3] = { DBL_MAX, DBL_MAX, DBL_MAX }, hi[3] = { -DBL_MAX, -DBL_MAX, -DBL_MAX };
      const penumbra::SceneTriangles& triangles = this->Geometry->GetTriangles();
      const vtkIdType n = triangles.Size();
      for (vtkIdType t = 0; t < n; ++t)
      {
        if (!triangles.IsOccluder(t))
        {
          continue;
        }
        this->HasCasters = true;
        double v[9];
        triangles.Get(t, v);
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
        vtkWarningWithObjectMacro(pass, << note
                                        << " (in every technique; the frame is shadowed with "
                                        << this->Technique->GetTechniqueName() << ")");
      }
    }
  }

  // Why the last frame needed no shadow work although lights shine ("" when it did).
  std::string Idle;

  // Whether some extracted triangle receives shadows on a prop that is lit (an unlit prop
  // receives no light, so no shadow). Kept while the geometry and its flags are unchanged.
  bool Receivers = false;
  penumbra::CastersStamp ReceiversFound;
  bool AnyReceiver()
  {
    if (!this->ReceiversFound.Changed(this->Geometry))
    {
      return this->Receivers;
    }
    this->ReceiversFound.Remember(this->Geometry);
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
      const penumbra::SceneTriangles& triangles = g->GetTriangles();
      for (vtkIdType t = first; t < first + count && !this->Receivers; ++t)
      {
        this->Receivers = (triangles.GetFlags(t) & vtkPenumbraSceneGeometry::RECEIVES_SHADOWS) != 0;
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

#endif
