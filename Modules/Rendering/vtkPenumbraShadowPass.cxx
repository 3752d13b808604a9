#include "vtkPenumbraShadowPass.h"

#include "vtkActor.h"
#include "vtkCollection.h"
#include "vtkFloatArray.h"
#include "vtkProperty.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkLightsPass.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpaquePass.h"
#include "vtkOpenGLPolyDataMapper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkOverlayPass.h"
#include "vtkPenumbraGoniometricLight.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkRenderPassCollection.h"
#include "vtkRenderState.h"
#include "vtkRenderer.h"
#include "vtkSequencePass.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkTimerLog.h"
#include "vtkTranslucentPass.h"
#include "vtkVolumetricPass.h"
#include "vtk_glew.h"

#include "vtkPenumbraVisibilityDec.h"

#include <algorithm>
#include <string>
#include <vector>

namespace
{
double Now()
{
  return vtkTimerLog::GetUniversalTime();
}

// Slot `i` of a pool of per-light arrays, created on first use and kept: a frame reuses the
// previous frame's arrays (same sizes, so no allocation) instead of allocating 4 bytes per
// pixel and light afresh, whose page faults cost tens of ms per frame at 1280 x 720.
vtkFloatArray* Pooled(std::vector<vtkSmartPointer<vtkFloatArray>>& pool, size_t i)
{
  if (pool.size() <= i)
  {
    pool.resize(i + 1);
  }
  if (!pool[i])
  {
    pool[i] = vtkSmartPointer<vtkFloatArray>::New();
  }
  return pool[i];
}

// Goniometric diagram (seed 004 §8.3.1): the thesis scales its shadow mask by the light's
// relative intensity toward each sample. Done here, after any technique, so every technique
// renders the diagram and the visibility stays the geometric one the reference checks.
// Returns `vis` itself for other lights, for goniometric ones a scaled copy in pool slot `i`.
vtkFloatArray* ScaleByDiagram(vtkLight* light, vtkPenumbraViewSamples* samples,
  vtkFloatArray* vis, std::vector<vtkSmartPointer<vtkFloatArray>>& pool, size_t i)
{
  auto* gonio = vtkPenumbraGoniometricLight::SafeDownCast(light);
  if (!gonio || !vis)
  {
    return vis;
  }
  vtkFloatArray* scaled = Pooled(pool, i);
  scaled->DeepCopy(vis);
  double lightWorld[3];
  gonio->GetTransformedPosition(lightWorld);
  float* v = scaled->GetPointer(0);
  for (vtkIdType s = 0; s < scaled->GetNumberOfTuples(); ++s)
  {
    double w[3];
    if (v[s] > 0.0f && samples->GetWorldPosition(s, w))
    {
      const double d[3] = { w[0] - lightWorld[0], w[1] - lightWorld[1], w[2] - lightWorld[2] };
      v[s] = static_cast<float>(v[s] * gonio->GetRelativeIntensity(d));
    }
  }
  return scaled;
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

// What VTK draws in its translucent pass, for a receiver: the props whose nearest
// translucent surface gets its own view samples and visibility.
bool IsTranslucentReceiver(vtkProp* prop)
{
  auto* actor = vtkActor::SafeDownCast(prop);
  return actor && actor->GetVisibility() && actor->HasTranslucentPolygonalGeometry() &&
    vtkPenumbraShadowKeys::ReceivesShadows(prop);
}

// Samples of props that do not receive are lit unshadowed: they get no shadow work.
void DropNonReceivers(vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples)
{
  std::vector<char> receives(static_cast<size_t>(geometry->GetNumberOfProps()), 1);
  bool anyNonReceiver = false;
  for (size_t p = 0; p < receives.size(); ++p)
  {
    receives[p] = vtkPenumbraShadowKeys::ReceivesShadows(geometry->GetProp(static_cast<int>(p)));
    anyNonReceiver = anyNonReceiver || !receives[p];
  }
  if (!anyNonReceiver)
  {
    return;
  }
  int* props = samples->GetPropIndices()->GetPointer(0);
  vtkIdType* tris = samples->GetTriangleIds()->GetPointer(0);
  for (vtkIdType i = 0; i < samples->GetNumberOfSamples(); ++i)
  {
    if (props[i] >= 0 && props[i] < static_cast<int>(receives.size()) &&
      !receives[static_cast<size_t>(props[i])])
    {
      props[i] = -1;
      tris[i] = -1;
    }
  }
}

// `out` = the rows of `a` followed by the rows of `b` (same width and origin), so that one
// technique call serves both sample layers (and per-light caches stay valid).
void Stack(vtkPenumbraViewSamples* a, vtkPenumbraViewSamples* b, vtkPenumbraViewSamples* out)
{
  out->SetSize(a->GetWidth(), a->GetHeight() + b->GetHeight());
  out->SetOrigin(a->GetOrigin());
  out->SetCameraPosition(a->GetCameraPosition());
  const vtkIdType na = a->GetNumberOfSamples();
  const vtkIdType nb = b->GetNumberOfSamples();
  auto copy = [&](auto* dst, auto* srcA, auto* srcB, int components) {
    std::copy(srcA->GetPointer(0), srcA->GetPointer(0) + components * na, dst->GetPointer(0));
    std::copy(
      srcB->GetPointer(0), srcB->GetPointer(0) + components * nb, dst->GetPointer(components * na));
  };
  copy(out->GetPositions(), a->GetPositions(), b->GetPositions(), 3);
  copy(out->GetNormals(), a->GetNormals(), b->GetNormals(), 3);
  copy(out->GetPropIndices(), a->GetPropIndices(), b->GetPropIndices(), 1);
  copy(out->GetTriangleIds(), a->GetTriangleIds(), b->GetTriangleIds(), 1);
  out->Modified();
}

// The values [begin, begin + n) of `in`, copied into `out`.
vtkFloatArray* Slice(vtkFloatArray* in, vtkIdType begin, vtkIdType n, vtkFloatArray* out)
{
  out->SetNumberOfComponents(1);
  out->SetNumberOfTuples(n);
  std::copy(in->GetPointer(begin), in->GetPointer(begin) + n, out->GetPointer(0));
  return out;
}

// Shader tags of the two sample layers and the prefixes of their visibility samplers.
const char* const LayerTags[2] = { "//PENUMBRA::Visibility::Dec",
  "//PENUMBRA::TranslucentVisibility::Dec" };
const char* const LayerSamplers[2] = { "penumbraVisibility", "penumbraTranslucentVisibility" };
}

struct vtkPenumbraShadowPass::Internals
{
  vtkSmartPointer<vtkPenumbraShadowTechnique> Technique;
  vtkSmartPointer<vtkRenderPass> Delegate;
  vtkSmartPointer<vtkRenderPass> Baker = vtkSmartPointer<NoBakingPass>::New();
  vtkSmartPointer<vtkPenumbraSceneGeometry> Geometry =
    vtkSmartPointer<vtkPenumbraSceneGeometry>::New();
  vtkSmartPointer<vtkPenumbraViewSamplesPass> SamplesPass =
    vtkSmartPointer<vtkPenumbraViewSamplesPass>::New();
  // Nearest translucent surface per pixel, sampled only when translucent receivers exist.
  vtkSmartPointer<vtkPenumbraViewSamplesPass> TranslucentSamplesPass;
  vtkSmartPointer<vtkPenumbraViewSamples> Stacked; // opaque rows, then translucent rows
  bool HasTranslucentLayer = false;

