#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowPassInternals.h"

#include "vtkCameraPass.h"
#include "vtkDepthPeelingPass.h"
#include "vtkHardwareSelector.h"
#include "vtkImageProcessingPass.h"
#include "vtkOrderIndependentTranslucentPass.h"
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
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraMapperDraws.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraStatistics.h"
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
#include "vtkTranslucentPass.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolumetricPass.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include <cfloat>
#include <limits>

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
    // VTK's own shadows (vtkRenderer::UseShadows) are what the shadow pass replaces: not
    // drawn twice.
    const bool vtkShadows = ren->GetUseShadows() != 0;
    if (vtkShadows)
    {
      ren->UseShadowsOff();
    }
    this->UpdateGeometry(ren, s->GetFrameBuffer());
    if (vtkShadows)
    {
      ren->UseShadowsOn();
    }
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

}

namespace penumbra_shadow_pass
{
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
    const int shape = area->GetShape();
    if (shape == vtkPenumbraAreaLight::Disc)
    {
      std::ostringstream name;
      name << "disc light of diameter " << area->GetWidth() << ", " << area->GetNumberOfSamples()
           << " samples";
      return name.str();
    }
    return shape == vtkPenumbraAreaLight::Line
      ? "linear light, " + std::to_string(k) + " samples"
      : "area light, " + std::to_string(k) + "x" + std::to_string(k) + " samples";
  }
  if (!light->GetPositional())
  {
    return "directional light";
  }
  return light->GetConeAngle() < 90.0 ? "spot light" : "point light";
}

}

using namespace penumbra_shadow_pass;
using penumbra::Clock;
using penumbra::ElapsedMs;

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
  key.push_back(static_cast<double>(this->Geometry->GetCastersTime()));
  // What of the props the view samples show beyond their triangles (which the casters time
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
  const auto t = Clock::now();
  std::vector<vtkProp*> props;
  for (const auto& prop : this->SampleProps)
  {
    props.push_back(prop);
  }
  vtkRenderState state(this->SampleRenderer);
  state.SetPropArrayAndCount(props.data(), static_cast<int>(props.size()));
  this->RenderSamples(&state);
  this->LastSampled = true;
  this->SamplesMs += ElapsedMs(t);
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

vtkPenumbraShadowPass::FallbackFactory vtkPenumbraShadowPass::DefaultFallback = nullptr;

void vtkPenumbraShadowPass::SetDefaultFallbackFactory(FallbackFactory factory)
{
  vtkPenumbraShadowPass::DefaultFallback = factory;
}

vtkStandardNewMacro(vtkPenumbraShadowPass);
vtkInformationKeyMacro(vtkPenumbraShadowPass, INSTALLED, ObjectBase);

