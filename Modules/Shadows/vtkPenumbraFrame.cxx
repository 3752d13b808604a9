#include "vtkPenumbraFrame.h"

#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraGoniometricLight.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraRemoteShadows.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include <algorithm>
#include <vector>

namespace
{
enum class Answer
{
  None,
  CPU,
  GPU,
  Shader // a ShaderLookup, its textures not written (yet): Resolve() writes them
};

// A pool slot that is created on first use and kept: frames reuse the same arrays (same
// sizes, no allocation) instead of paying page faults for 4 bytes per pixel and light.
vtkFloatArray* Pooled(std::vector<vtkSmartPointer<vtkFloatArray>>& pool, size_t i)
{
  if (pool.size() <= i)
  {
    pool.resize(i + 1);
  }
  if (!pool[i])
  {
    pool[i] = vtkSmartPointer<vtkFloatArray>::New();
    pool[i]->SetNumberOfComponents(1);
  }
  return pool[i];
}

using penumbra::Clock;
using penumbra::ElapsedMs;
}

struct vtkPenumbraFrame::Internals
{
  vtkWeakPointer<vtkRenderer> Renderer;
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  vtkWeakPointer<vtkPenumbraSceneGeometry> Geometry;
  vtkWeakPointer<vtkPenumbraRemoteShadows> Processes;
  vtkPenumbraViewSamplesPass* Layers[2] = { nullptr, nullptr };
  // Renders the layers' samples when they are first asked for (Begin()); empty once done.
  std::function<void()> PendingSamples;
  int NumberOfLayers = 0;
  int Width = 0, Height = 0;
  int NumberOfLights = 0;

  vtkSmartPointer<vtkPenumbraViewSamples> Stacked; // two layers: opaque rows, then translucent
  bool SamplesRead = false;
  vtkTimeStamp SamplesTime; // modified when the layers hold newly rendered samples

  struct Shadowed
  {
    vtkSmartPointer<vtkLight> Light;
    int Index = 0;
    Answer State = Answer::None;
    vtkSmartPointer<vtkFloatArray> Values;                  // CPU answers: stacked samples
    std::shared_ptr<vtkPenumbraFrame::ShaderLookup> Lookup; // kept once resolved
  };
  std::vector<Shadowed> Lights;
  // SetActiveLights(): the lights a technique sees, as indices into Lights; empty with
  // Subset false = all of them.
  std::vector<int> Active;
  bool Subset = false;

  // The entry of Lights that shadowed light `k` of the current view names, or nullptr.
  Shadowed* Slot(int k)
  {
    if (this->Subset)
    {
      if (k < 0 || static_cast<size_t>(k) >= this->Active.size())
      {
        return nullptr;
      }
      k = this->Active[static_cast<size_t>(k)];
    }
    return k >= 0 && static_cast<size_t>(k) < this->Lights.size()
      ? &this->Lights[static_cast<size_t>(k)]
      : nullptr;
  }

  // Per layer and pass light: the CPU copy (valid when Fresh), the diagram-scaled factor.
  std::vector<vtkSmartPointer<vtkFloatArray>> Visibility[2], Factor[2];
  std::vector<char> Fresh[2], HasFactor[2];

  // Per layer and light: an R32F visibility texture, and whether it holds this frame's
  // values yet (cleared or uploaded). One light a texture: a technique writes 4 bytes a
  // pixel with no channel mask, and CPU answers are uploaded straight from their arrays.
  std::vector<vtkSmartPointer<vtkTextureObject>> Textures[2];
  std::vector<char> Ready[2];
  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;

  Shadowed* Find(int index)
  {
    for (auto& l : this->Lights)
    {
      if (l.Index == index)
      {
        return &l;
      }
    }
    return nullptr;
  }

  vtkOpenGLFramebufferObject* Framebuffer()
  {
    if (!this->FBO)
    {
      this->FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
      this->FBO->SetContext(this->Window);
    }
    return this->FBO;
  }

