#include "vtkPenumbraViewSamplesPass.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkInformation.h"
#include "vtkOpenGLActor.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpaquePass.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLPolyDataMapper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkProp.h"
#include "vtkRenderState.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkTranslucentPass.h"
#include "vtk_glew.h"

#include "vtkPenumbraViewSamplesDec.h"
#include "vtkPenumbraViewSamplesImpl.h"

#include <map>
#include <vector>

struct vtkPenumbraViewSamplesPass::Internals
{
  vtkSmartPointer<vtkPenumbraSceneGeometry> Geometry;
  vtkSmartPointer<vtkPenumbraViewSamples> Samples = vtkSmartPointer<vtkPenumbraViewSamples>::New();
  vtkSmartPointer<vtkOpaquePass> Opaque = vtkSmartPointer<vtkOpaquePass>::New();
  vtkSmartPointer<vtkTranslucentPass> TranslucentPass =
    vtkSmartPointer<vtkTranslucentPass>::New();
  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  vtkSmartPointer<vtkTextureObject> Textures[3];
  vtkSmartPointer<vtkTextureObject> Depth;
  std::map<vtkProp*, int> PropIndex;
  // Read-back buffers, kept between frames: allocating the 48 bytes per pixel afresh each
  // frame (44 MB at 1280 x 720) cost 40-80 ms of page faults per frame on the test machine.
  std::vector<float> ReadBuffers[3];
  // The last Render(): size, frames, and whether Samples still holds an older frame.
  int Width = 0, Height = 0;
  double Origin[3] = { 0, 0, 0 };
  double CameraPosition[3] = { 0, 0, 0 };
  bool Stale = false;

  // Per-frame uniforms, computed once in double precision.
  vtkNew<vtkMatrix4x4> VCToRebasedTransposed;
  float CameraRebased[3] = { 0, 0, 0 };
  float ViewDirection[3] = { 0, 0, -1 };
  int Parallel = 0;

  void Allocate(vtkOpenGLRenderWindow* win, int w, int h)
  {
    if (!this->FBO)
    {
      this->FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
      this->FBO->SetContext(win);
    }
    for (auto& tex : this->Textures)
    {
      if (!tex)
      {
        tex = vtkSmartPointer<vtkTextureObject>::New();
        tex->SetContext(win);
        tex->SetFormat(GL_RGBA);
        tex->SetInternalFormat(GL_RGBA32F);
        tex->SetDataType(GL_FLOAT);
        tex->SetMinificationFilter(vtkTextureObject::Nearest);
        tex->SetMagnificationFilter(vtkTextureObject::Nearest);
        tex->SetWrapS(vtkTextureObject::ClampToEdge);
        tex->SetWrapT(vtkTextureObject::ClampToEdge);
        tex->Allocate2D(w, h, 4, VTK_FLOAT);
      }
      else if (static_cast<int>(tex->GetWidth()) != w || static_cast<int>(tex->GetHeight()) != h)
      {
        tex->Resize(w, h);
      }
    }
    if (!this->Depth)
    {
      this->Depth = vtkSmartPointer<vtkTextureObject>::New();
      this->Depth->SetContext(win);
      this->Depth->AllocateDepth(w, h, vtkTextureObject::Float32);
    }
    else if (static_cast<int>(this->Depth->GetWidth()) != w ||
      static_cast<int>(this->Depth->GetHeight()) != h)
    {
      this->Depth->Resize(w, h);
    }
  }
};

vtkStandardNewMacro(vtkPenumbraViewSamplesPass);

vtkPenumbraViewSamplesPass::vtkPenumbraViewSamplesPass()
  : Impl(new Internals)
{
  this->ActiveDrawBuffers = 3;
}

vtkPenumbraViewSamplesPass::~vtkPenumbraViewSamplesPass() = default;

void vtkPenumbraViewSamplesPass::SetGeometry(vtkPenumbraSceneGeometry* geometry)
{
  if (this->Impl->Geometry != geometry)
  {
    this->Impl->Geometry = geometry;
    this->Modified();
  }
}

vtkPenumbraSceneGeometry* vtkPenumbraViewSamplesPass::GetGeometry()
{
  return this->Impl->Geometry;
}

vtkTextureObject* vtkPenumbraViewSamplesPass::GetPositionTexture()
{
  return this->Impl->Textures[0];
}