vtkPenumbraShadowPass::vtkPenumbraShadowPass()
  : Impl(new Internals)
{
  this->Impl->DefaultDelegate = vtkSmartPointer<RendererDrawingPass>::New();
  this->Impl->Baker = vtkSmartPointer<NoBakingPass>::New();
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
      vtkNew<vtkPenumbraStatistics> stats;
      r.Technique->GetStatistics(impl.Lights[i], stats);
      out << "  figures: " << stats->Format() << "\n";
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

bool vtkPenumbraShadowPass::GetLightStatistics(int index, vtkPenumbraStatistics* stats)
{
  if (!stats)
  {
    return false;
  }
  stats->Clear();
  const Internals& impl = *this->Impl;
  if (!impl.HasFrame || index < 0 || static_cast<size_t>(index) >= impl.Lights.size())
  {
    return false;
  }
  stats->Set("extraction_ms", impl.ExtractionMs);
  stats->Set("samples_ms", impl.SamplesMs);
  stats->Set("technique_ms", impl.TechniqueMs);
  stats->Set("shading_ms", impl.ShadingMs);
  if (vtkPenumbraShadowTechnique* technique = this->GetLightTechnique(index))
  {
    technique->GetStatistics(this->GetLight(index), stats);
  }
  return true;
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
  impl.CollectLights(this, ren);
  bool anyShadowed = false;
  for (auto& light : impl.Lights)
  {
    anyShadowed = anyShadowed || (impl.Technique && Internals::CastsLight(light));
  }

  impl.ExtractionMs = impl.SamplesMs = impl.TechniqueMs = 0.0;
  impl.LastReused = false;
  impl.RemoteResolved = false;
  impl.LastSampled = false;
  auto t = Clock::now();
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
  impl.ExtractionMs = ElapsedMs(t);
  // A scene without casters, or without a lit surface to receive (2D annotations, volumes,
  // unlit props), gets no shadow work at all: it is drawn as without shadows.
  impl.Idle.clear();
  if (anyShadowed && geometryOk)
  {
    // Other processes' casters may shadow this one's receivers, and its casters theirs
    // (SetRemoteShadows()): a distributed frame is computed on every process.
    impl.Idle = impl.Remote ? ""
      : !impl.CasterBox()   ? "nothing casts shadows"
      : !impl.AnyReceiver() ? "no lit surface receives shadows"
                            : "";
  }

  int w = 0, h = 0, x = 0, y = 0;
  ren->GetTiledSizeAndOrigin(&w, &h, &x, &y);
  const bool active = anyShadowed && geometryOk && impl.Idle.empty() && w > 0 && h > 0;
  std::vector<double> viewKey, lightsKey;
  bool sameView = false, unchanged = true; // unchanged: a process with no work has none to redo
  if (active)
  {
    viewKey = impl.ViewKey(s, this);
    lightsKey = impl.LightsKey();
    // The view samples are the same as long as the view is: a light that moves, a technique
    // that changes, reuse them (no G-buffer, no read-back).
    sameView = impl.HasFrame && viewKey == impl.LastViewKey;
    unchanged = this->ReuseUnchangedFrames && sameView && lightsKey == impl.LastLightsKey;
  }
  // A distributed frame is reused only when every process's is, and no process's casters
  // moved: all of them then skip Resolve() together.
  // The techniques that composite across processes get their collective operations only
  // in a frame every process computes (vtkPenumbraFrame::GetProcesses()).
  bool composing = false;
  if (impl.Remote)
  {
    composing = impl.Remote->AllAgree(active);
    unchanged = impl.Remote->AgreeToReuse(unchanged);
  }
  impl.Frame->SetProcesses(composing ? impl.Remote.Get() : nullptr);
  if (active)
  {
    impl.LastReused = unchanged;
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
      t = Clock::now();
      Internals* internals = &impl;
      impl.Frame->Begin(ren, impl.Geometry, impl.SamplesPass,
        impl.HasTranslucentLayer ? impl.TranslucentSamplesPass.Get() : nullptr,
        static_cast<int>(impl.Lights.size()), !sameView,
        [internals] { internals->RenderPreparedSamples(); });
      impl.HasFrame = true;
      impl.ComputeVisibility(this);
      if (impl.HasTranslucentLayer)
      {
        // Translucent props take the nearest translucent surface's visibility in every
        // fragment of the pixel (the contract): a lookup in their own shaders would shadow
        // the surfaces behind it by it. The lookups are written into textures instead.
        impl.BakeShaderLookups();
      }
      win->WaitForCompletion();
      impl.TechniqueMs = ElapsedMs(t) - impl.SamplesMs;
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
  // Nothing shadowed here: the other processes' rays are answered all the same.
  if (!unchanged)
  {
    impl.ResolveRemote(this, nullptr);
  }

  this->RenderShaded(s, win);
}

void vtkPenumbraShadowPass::SetRemoteShadows(vtkPenumbraRemoteShadows* remote)
{
  if (remote != this->Impl->Remote)
  {
    this->Impl->Remote = remote;
    this->Modified();
  }
}

vtkPenumbraRemoteShadows* vtkPenumbraShadowPass::GetRemoteShadows()
{
  return this->Impl->Remote;
}

// The scene drawn by the renderer's own drawing (or the user's pass), each shadowed light's
// colour scaled in the receivers' shaders by its visibility textures or its shader lookup.
void vtkPenumbraShadowPass::RenderShaded(const vtkRenderState* s, vtkOpenGLRenderWindow* win)
{
  Internals& impl = *this->Impl;
  const auto t = Clock::now();
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
  impl.SamplesPass->IndexProps(); // the receivers' lookups ask GivesSamples() while drawing
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
  impl.ShadingMs = ElapsedMs(t);
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