  void AllocateTextures()
  {
    const int count = this->NumberOfLights;
    for (int layer = 0; layer < 2; ++layer)
    {
      auto& textures = this->Textures[layer];
      const size_t used = layer < this->NumberOfLayers ? static_cast<size_t>(count) : 0;
      for (size_t t = used; t < textures.size(); ++t)
      {
        textures[t]->ReleaseGraphicsResources(this->Window);
      }
      textures.resize(used);
      this->Ready[layer].assign(used, 0);
      for (auto& tex : textures)
      {
        if (!tex)
        {
          tex = vtkSmartPointer<vtkTextureObject>::New();
          tex->SetContext(this->Window);
          tex->SetMinificationFilter(vtkTextureObject::Nearest);
          tex->SetMagnificationFilter(vtkTextureObject::Nearest);
          tex->SetWrapS(vtkTextureObject::ClampToEdge);
          tex->SetWrapT(vtkTextureObject::ClampToEdge);
          tex->SetInternalFormat(GL_R32F);
          tex->SetFormat(GL_RED);
          tex->SetDataType(GL_FLOAT);
        }
        if (!tex->GetHandle() || static_cast<int>(tex->GetWidth()) != this->Width ||
          static_cast<int>(tex->GetHeight()) != this->Height)
        {
          tex->Allocate2D(this->Width, this->Height, 1, VTK_FLOAT);
        }
      }
    }
  }

  // Sets texture `t` (a light) of `layer` to -1 (no shadow work: lit), once per frame.
  void Clear(int layer, size_t t)
  {
    if (this->Ready[layer][t])
    {
      return;
    }
    vtkOpenGLState* ostate = this->Window->GetState();
    vtkOpenGLState::ScopedglClearColor clearColor(ostate);
    penumbra_gl::QuadPassState pass(
      ostate, this->Framebuffer(), { this->Textures[layer][t].Get() }, this->Width, this->Height);
    ostate->vtkglClearColor(-1.0, -1.0, -1.0, -1.0);
    ostate->vtkglClear(GL_COLOR_BUFFER_BIT);
    this->Ready[layer][t] = 1;
  }

  // Light `index`'s texture of `layer` into `out` (one value per sample).
  void ReadTexture(int layer, int index, vtkFloatArray* out)
  {
    out->SetNumberOfComponents(1);
    out->SetNumberOfTuples(static_cast<vtkIdType>(this->Width) * this->Height);
    vtkOpenGLState* ostate = this->Window->GetState();
    ostate->PushFramebufferBindings();
    vtkOpenGLFramebufferObject* fbo = this->Framebuffer();
    fbo->Bind();
    fbo->AddColorAttachment(0, this->Textures[layer][static_cast<size_t>(index)]);
    fbo->RemoveDepthAttachment();
    fbo->ActivateReadBuffer(0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, this->Width, this->Height, GL_RED, GL_FLOAT, out->GetPointer(0));
    ostate->PopFramebufferBindings();
    out->Modified();
  }
};

//------------------------------------------------------------------------------
struct vtkPenumbraFrame::VisibilityTarget::State
{
  penumbra_gl::QuadPassState Pass;

  State(vtkOpenGLState* gl, vtkOpenGLFramebufferObject* fbo, vtkTextureObject* target, int w, int h,
    vtkTextureObject* depth)
    : Pass(gl, fbo, { target }, w, h, depth)
  {
  }
};

vtkPenumbraFrame::VisibilityTarget::VisibilityTarget(State* state)
  : Saved(state)
{
}
vtkPenumbraFrame::VisibilityTarget::VisibilityTarget(VisibilityTarget&&) noexcept = default;
vtkPenumbraFrame::VisibilityTarget::~VisibilityTarget() = default;

//------------------------------------------------------------------------------
vtkStandardNewMacro(vtkPenumbraFrame);

vtkPenumbraFrame::vtkPenumbraFrame()
  : Impl(new Internals)
{
}

vtkPenumbraFrame::~vtkPenumbraFrame() = default;

vtkRenderer* vtkPenumbraFrame::GetRenderer()
{
  return this->Impl->Renderer;
}