vtkTextureObject* vtkPenumbraViewSamplesPass::GetNormalTexture()
{
  return this->Impl->Textures[1];
}

vtkTextureObject* vtkPenumbraViewSamplesPass::GetDepthTexture()
{
  return this->Impl->Depth;
}

vtkTextureObject* vtkPenumbraViewSamplesPass::GetPrimitiveTexture()
{
  return this->Impl->Textures[2];
}

void vtkPenumbraViewSamplesPass::Render(const vtkRenderState* s)
{
  Internals& impl = *this->Impl;
  this->NumberOfRenderedProps = 0;
  vtkRenderer* ren = s->GetRenderer();
  auto* win = vtkOpenGLRenderWindow::SafeDownCast(ren->GetRenderWindow());
  if (!impl.Geometry || !win)
  {
    vtkErrorMacro("View samples need a scene geometry and an OpenGL render window");
    return;
  }
  int w = 0, h = 0, x = 0, y = 0;
  ren->GetTiledSizeAndOrigin(&w, &h, &x, &y);
  if (w < 1 || h < 1)
  {
    return;
  }
  impl.Allocate(win, w, h);
  // The mapper only emits view-space positions and normals for lit shaders, and decides
  // that from the renderer's lighting complexity, which VTK computes when lights update.
  this->UpdateLightGeometry(ren);
  this->UpdateLights(ren);

  impl.PropIndex.clear();
  for (int i = 0; i < impl.Geometry->GetNumberOfProps(); ++i)
  {
    impl.PropIndex[impl.Geometry->GetProp(i)] = i;
  }

  // View coordinates -> world -> minus origin, composed in double and sent once as float.
  vtkCamera* cam = ren->GetActiveCamera();
  double origin[3];
  impl.Geometry->GetOrigin(origin);
  vtkNew<vtkMatrix4x4> vcToWorld;
  vtkMatrix4x4::Invert(cam->GetModelViewTransformMatrix(), vcToWorld);
  for (int r = 0; r < 3; ++r)
  {
    vcToWorld->SetElement(r, 3, vcToWorld->GetElement(r, 3) - origin[r]);
  }
  // vtkShaderProgram uploads row-major data as GLSL's column-major matrices.
  vtkMatrix4x4::Transpose(vcToWorld, impl.VCToRebasedTransposed);
  double camPos[3], dop[3];
  cam->GetPosition(camPos);
  cam->GetDirectionOfProjection(dop);
  for (int c = 0; c < 3; ++c)
  {
    impl.CameraRebased[c] = static_cast<float>(camPos[c] - origin[c]);
    impl.ViewDirection[c] = static_cast<float>(dop[c]);
  }
  impl.Parallel = cam->GetParallelProjection() ? 1 : 0;

  vtkOpenGLState* ostate = win->GetState();
  vtkOpenGLState::ScopedglEnableDisable blendSaver(ostate, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthSaver(ostate, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable scissorSaver(ostate, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglViewport viewportSaver(ostate);
  vtkOpenGLState::ScopedglScissor scissorBoxSaver(ostate);
  vtkOpenGLState::ScopedglClearColor clearSaver(ostate);

  ostate->PushFramebufferBindings();
  impl.FBO->Bind();
  impl.FBO->AddColorAttachment(0, impl.Textures[0]);
  impl.FBO->AddColorAttachment(1, impl.Textures[1]);
  impl.FBO->AddColorAttachment(2, impl.Textures[2]);
  impl.FBO->AddDepthAttachment(impl.Depth);
  impl.FBO->ActivateDrawBuffers(3);
  ostate->vtkglViewport(0, 0, w, h);
  ostate->vtkglScissor(0, 0, w, h);
  ostate->vtkglDisable(GL_SCISSOR_TEST);
  // Ids are stored as exact float values: blending must never touch them.
  ostate->vtkglDisable(GL_BLEND);
  ostate->vtkglEnable(GL_DEPTH_TEST);
  ostate->vtkglDepthMask(GL_TRUE);
  ostate->vtkglClearColor(0.0, 0.0, 0.0, 0.0);
  ostate->vtkglClearDepth(1.0);
  ostate->vtkglClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  this->PreRender(s);
  if (this->Translucent)
  {
    // vtkOpenGLActor turns depth writes off for translucent geometry unless told otherwise;
    // the nearest surface per pixel needs them (the override is removed afterwards).
    std::vector<vtkActor*> overridden;
    for (int i = 0; i < s->GetPropArrayCount(); ++i)
    {
      auto* actor = vtkActor::SafeDownCast(s->GetPropArray()[i]);
      if (actor && actor->GetVisibility() && actor->HasTranslucentPolygonalGeometry())
      {
        if (!actor->GetPropertyKeys())
        {
          actor->SetPropertyKeys(vtkNew<vtkInformation>());
        }
        if (!actor->GetPropertyKeys()->Has(vtkOpenGLActor::GLDepthMaskOverride()))
        {
          actor->GetPropertyKeys()->Set(vtkOpenGLActor::GLDepthMaskOverride(), 1);
          overridden.push_back(actor);
        }
      }
    }
    impl.TranslucentPass->Render(s);
    this->NumberOfRenderedProps = impl.TranslucentPass->GetNumberOfRenderedProps();
    for (vtkActor* actor : overridden)
    {
      actor->GetPropertyKeys()->Remove(vtkOpenGLActor::GLDepthMaskOverride());
    }
  }
  else
  {
    impl.Opaque->Render(s);
    this->NumberOfRenderedProps = impl.Opaque->GetNumberOfRenderedProps();
  }
  this->PostRender(s);

  impl.Width = w;
  impl.Height = h;
  std::copy(origin, origin + 3, impl.Origin);
  std::copy(camPos, camPos + 3, impl.CameraPosition);
  impl.Stale = true;
  ostate->PopFramebufferBindings();
}

vtkPenumbraViewSamples* vtkPenumbraViewSamplesPass::GetSamples()
{
  Internals& impl = *this->Impl;
  if (impl.Stale && impl.FBO)
  {
    impl.Samples->SetSize(impl.Width, impl.Height);
    this->ReadSamples(impl.Samples, 0);
    impl.Stale = false;
  }
  return impl.Samples;
}

bool vtkPenumbraViewSamplesPass::ReadSamples(vtkPenumbraViewSamples* target, int firstRow)
{
  Internals& impl = *this->Impl;
  const int w = impl.Width, h = impl.Height;
  if (!impl.FBO || !target || target->GetWidth() != w || firstRow < 0 ||
    target->GetHeight() < firstRow + h || !impl.Geometry)
  {
    vtkErrorMacro("ReadSamples: no samples rendered, or a target of the wrong size");
    return false;
  }
  auto* win = vtkOpenGLRenderWindow::SafeDownCast(impl.FBO->GetContext());
  win->MakeCurrent();
  target->SetOrigin(impl.Origin);
  target->SetCameraPosition(impl.CameraPosition);
  const vtkIdType n = static_cast<vtkIdType>(w) * h;
  std::vector<float>* buffers = impl.ReadBuffers;
  vtkOpenGLState* ostate = win->GetState();
  ostate->PushFramebufferBindings();
  impl.FBO->Bind();
  for (int a = 0; a < 3; ++a)
  {
    buffers[a].resize(static_cast<size_t>(n) * 4);
    impl.FBO->ActivateReadBuffer(a);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, buffers[a].data());
  }
  ostate->PopFramebufferBindings();
  const vtkIdType first = static_cast<vtkIdType>(firstRow) * w;
  float* pos = target->GetPositions()->GetPointer(3 * first);
  float* nrm = target->GetNormals()->GetPointer(3 * first);
  int* props = target->GetPropIndices()->GetPointer(first);
  vtkIdType* tris = target->GetTriangleIds()->GetPointer(first);
  vtkPenumbraSceneGeometry* geometry = impl.Geometry;
  vtkSMPTools::For(0, n, [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType i = begin; i < end; ++i)
    {
      const float* p = &buffers[0][static_cast<size_t>(4 * i)];
      const float* q = &buffers[1][static_cast<size_t>(4 * i)];
      const float* t = &buffers[2][static_cast<size_t>(4 * i)];
      const int prop = (p[3] > 0.5f && q[3] >= 0.0f) ? static_cast<int>(q[3]) : -1;
      props[i] = prop;
      for (int c = 0; c < 3; ++c)
      {
        pos[3 * i + c] = p[c];
        nrm[3 * i + c] = q[c];
      }
      const vtkIdType prim = static_cast<vtkIdType>(t[0]) + (static_cast<vtkIdType>(t[1]) << 16);
      tris[i] = prop >= 0 ? geometry->MapPrimitiveId(prop, prim) : -1; // read-only lookup
    }
  });
  target->Modified();
  return true;
}

bool vtkPenumbraViewSamplesPass::PreReplaceShaderValues(std::string&, std::string&,
  std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp*)
{
  if (vtkOpenGLPolyDataMapper::SafeDownCast(mapper))
  {
    // Our code goes after VTK's lighting, where vertexVC and the outputs exist.
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::Light::Dec",
      "//VTK::Light::Dec\n//PENUMBRA::Samples::Dec\n", false);
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::Light::Impl",
      "//VTK::Light::Impl\n//PENUMBRA::Samples::Impl\n", false);
  }
  return true;
}