  std::vector<vtkSmartPointer<vtkLight>> Lights; // switched-on, shader order
  // Per layer (0 opaque, 1 translucent) and light: visibility, null = no shadow.
  std::vector<vtkSmartPointer<vtkFloatArray>> Visibility[2];
  // Array pools (see Pooled()): the technique's per-light results, their per-layer slices,
  // the diagram-scaled copies.
  std::vector<vtkSmartPointer<vtkFloatArray>> ResultPool, SlicePool[2], ScaledPool[2];
  // Per layer and light: what the light's colour is scaled by (the visibility, times the
  // diagram for goniometric lights); null = no shadow.
  std::vector<vtkSmartPointer<vtkFloatArray>> Factor[2];
  // Upload staging, kept between frames (no per-frame allocation of 16 bytes per pixel).
  std::vector<float> Texels;
  // Per layer: 4 lights per RGBA texture, and the samplers' names.
  std::vector<vtkSmartPointer<vtkTextureObject>> Textures[2];
  std::vector<std::string> SamplerNames[2];

  // Number of lights whose colour the shaders scale; shader code depends on it.
  int InjectedLights = 0;
  vtkTimeStamp ShaderTime;

  double ExtractionMs = 0, SamplesMs = 0, TechniqueMs = 0, ShadingMs = 0;