vtkOpenGLRenderWindow* vtkPenumbraFrame::GetWindow()
{
  return this->Impl->Window;
}

vtkPenumbraSceneGeometry* vtkPenumbraFrame::GetGeometry()
{
  return this->Impl->Geometry;
}

vtkPenumbraRemoteShadows* vtkPenumbraFrame::GetProcesses()
{
  return this->Impl->Processes;
}

void vtkPenumbraFrame::SetProcesses(vtkPenumbraRemoteShadows* processes)
{
  this->Impl->Processes = processes;
}

int vtkPenumbraFrame::GetWidth()
{
  return this->Impl->Width;
}

int vtkPenumbraFrame::GetHeight()
{
  return this->Impl->Height;
}

int vtkPenumbraFrame::GetNumberOfLayers()
{
  return this->Impl->NumberOfLayers;
}

void vtkPenumbraFrame::EnsureSamples()
{
  Internals& impl = *this->Impl;
  if (impl.PendingSamples)
  {
    const std::function<void()> render = std::move(impl.PendingSamples);
    impl.PendingSamples = nullptr;
    render();
  }
}

void vtkPenumbraFrame::ForgetPendingSamples()
{
  this->Impl->PendingSamples = nullptr;
}

vtkPenumbraViewSamplesPass* vtkPenumbraFrame::GetLayer(int layer)
{
  this->EnsureSamples();
  return layer >= 0 && layer < this->Impl->NumberOfLayers ? this->Impl->Layers[layer] : nullptr;
}

vtkMTimeType vtkPenumbraFrame::GetSamplesTime()
{
  return this->Impl->SamplesTime.GetMTime();
}

bool vtkPenumbraFrame::GetSamplesReadBack()
{
  return this->Impl->SamplesRead;
}

vtkPenumbraViewSamples* vtkPenumbraFrame::GetSamples()
{
  Internals& impl = *this->Impl;
  this->EnsureSamples();
  if (impl.NumberOfLayers == 0)
  {
    return nullptr;
  }
  if (impl.NumberOfLayers == 1)
  {
    impl.SamplesRead = true;
    return impl.Layers[0]->GetSamples(); // read back on first request
  }
  if (!impl.SamplesRead)
  {
    const auto t = Clock::now();
    if (!impl.Stacked)
    {
      impl.Stacked = vtkSmartPointer<vtkPenumbraViewSamples>::New();
    }
    impl.Stacked->SetSize(impl.Width, 2 * impl.Height);
    impl.Layers[0]->ReadSamples(impl.Stacked, 0);
    impl.Layers[1]->ReadSamples(impl.Stacked, impl.Height);
    impl.SamplesRead = true;
    this->TransferTimeMs += ElapsedMs(t);
  }
  return impl.Stacked;
}

int vtkPenumbraFrame::GetNumberOfShadowedLights()
{
  return static_cast<int>(
    this->Impl->Subset ? this->Impl->Active.size() : this->Impl->Lights.size());
}

void vtkPenumbraFrame::SetActiveLights(const std::vector<int>& ks)
{
  this->Impl->Active.clear();
  for (int k : ks)
  {
    if (k >= 0 && static_cast<size_t>(k) < this->Impl->Lights.size())
    {
      this->Impl->Active.push_back(k);
    }
  }
  this->Impl->Subset = true;
}

void vtkPenumbraFrame::ClearActiveLights()
{
  this->Impl->Active.clear();
  this->Impl->Subset = false;
}

vtkLight* vtkPenumbraFrame::GetShadowedLight(int k)
{
  const auto* l = this->Impl->Slot(k);
  return l ? l->Light.Get() : nullptr;
}

int vtkPenumbraFrame::GetLightIndex(int k)
{
  const auto* l = this->Impl->Slot(k);
  return l ? l->Index : -1;
}