bool vtkPenumbraViewSamplesPass::PostReplaceShaderValues(std::string&, std::string&,
  std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp*)
{
  if (!vtkOpenGLPolyDataMapper::SafeDownCast(mapper))
  {
    return true;
  }
  const bool hasPosition = fragmentShader.find("vec4 vertexVC") != std::string::npos;
  if (hasPosition)
  {
    std::string dec = vtkPenumbraViewSamplesDec;
    if (fragmentShader.find("uniform int PrimitiveIDOffset") == std::string::npos)
    {
      dec += "uniform int PrimitiveIDOffset;\n";
    }
    vtkShaderProgram::Substitute(fragmentShader, "//PENUMBRA::Samples::Dec", dec, false);
    vtkShaderProgram::Substitute(
      fragmentShader, "//PENUMBRA::Samples::Impl", vtkPenumbraViewSamplesImpl, false);
  }
  else
  {
    // Unlit props: occlude, but give no sample.
    vtkShaderProgram::Substitute(fragmentShader, "//PENUMBRA::Samples::Dec", "", false);
    vtkShaderProgram::Substitute(fragmentShader, "//PENUMBRA::Samples::Impl",
      "  gl_FragData[0] = vec4(0.0);\n  gl_FragData[1] = vec4(0.0, 0.0, 0.0, -1.0);\n"
      "  gl_FragData[2] = vec4(0.0);\n",
      false);
  }
  return true;
}