  void SetInjectedLights(int n)
  {
    if (n != this->InjectedLights)
    {
      this->InjectedLights = n;
      this->ShaderTime.Modified();
      for (int layer = 0; layer < 2; ++layer)
      {
        this->SamplerNames[layer].clear();
        for (int k = 0; k < (n + 3) / 4; ++k)
        {
          this->SamplerNames[layer].push_back(LayerSamplers[layer] + std::to_string(k));
        }
      }
    }
  }

  static bool CastsLight(vtkLight* light)
  {
    const double* c = light->GetDiffuseColor();
    const double* s = light->GetSpecularColor();
    return light->GetIntensity() > 0.0 && (c[0] > 0 || c[1] > 0 || c[2] > 0 || s[0] > 0 ||
                                             s[1] > 0 || s[2] > 0);
  }
};

vtkStandardNewMacro(vtkPenumbraShadowPass);

vtkPenumbraShadowPass::vtkPenumbraShadowPass()
  : Impl(new Internals)
{
  // The same steps vtkRenderStepsPass runs, so translucent props, volumes and overlays are
  // still drawn (VTK's UseShadows drops translucent geometry).
  vtkNew<vtkRenderPassCollection> steps;
  steps->AddItem(vtkNew<vtkLightsPass>());
  steps->AddItem(vtkNew<vtkOpaquePass>());
  steps->AddItem(vtkNew<vtkTranslucentPass>());
  steps->AddItem(vtkNew<vtkVolumetricPass>());
  steps->AddItem(vtkNew<vtkOverlayPass>());
  vtkNew<vtkSequencePass> sequence;
  sequence->SetPasses(steps);
  this->Impl->Delegate = sequence;
}

vtkPenumbraShadowPass::~vtkPenumbraShadowPass() = default;

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

void vtkPenumbraShadowPass::SetDelegatePass(vtkRenderPass* pass)
{
  if (this->Impl->Delegate != pass)
  {
    this->Impl->Delegate = pass;
    this->Modified();
  }
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
  return this->Impl->SamplesPass;
}

vtkPenumbraViewSamples* vtkPenumbraShadowPass::GetViewSamples()
{
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
  return (index >= 0 && index < static_cast<int>(this->Impl->Visibility[0].size()))
    ? this->Impl->Visibility[0][static_cast<size_t>(index)].Get()
    : nullptr;
}

vtkFloatArray* vtkPenumbraShadowPass::GetLightFactor(int index)
{
  return (index >= 0 && index < static_cast<int>(this->Impl->Factor[0].size()))
    ? this->Impl->Factor[0][static_cast<size_t>(index)].Get()
    : nullptr;
}

vtkPenumbraViewSamples* vtkPenumbraShadowPass::GetTranslucentViewSamples()
{
  return this->Impl->HasTranslucentLayer ? this->Impl->TranslucentSamplesPass->GetSamples()
                                         : nullptr;
}

vtkFloatArray* vtkPenumbraShadowPass::GetTranslucentVisibility(int index)
{
  return (this->Impl->HasTranslucentLayer && index >= 0 &&
           index < static_cast<int>(this->Impl->Visibility[1].size()))
    ? this->Impl->Visibility[1][static_cast<size_t>(index)].Get()
    : nullptr;
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

  // Light positions must be final (headlights follow the camera) before shadows are cast.
  this->UpdateLightGeometry(ren);
  impl.Lights.clear();
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  while (vtkLight* light = lights->GetNextLight(it))
  {
    if (light->GetSwitch())
    {
      impl.Lights.emplace_back(light);
    }
  }
  impl.Visibility[0].assign(impl.Lights.size(), nullptr);
  impl.Visibility[1].assign(impl.Lights.size(), nullptr);
  impl.HasTranslucentLayer = false;
  bool anyShadowed = false;
  for (auto& light : impl.Lights)
  {
    anyShadowed = anyShadowed || (impl.Technique && Internals::CastsLight(light));
  }

  impl.ExtractionMs = impl.SamplesMs = impl.TechniqueMs = 0.0;
  double t = Now();
  bool geometryOk = false;
  if (anyShadowed)
  {
    geometryOk = impl.Geometry->Update(ren) != 0;
    if (!geometryOk)
    {
      vtkErrorMacro("Shadows disabled for this frame: " << impl.Geometry->GetErrorMessage());
    }
  }
  impl.ExtractionMs = 1000.0 * (Now() - t);

  int w = 0, h = 0, x = 0, y = 0;
  ren->GetTiledSizeAndOrigin(&w, &h, &x, &y);
  if (anyShadowed && geometryOk && w > 0 && h > 0)
  {
    t = Now();
    impl.SamplesPass->SetGeometry(impl.Geometry);
    impl.SamplesPass->Render(s);
    win->WaitForCompletion();

    // Translucent receivers: their nearest surface per pixel is a second sample layer
    // (translucent props are drawn after the opaque ones, over them, and need their own
    // visibility; the opaque samples hold the surface behind them).
    for (int i = 0; i < s->GetPropArrayCount() && !impl.HasTranslucentLayer; ++i)
    {
      impl.HasTranslucentLayer = IsTranslucentReceiver(s->GetPropArray()[i]);
    }
    if (impl.HasTranslucentLayer)
    {
      if (!impl.TranslucentSamplesPass)
      {
        impl.TranslucentSamplesPass = vtkSmartPointer<vtkPenumbraViewSamplesPass>::New();
        impl.TranslucentSamplesPass->TranslucentOn();
        impl.Stacked = vtkSmartPointer<vtkPenumbraViewSamples>::New();
      }
      impl.TranslucentSamplesPass->SetGeometry(impl.Geometry);
      impl.TranslucentSamplesPass->Render(s);
      win->WaitForCompletion();
    }
    impl.SamplesMs = 1000.0 * (Now() - t);

    t = Now();
    vtkPenumbraViewSamples* samples = impl.SamplesPass->GetSamples();
    DropNonReceivers(impl.Geometry, samples);
    vtkPenumbraViewSamples* work = samples;
    if (impl.HasTranslucentLayer)
    {
      vtkPenumbraViewSamples* translucent = impl.TranslucentSamplesPass->GetSamples();
      DropNonReceivers(impl.Geometry, translucent);
      Stack(samples, translucent, impl.Stacked);
      work = impl.Stacked;
    }
    const vtkIdType n = samples->GetNumberOfSamples();
    // Every light that casts light, in one call: techniques may share work between lights
    // (shadow volumes count four lights per RGBA mask, seed 004 ch. 8).
    vtkNew<vtkLightCollection> casting;
    vtkNew<vtkCollection> results;
    std::vector<size_t> index;
    for (size_t i = 0; i < impl.Lights.size(); ++i)
    {
      if (!Internals::CastsLight(impl.Lights[i]))
      {
        continue; // black or zero-intensity light: nothing to shadow
      }
      casting->AddItem(impl.Lights[i]);
      results->AddItem(Pooled(impl.ResultPool, i));
      index.push_back(i);
    }
    if (!index.empty())
    {
      impl.Technique->ComputeVisibilities(ren, impl.Geometry, work, casting, results);
    }
    for (size_t k = 0; k < index.size(); ++k)
    {
      const size_t i = index[k];
      auto* vis = vtkFloatArray::SafeDownCast(results->GetItemAsObject(static_cast<int>(k)));
      if (vis && vis->GetNumberOfTuples() == work->GetNumberOfSamples())
      {
        if (impl.HasTranslucentLayer)
        {
          impl.Visibility[0][i] = Slice(vis, 0, n, Pooled(impl.SlicePool[0], i));
          impl.Visibility[1][i] =
            Slice(vis, n, work->GetNumberOfSamples() - n, Pooled(impl.SlicePool[1], i));
        }
        else
        {
          impl.Visibility[0][i] = vis;
        }
      }
      else
      {
        vtkErrorMacro("Light " << i << " rendered without shadows: the technique failed");
      }
    }
    impl.TechniqueMs = 1000.0 * (Now() - t);
  }
  for (int layer = 0; layer < 2; ++layer)
  {
    vtkPenumbraViewSamples* layerSamples = layer == 0 ? impl.SamplesPass->GetSamples()
      : impl.HasTranslucentLayer                     ? impl.TranslucentSamplesPass->GetSamples()
                                                     : nullptr;
    impl.Factor[layer].assign(impl.Lights.size(), nullptr);
    for (size_t i = 0; i < impl.Lights.size() && layerSamples; ++i)
    {
      impl.Factor[layer][i] =
        ScaleByDiagram(impl.Lights[i], layerSamples, impl.Visibility[layer][i],
          impl.ScaledPool[layer], i);
    }
  }

  // Upload: 4 lights per RGBA texture and layer; unshadowed lights and background read 1.
  int injected = 0;
  for (size_t i = 0; i < impl.Visibility[0].size(); ++i)
  {
    if (impl.Visibility[0][i])
    {
      injected = static_cast<int>(i) + 1;
    }
  }
  impl.SetInjectedLights(injected);
  const int textures = (injected + 3) / 4;
  std::vector<float>& texels = impl.Texels;
  for (int layer = 0; layer < 2; ++layer)
  {
    const bool used = layer == 0 || impl.HasTranslucentLayer;
    impl.Textures[layer].resize(used ? static_cast<size_t>(textures) : 0);
    for (int k = 0; used && k < textures; ++k)
    {
      const vtkIdType n = static_cast<vtkIdType>(w) * h;
      texels.assign(static_cast<size_t>(4 * n), 1.0f);
      for (int c = 0; c < 4; ++c)
      {
        const size_t light = static_cast<size_t>(4 * k + c);
        vtkFloatArray* vis =
          light < impl.Factor[layer].size() ? impl.Factor[layer][light].Get() : nullptr;
        if (!vis)
        {
          continue;
        }
        const float* v = vis->GetPointer(0);
        for (vtkIdType p = 0; p < n; ++p)
        {
          texels[static_cast<size_t>(4 * p + c)] = v[p] < 0.0f ? 1.0f : v[p];
        }
      }
      auto& tex = impl.Textures[layer][static_cast<size_t>(k)];
    if (!tex)
    {
      tex = vtkSmartPointer<vtkTextureObject>::New();
      tex->SetContext(win);
      tex->SetMinificationFilter(vtkTextureObject::Nearest);
      tex->SetMagnificationFilter(vtkTextureObject::Nearest);
      tex->SetWrapS(vtkTextureObject::ClampToEdge);
      tex->SetWrapT(vtkTextureObject::ClampToEdge);
    }
    tex->SetInternalFormat(GL_RGBA32F);
    tex->SetFormat(GL_RGBA);
    tex->SetDataType(GL_FLOAT);
    tex->Create2DFromRaw(w, h, 4, VTK_FLOAT, texels.data());
    }
  }

  t = Now();
  for (auto& layer : impl.Textures)
  {
    for (auto& tex : layer)
    {
      tex->Activate();
    }
  }
  this->PreRender(s);
  impl.Delegate->Render(s);
  this->NumberOfRenderedProps = impl.Delegate->GetNumberOfRenderedProps();
  this->PostRender(s);
  for (auto& layer : impl.Textures)
  {
    for (auto& tex : layer)
    {
      tex->Deactivate();
    }
  }
  win->WaitForCompletion();
  impl.ShadingMs = 1000.0 * (Now() - t);
}

vtkMTimeType vtkPenumbraShadowPass::GetShaderStageMTime()
{
  return this->Impl->ShaderTime.GetMTime();
}

bool vtkPenumbraShadowPass::PreReplaceShaderValues(std::string&, std::string&,
  std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop)
{
  // Translucent props read the translucent layer's visibility: the opaque samples hold the
  // surface behind them.
  if (this->Impl->InjectedLights > 0 && vtkOpenGLPolyDataMapper::SafeDownCast(mapper) &&
    vtkPenumbraShadowKeys::ReceivesShadows(prop))
  {
    const int layer = IsTranslucentReceiver(prop) ? 1 : 0;
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::Light::Dec",
      std::string("//VTK::Light::Dec\n") + LayerTags[layer] + "\n", false);
  }
  return true;
}