void vtkPenumbraFrame::SetVisibility(int k, vtkFloatArray* visibility)
{
  Internals& impl = *this->Impl;
  const vtkIdType expected = static_cast<vtkIdType>(impl.Width) * impl.Height * impl.NumberOfLayers;
  auto* slot = impl.Slot(k);
  if (!slot || !visibility || visibility->GetNumberOfTuples() != expected ||
    visibility->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro(
      "SetVisibility: light " << k << " needs one value per stacked sample (" << expected << ")");
    return;
  }
  auto& l = *slot;
  l.State = Answer::CPU;
  l.Values = visibility;
  l.Lookup = nullptr;
  for (int layer = 0; layer < impl.NumberOfLayers; ++layer)
  {
    impl.Fresh[layer][static_cast<size_t>(l.Index)] = 0;
  }
}

void vtkPenumbraFrame::MarkOnGPU(int k)
{
  Internals& impl = *this->Impl;
  auto* slot = impl.Slot(k);
  // A shader lookup stays one: its textures are written when asked for (Resolve()).
  if (slot && slot->State != Answer::Shader)
  {
    auto& l = *slot;
    l.State = Answer::GPU;
    l.Values = nullptr;
    for (int layer = 0; layer < impl.NumberOfLayers; ++layer)
    {
      impl.Fresh[layer][static_cast<size_t>(l.Index)] = 0;
    }
  }
}

vtkPenumbraFrame::ShaderLookup::~ShaderLookup() = default;

void vtkPenumbraFrame::SetShaderLookup(int k, std::shared_ptr<ShaderLookup> lookup)
{
  Internals& impl = *this->Impl;
  auto* slot = impl.Slot(k);
  if (!slot || !lookup)
  {
    vtkErrorMacro("SetShaderLookup: no shadowed light " << k << " or no lookup");
    return;
  }
  slot->State = Answer::Shader;
  slot->Values = nullptr;
  slot->Lookup = std::move(lookup);
  for (int layer = 0; layer < impl.NumberOfLayers; ++layer)
  {
    impl.Fresh[layer][static_cast<size_t>(slot->Index)] = 0;
  }
}

vtkPenumbraFrame::ShaderLookup* vtkPenumbraFrame::GetShaderLookup(int index)
{
  Internals& impl = *this->Impl;
  Internals::Shadowed* l = impl.Find(index);
  // A goniometric diagram scales the textures (Finish()): the shader does not know it.
  const bool scaled = l && impl.NumberOfLayers > 0 &&
    static_cast<size_t>(index) < impl.HasFactor[0].size() &&
    impl.HasFactor[0][static_cast<size_t>(index)];
  return l && l->State != Answer::None && !scaled ? l->Lookup.get() : nullptr;
}

// A shader lookup's textures, written on the first request: the lookup sees the frame with
// this light alone, as its technique saw it.
void vtkPenumbraFrame::Resolve(int index)
{
  Internals& impl = *this->Impl;
  Internals::Shadowed* l = impl.Find(index);
  if (!l || l->State != Answer::Shader)
  {
    return;
  }
  const std::vector<int> active = impl.Active;
  const bool subset = impl.Subset;
  impl.Active = { static_cast<int>(l - impl.Lights.data()) };
  impl.Subset = true;
  impl.Window->MakeCurrent();
  std::string error;
  const std::shared_ptr<ShaderLookup> lookup = l->Lookup;
  const bool ok = lookup->Resolve(this, error);
  impl.Active = active;
  impl.Subset = subset;
  l->State = Answer::GPU;
  if (!ok)
  {
    vtkErrorMacro("The visibility of light " << index << " could not be read: " << error);
  }
}

bool vtkPenumbraFrame::HasVisibility(int k)
{
  const auto* l = this->Impl->Slot(k);
  return l && l->State != Answer::None;
}

vtkPenumbraFrame::VisibilityTarget vtkPenumbraFrame::BindVisibilityTarget(int layer, int k)
{
  Internals& impl = *this->Impl;
  const int index = this->GetLightIndex(k);
  const size_t t = static_cast<size_t>(index);
  this->EnsureSamples(); // the target tests against the layer's depth
  impl.Clear(layer, t);
  return VisibilityTarget(new VisibilityTarget::State(impl.Window->GetState(), impl.Framebuffer(),
    impl.Textures[layer][t], impl.Width, impl.Height, impl.Layers[layer]->GetDepthTexture()));
}