bool vtkPenumbraViewSamplesPass::SetShaderParameters(
  vtkShaderProgram* program, vtkAbstractMapper* mapper, vtkProp* prop, vtkOpenGLVertexArrayObject*)
{
  Internals& impl = *this->Impl;
  if (!vtkOpenGLPolyDataMapper::SafeDownCast(mapper))
  {
    return true;
  }
  if (impl.FBO)
  {
    impl.FBO->ActivateDrawBuffers(3);
  }
  if (program->IsUniformUsed("penumbraVCToRebased"))
  {
    auto it = impl.PropIndex.find(prop);
    program->SetUniformMatrix("penumbraVCToRebased", impl.VCToRebasedTransposed);
    program->SetUniform3f("penumbraCameraRebased", impl.CameraRebased);
    program->SetUniform3f("penumbraViewDirection", impl.ViewDirection);
    program->SetUniformi("penumbraParallel", impl.Parallel);
    // Props that do not receive shadows give no sample: they are lit unshadowed and get no
    // shadow work (they still occlude the samples behind them).
    const bool sampled = it != impl.PropIndex.end() && vtkPenumbraShadowKeys::ReceivesShadows(prop);
    program->SetUniformf("penumbraPropIndex", sampled ? static_cast<float>(it->second) : -1.0f);
  }
  return true;
}

void vtkPenumbraViewSamplesPass::ReleaseGraphicsResources(vtkWindow* w)
{
  Internals& impl = *this->Impl;
  impl.Opaque->ReleaseGraphicsResources(w);
  impl.TranslucentPass->ReleaseGraphicsResources(w);
  for (auto& tex : impl.Textures)
  {
    if (tex)
    {
      tex->ReleaseGraphicsResources(w);
    }
    tex = nullptr;
  }
  if (impl.Depth)
  {
    impl.Depth->ReleaseGraphicsResources(w);
  }
  impl.Depth = nullptr;
  if (impl.FBO)
  {
    impl.FBO->ReleaseGraphicsResources(w);
  }
  impl.FBO = nullptr;
}

void vtkPenumbraViewSamplesPass::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Translucent: " << this->Translucent << "\n";
}