bool vtkPenumbraShadowPass::PostReplaceShaderValues(
  std::string&, std::string&, std::string& fragmentShader, vtkAbstractMapper*, vtkProp*)
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
  // After VTK's light uniforms: rename each shadowed light's colour to colour x visibility.
  // A macro naming itself is not expanded again, so `lightColorN` inside it is the uniform.
  std::string dec = vtkPenumbraVisibilityDec;
  const Internals& impl = *this->Impl;
  const std::vector<std::string>& samplers = impl.SamplerNames[layer];
  for (const auto& name : samplers)
  {
    dec += "uniform sampler2D " + name + ";\n";
  }
  const char channels[] = "rgba";
  for (int i = 0; i < impl.InjectedLights; ++i)
  {
    const std::string color = "lightColor" + std::to_string(i);
    if (fragmentShader.find("uniform vec3 " + color + ";") == std::string::npos)
    {
      continue; // this shader does not light with light i
    }
    dec += "#define " + color + " (" + color + " * texelFetch(" + samplers[i / 4] +
      ", penumbraTexel(), 0)." + channels[i % 4] + ")\n";
  }
  vtkShaderProgram::Substitute(fragmentShader, tag, dec, false);
  return true;
}

bool vtkPenumbraShadowPass::SetShaderParameters(
  vtkShaderProgram* program, vtkAbstractMapper*, vtkProp*, vtkOpenGLVertexArrayObject*)
{
  Internals& impl = *this->Impl;
  if (impl.InjectedLights == 0 || !program->IsUniformUsed("penumbraViewportOrigin"))
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
    for (size_t k = 0; k < impl.Textures[layer].size(); ++k)
    {
      const char* name = impl.SamplerNames[layer][k].c_str();
      if (program->IsUniformUsed(name))
      {
        program->SetUniformi(name, impl.Textures[layer][k]->GetTextureUnit());
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
  for (auto& layer : impl.Textures)
  {
    for (auto& tex : layer)
    {
      tex->ReleaseGraphicsResources(w);
    }
    layer.clear();
  }
}

void vtkPenumbraShadowPass::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Technique: " << (this->Impl->Technique ? this->Impl->Technique->GetClassName() : "(none)")
     << "\n";
  os << indent << "Lights: " << this->Impl->Lights.size() << "\n";
}