const char* vtkPenumbraFrame::GetSurfaceQuadVS()
{
  return "//VTK::System::Dec\n"
         "in vec4 ndCoordIn;\n"
         "in vec2 texCoordIn;\n"
         "out vec2 texCoord;\n"
         "void main()\n"
         "{\n"
         "  gl_Position = vec4(ndCoordIn.xy, 1.0, 1.0);\n"
         "  texCoord = texCoordIn;\n"
         "}\n";
}

vtkFloatArray* vtkPenumbraFrame::GetVisibility(int layer, int index)
{
  Internals& impl = *this->Impl;
  this->Resolve(index);
  const Internals::Shadowed* l = impl.Find(index);
  if (layer < 0 || layer >= impl.NumberOfLayers || !l || l->State == Answer::None)
  {
    return nullptr;
  }
  const size_t i = static_cast<size_t>(index);
  vtkFloatArray* out = Pooled(impl.Visibility[layer], i);
  if (impl.Fresh[layer][i])
  {
    return out;
  }
  const auto t = Clock::now();
  if (l->State == Answer::CPU)
  {
    const vtkIdType n = static_cast<vtkIdType>(impl.Width) * impl.Height;
    if (impl.NumberOfLayers == 1)
    {
      return l->Values; // the technique's own array: no copy needed
    }
    else
    {
      out->SetNumberOfTuples(n);
      const float* src = l->Values->GetPointer(layer * n);
      std::copy(src, src + n, out->GetPointer(0));
      out->Modified();
    }
  }
  else
  {
    impl.Window->MakeCurrent();
    impl.ReadTexture(layer, index, out);
  }
  impl.Fresh[layer][i] = 1;
  this->TransferTimeMs += ElapsedMs(t);
  return out;
}

vtkFloatArray* vtkPenumbraFrame::GetLightFactor(int layer, int index)
{
  Internals& impl = *this->Impl;
  if (layer >= 0 && layer < impl.NumberOfLayers && index >= 0 &&
    static_cast<size_t>(index) < impl.HasFactor[layer].size() &&
    impl.HasFactor[layer][static_cast<size_t>(index)])
  {
    return impl.Factor[layer][static_cast<size_t>(index)];
  }
  return this->GetVisibility(layer, index);
}

vtkTextureObject* vtkPenumbraFrame::GetVisibilityTexture(int layer, int index)
{
  Internals& impl = *this->Impl;
  this->Resolve(index);
  const Internals::Shadowed* l = impl.Find(index);
  return layer >= 0 && layer < impl.NumberOfLayers && l && l->State != Answer::None
    ? impl.Textures[layer][static_cast<size_t>(index)].Get()
    : nullptr;
}

void vtkPenumbraFrame::Begin(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
  vtkPenumbraViewSamplesPass* opaque, vtkPenumbraViewSamplesPass* translucent, int numberOfLights,
  bool newSamples, std::function<void()> renderSamples)
{
  Internals& impl = *this->Impl;
  auto* win = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
  if (impl.Window && impl.Window != win)
  {
    this->Release(impl.Window);
  }
  impl.Renderer = renderer;
  impl.Window = win;
  impl.Geometry = geometry;
  impl.Layers[0] = opaque;
  impl.Layers[1] = translucent;
  impl.NumberOfLayers = translucent ? 2 : 1;
  int x = 0, y = 0;
  renderer->GetTiledSizeAndOrigin(&impl.Width, &impl.Height, &x, &y);
  impl.NumberOfLights = numberOfLights;
  impl.SamplesRead = impl.SamplesRead && !newSamples;
  if (newSamples)
  {
    impl.SamplesTime.Modified();
    impl.PendingSamples = std::move(renderSamples); // rendered already when empty
  }
  impl.Lights.clear();
  impl.Active.clear();
  impl.Subset = false;
  impl.AllocateTextures();
  for (int layer = 0; layer < 2; ++layer)
  {
    impl.Fresh[layer].assign(static_cast<size_t>(numberOfLights), 0);
    impl.HasFactor[layer].assign(static_cast<size_t>(numberOfLights), 0);
  }
  this->TransferTimeMs = 0.0;
}

void vtkPenumbraFrame::AddShadowedLight(vtkLight* light, int index)
{
  Internals& impl = *this->Impl;
  Internals::Shadowed l;
  l.Light = light;
  l.Index = index;
  impl.Lights.push_back(l);
  impl.NumberOfLights = std::max(impl.NumberOfLights, index + 1);
}

void vtkPenumbraFrame::Finish()
{
  Internals& impl = *this->Impl;
  const auto t0 = Clock::now();
  const vtkIdType n = static_cast<vtkIdType>(impl.Width) * impl.Height;
  // Goniometric diagram (Brabec 2003, §8.3.1): the shadow mask is scaled by the light's
  // relative intensity toward each sample. Done here, after any technique, so every
  // technique renders the diagram and the visibility stays the geometric one.
  for (const auto& l : impl.Lights)
  {
    auto* gonio = vtkPenumbraGoniometricLight::SafeDownCast(l.Light);
    if (!gonio || l.State == Answer::None)
    {
      continue;
    }
    vtkPenumbraViewSamples* samples = this->GetSamples();
    double lightWorld[3];
    gonio->GetTransformedPosition(lightWorld);
    for (int layer = 0; layer < impl.NumberOfLayers; ++layer)
    {
      const size_t i = static_cast<size_t>(l.Index);
      vtkFloatArray* scaled = Pooled(impl.Factor[layer], i);
      scaled->DeepCopy(this->GetVisibility(layer, l.Index));
      float* v = scaled->GetPointer(0);
      for (vtkIdType s = 0; s < n; ++s)
      {
        double w[3];
        if (v[s] > 0.0f && samples->GetWorldPosition(layer * n + s, w))
        {
          const double d[3] = { w[0] - lightWorld[0], w[1] - lightWorld[1], w[2] - lightWorld[2] };
          v[s] = static_cast<float>(v[s] * gonio->GetRelativeIntensity(d));
        }
      }
      impl.HasFactor[layer][i] = 1;
    }
  }

  // Upload the CPU answers (and diagram-scaled factors) straight from their arrays; clear the
  // textures of lights nothing wrote.
  for (int layer = 0; layer < impl.NumberOfLayers; ++layer)
  {
    for (const auto& l : impl.Lights)
    {
      const size_t i = static_cast<size_t>(l.Index);
      if (l.State == Answer::None || l.State == Answer::Shader)
      {
        continue; // a shader lookup's textures are written when asked for (Resolve())
      }
      if (l.State != Answer::CPU && !impl.HasFactor[layer][i])
      {
        impl.Clear(layer, i); // no-op when the technique wrote into it
        continue;
      }
      vtkFloatArray* values = this->GetLightFactor(layer, l.Index);
      impl.Textures[layer][i]->Create2DFromRaw(
        impl.Width, impl.Height, 1, VTK_FLOAT, values->GetPointer(0));
      impl.Ready[layer][i] = 1;
    }
  }
  this->TransferTimeMs += ElapsedMs(t0);
}

void vtkPenumbraFrame::Release(vtkWindow* window)
{
  Internals& impl = *this->Impl;
  impl.PendingSamples = nullptr;
  for (auto& layer : impl.Textures)
  {
    for (auto& tex : layer)
    {
      tex->ReleaseGraphicsResources(window);
    }
    layer.clear();
  }
  if (impl.FBO)
  {
    impl.FBO->ReleaseGraphicsResources(window);
    impl.FBO = nullptr;
  }
  impl.Lights.clear();
  impl.NumberOfLayers = 0;
}

void vtkPenumbraFrame::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Size: " << this->Impl->Width << " x " << this->Impl->Height << "\n";
  os << indent << "Layers: " << this->Impl->NumberOfLayers << "\n";
  os << indent << "ShadowedLights: " << this->Impl->Lights.size() << "\n";
}
