#include "vtkPenumbraViewSamplesPass.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpaquePass.h"
#include "vtkOpenGLActor.h"
#include "vtkOpenGLCamera.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLPolyDataMapper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraMapperDraws.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkProp.h"
#include "vtkProperty.h"
#include "vtkRenderState.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSkybox.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkTranslucentPass.h"
#include "vtk_glew.h"

#include "vtkPenumbraSurfaceDec.h"
#include "vtkPenumbraViewSamplesDec.h"
#include "vtkPenumbraViewSamplesImpl.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace
{
// Binds a framebuffer for reading and packs rows tightly; restores both on exit.
class ScopedReadFramebuffer
{
public:
  ScopedReadFramebuffer(vtkOpenGLState* state, vtkOpenGLFramebufferObject* fbo)
    : State(state)
  {
    this->State->PushFramebufferBindings();
    fbo->Bind();
    glGetIntegerv(GL_PACK_ALIGNMENT, &this->PackAlignment);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
  }
  ~ScopedReadFramebuffer()
  {
    glPixelStorei(GL_PACK_ALIGNMENT, this->PackAlignment);
    this->State->PopFramebufferBindings();
  }
  ScopedReadFramebuffer(const ScopedReadFramebuffer&) = delete;
  void operator=(const ScopedReadFramebuffer&) = delete;

private:
  vtkOpenGLState* State;
  GLint PackAlignment = 4;
};

// Where the fragment's surface is computed (GetSurfaceCall()), in uniform control flow.
const char* const SurfaceTag = "//PENUMBRA::Samples::Surface";

// Prop index of a primitive-target texel (x, y: primitive id halves, z: prop, w: valid).
inline int SamplePropIndex(const float* t)
{
  return (t[3] > 0.5f && t[2] >= 0.0f) ? static_cast<int>(t[2]) : -1;
}

inline vtkIdType SamplePrimitiveId(const float* t)
{
  return static_cast<vtkIdType>(t[0]) + (static_cast<vtkIdType>(t[1]) << 16);
}

// The point of triangle (a, b, c) closest to p, a point of its plane (Ericson, "Real-Time
// Collision Detection", 2005, section 5.1.5), for intersections that the rasterizer's
// snapped vertices put a hair outside the exact triangle.
void ClosestPointOnTriangle(
  const double a[3], const double b[3], const double c[3], const double p[3], double out[3])
{
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int k = 0; k < 3; ++k)
  {
    ab[k] = b[k] - a[k];
    ac[k] = c[k] - a[k];
    ap[k] = p[k] - a[k];
    bp[k] = p[k] - b[k];
    cp[k] = p[k] - c[k];
  }
  const double d1 = vtkMath::Dot(ab, ap), d2 = vtkMath::Dot(ac, ap), d3 = vtkMath::Dot(ab, bp),
               d4 = vtkMath::Dot(ac, bp);
  const double d5 = vtkMath::Dot(ab, cp), d6 = vtkMath::Dot(ac, cp);
  const double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  double u = 0.0, v = 0.0; // out = a + u ab + v ac
  if (d1 <= 0.0 && d2 <= 0.0)
  {
  }
  else if (d3 >= 0.0 && d4 <= d3)
  {
    u = 1.0;
  }
  else if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
  {
    u = d1 / (d1 - d3);
  }
  else if (d6 >= 0.0 && d5 <= d6)
  {
    v = 1.0;
  }
  else if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
  {
    v = d2 / (d2 - d6);
  }
  else if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
  {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    u = 1.0 - w;
    v = w;
  }
  else
  {
    std::copy(p, p + 3, out); // inside: the plane point itself
    return;
  }
  for (int k = 0; k < 3; ++k)
  {
    out[k] = a[k] + u * ab[k] + v * ac[k];
  }
}

// Rebuilds one sample from its triangle (three rebased double vertices) and the camera ray
// through the pixel centre (origin o, direction d, rebased). Returns false when the triangle
// has no normal or the ray runs parallel to its plane: the intersection is then undefined.
bool RebuildSample(
  const double* v, const double o[3], const double d[3], float pos[3], float nrm[3])
{
  const double e1[3] = { v[3] - v[0], v[4] - v[1], v[5] - v[2] };
  const double e2[3] = { v[6] - v[0], v[7] - v[1], v[8] - v[2] };
  double n[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
    e1[0] * e2[1] - e1[1] * e2[0] };
  const double len = std::sqrt(vtkMath::Dot(n, n));
  const double denom = vtkMath::Dot(n, d);
  // 1e-12: the geometry's own zero-area rule, here on the angle between ray and plane.
  if (!(len > 0.0) || !std::isfinite(len) ||
    !(std::fabs(denom) > 1e-12 * len * std::sqrt(vtkMath::Dot(d, d))))
  {
    return false;
  }
  const double toV0[3] = { v[0] - o[0], v[1] - o[1], v[2] - o[2] };
  const double t = vtkMath::Dot(n, toV0) / denom;
  const double hit[3] = { o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2] };
  double onTriangle[3];
  ClosestPointOnTriangle(v, v + 3, v + 6, hit, onTriangle);
  // Turned toward the camera, as the shader does: against the ray's direction.
  const double sign = denom > 0.0 ? -1.0 / len : 1.0 / len;
  for (int k = 0; k < 3; ++k)
  {
    pos[k] = static_cast<float>(onTriangle[k]);
    nrm[k] = static_cast<float>(sign * n[k]);
  }
  return true;
}
}

struct vtkPenumbraViewSamplesPass::Internals
{
  vtkSmartPointer<vtkPenumbraSceneGeometry> Geometry;
  vtkSmartPointer<vtkPenumbraViewSamples> Samples = vtkSmartPointer<vtkPenumbraViewSamples>::New();
  vtkSmartPointer<vtkOpaquePass> Opaque = vtkSmartPointer<vtkOpaquePass>::New();
  vtkSmartPointer<vtkTranslucentPass> TranslucentPass = vtkSmartPointer<vtkTranslucentPass>::New();
  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  vtkSmartPointer<vtkTextureObject> Textures[3];
  vtkSmartPointer<vtkTextureObject> Depth;
  std::map<vtkProp*, int> PropIndex;
  // The same indices by the props' property keys: see FindPropIndex().
  std::map<vtkInformation*, int> KeysIndex;

  // The scene-geometry index of the prop a mapper draws for, or -1. Some actors draw through
  // another actor: ParaView's vtkPVLODActor renders its mapper through an internal "Device"
  // vtkActor that is in no renderer, so the mapper hands that device to the pass hooks. The
  // device shares the outer actor's property keys (where the shadow flags live too), so a
  // prop not found by pointer is matched by its keys.
  int FindPropIndex(vtkProp* prop) const
  {
    auto it = this->PropIndex.find(prop);
    if (it != this->PropIndex.end())
    {
      return it->second;
    }
    vtkInformation* keys = prop ? prop->GetPropertyKeys() : nullptr;
    auto byKeys = keys ? this->KeysIndex.find(keys) : this->KeysIndex.end();
    return byKeys != this->KeysIndex.end() ? byKeys->second : -1;
  }
  // Read-back buffers, kept between frames: 48 bytes per pixel allocated afresh each frame
  // would be paged in again every frame, a cost that grows with the window.
  std::vector<float> ReadBuffers[3];
  std::vector<unsigned char> Fallback; // per sample: keeps the G-buffer's position
  vtkIdType NumberOfFallbacks = 0;
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
  // Samples per pixel of the framebuffer last drawn into, and their offsets from the pixel
  // centre (see penumbraCoveredOffset() in vtkPenumbraSurfaceDec.glsl).
  int SampleCount = 0;
  float SampleOffsets[32] = {};
  // Normalized device coordinates -> rebased world (homogeneous, row-major), in double: a
  // pixel centre's camera ray for rebuilding positions from triangles.
  double NDCToRebased[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };

  // The camera ray through the centre of pixel (x, y): from the near to the far plane.
  void PixelRay(int x, int y, double o[3], double d[3]) const
  {
    const double nx = 2.0 * (x + 0.5) / this->Width - 1.0;
    const double ny = 2.0 * (y + 0.5) / this->Height - 1.0;
    double ends[2][3];
    for (int e = 0; e < 2; ++e)
    {
      const double ndc[4] = { nx, ny, e == 0 ? -1.0 : 1.0, 1.0 };
      double h[4];
      for (int r = 0; r < 4; ++r)
      {
        const double* m = this->NDCToRebased + 4 * r;
        h[r] = m[0] * ndc[0] + m[1] * ndc[1] + m[2] * ndc[2] + m[3] * ndc[3];
      }
      for (int k = 0; k < 3; ++k)
      {
        ends[e][k] = h[k] / h[3];
      }
    }
    for (int k = 0; k < 3; ++k)
    {
      o[k] = ends[0][k];
      d[k] = ends[1][k] - ends[0][k];
    }
  }

  void ReadRows(int attachment, int firstRow, int rows, float* out)
  {
    this->FBO->ActivateReadBuffer(attachment);
    glReadPixels(0, firstRow, this->Width, rows, GL_RGBA, GL_FLOAT, out);
  }

  void ComputeNDCToRebased(vtkRenderer* ren, vtkMatrix4x4* vcToRebased);
  bool UnpackGBuffer(vtkPenumbraViewSamples* target, vtkIdType first);
  void RebuildFromTriangles(vtkPenumbraViewSamples* target, vtkIdType first);
  void ReadFallbacks(vtkPenumbraViewSamples* target, vtkIdType first);

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

  this->UpdateView(ren);
  impl.Width = w;
  impl.Height = h;

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

  // Props whose drawing does not go through the shader hooks would write their colours
  // into the sample targets: they only occlude. Drawn first, depth only, so that the
  // samples behind them fail the depth test and their pixels keep "no sample"; a skybox is
  // behind everything and occludes nothing. In the translucent layer they are left out.
  std::vector<vtkProp*> hooked, occluding;
  for (int i = 0; i < s->GetPropArrayCount(); ++i)
  {
    vtkProp* prop = s->GetPropArray()[i];
    if (penumbra_draws::DrawsThroughHooks(prop))
    {
      hooked.push_back(prop);
    }
    else if (!vtkSkybox::SafeDownCast(prop))
    {
      occluding.push_back(prop);
    }
  }
  vtkRenderState hookedState(ren);
  hookedState.SetPropArrayAndCount(hooked.data(), static_cast<int>(hooked.size()));
  hookedState.SetFrameBuffer(s->GetFrameBuffer());

  this->PreRender(&hookedState);
  // After PreRender(), which gives every drawn prop its property keys (a LOD actor draws
  // through a device actor that shares them).
  this->IndexProps();
  if (this->Translucent)
  {
    // vtkOpenGLActor turns depth writes off for translucent geometry unless told otherwise;
    // the nearest surface per pixel needs them (the override is removed afterwards).
    std::vector<vtkActor*> overridden;
    for (vtkProp* prop : hooked)
    {
      auto* actor = vtkActor::SafeDownCast(prop);
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
    impl.TranslucentPass->Render(&hookedState);
    this->NumberOfRenderedProps = impl.TranslucentPass->GetNumberOfRenderedProps();
    for (vtkActor* actor : overridden)
    {
      actor->GetPropertyKeys()->Remove(vtkOpenGLActor::GLDepthMaskOverride());
    }
  }
  else
  {
    if (!occluding.empty())
    {
      vtkRenderState occludingState(ren);
      occludingState.SetPropArrayAndCount(occluding.data(), static_cast<int>(occluding.size()));
      occludingState.SetFrameBuffer(s->GetFrameBuffer());
      vtkOpenGLState::ScopedglColorMask colorMaskSaver(ostate);
      ostate->vtkglColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      impl.Opaque->Render(&occludingState);
    }
    impl.Opaque->Render(&hookedState);
    this->NumberOfRenderedProps = impl.Opaque->GetNumberOfRenderedProps();
  }
  this->PostRender(&hookedState);

  // What the samples were rendered with (the samples' metadata, see GetSamples()).
  impl.Geometry->GetOrigin(impl.Origin);
  ren->GetActiveCamera()->GetPosition(impl.CameraPosition);
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
  const vtkIdType first = static_cast<vtkIdType>(firstRow) * w;
  impl.NumberOfFallbacks = 0;
  if (this->ReadBackMode == READ_BACK_POSITIONS)
  {
    ScopedReadFramebuffer bound(win->GetState(), impl.FBO);
    for (int a = 0; a < 3; ++a)
    {
      impl.ReadBuffers[a].resize(static_cast<size_t>(n) * 4);
      impl.ReadRows(a, 0, h, impl.ReadBuffers[a].data());
    }
  }
  else
  {
    ScopedReadFramebuffer bound(win->GetState(), impl.FBO);
    impl.ReadBuffers[2].resize(static_cast<size_t>(n) * 4);
    impl.ReadRows(2, 0, h, impl.ReadBuffers[2].data());
  }
  if (this->ReadBackMode == READ_BACK_POSITIONS)
  {
    impl.UnpackGBuffer(target, first);
  }
  else
  {
    impl.RebuildFromTriangles(target, first);
    impl.ReadFallbacks(target, first);
  }
  // The read-back buffers (up to 48 bytes a pixel) are not kept between reads.
  for (std::vector<float>& buffer : impl.ReadBuffers)
  {
    std::vector<float>().swap(buffer);
  }
  std::vector<unsigned char>().swap(impl.Fallback);
  target->Modified();
  return true;
}

vtkIdType vtkPenumbraViewSamplesPass::GetNumberOfFallbackSamples()
{
  return this->Impl->NumberOfFallbacks;
}

void vtkPenumbraViewSamplesPass::Internals::ComputeNDCToRebased(
  vtkRenderer* ren, vtkMatrix4x4* vcToRebased)
{
  // The projection the mappers drew with: vtkOpenGLCamera's key matrices (stored transposed
  // for OpenGL) include the renderer's aspect corrections and tiling.
  vtkNew<vtkMatrix4x4> vcToNDC;
  auto* glCam = vtkOpenGLCamera::SafeDownCast(ren->GetActiveCamera());
  if (glCam)
  {
    vtkMatrix4x4 *wcvc = nullptr, *vcdc = nullptr, *wcdc = nullptr;
    vtkMatrix3x3* normals = nullptr;
    glCam->GetKeyMatrices(ren, wcvc, normals, vcdc, wcdc);
    vtkMatrix4x4::Transpose(vcdc, vcToNDC);
  }
  else
  {
    vcToNDC->DeepCopy(ren->GetActiveCamera()->GetProjectionTransformMatrix(
      static_cast<double>(this->Width) / this->Height, -1.0, 1.0));
  }
  vtkNew<vtkMatrix4x4> ndcToVC;
  vtkMatrix4x4::Invert(vcToNDC, ndcToVC);
  vtkNew<vtkMatrix4x4> ndcToRebased;
  vtkMatrix4x4::Multiply4x4(vcToRebased, ndcToVC, ndcToRebased);
  std::copy(&ndcToRebased->Element[0][0], &ndcToRebased->Element[0][0] + 16, this->NDCToRebased);
}

// READ_BACK_POSITIONS: every array comes from the three float32 targets.
bool vtkPenumbraViewSamplesPass::Internals::UnpackGBuffer(
  vtkPenumbraViewSamples* target, vtkIdType first)
{
  const vtkIdType n = static_cast<vtkIdType>(this->Width) * this->Height;
  float* pos = target->GetPositions()->GetPointer(3 * first);
  float* nrm = target->GetNormals()->GetPointer(3 * first);
  int* props = target->GetPropIndices()->GetPointer(first);
  vtkIdType* tris = target->GetTriangleIds()->GetPointer(first);
  vtkPenumbraSceneGeometry* geometry = this->Geometry;
  const std::vector<float>* buffers = this->ReadBuffers;
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        const float* p = &buffers[0][static_cast<size_t>(4 * i)];
        const float* q = &buffers[1][static_cast<size_t>(4 * i)];
        const float* t = &buffers[2][static_cast<size_t>(4 * i)];
        const int prop = SamplePropIndex(t);
        props[i] = prop;
        for (int c = 0; c < 3; ++c)
        {
          pos[3 * i + c] = p[c];
          nrm[3 * i + c] = q[c];
        }
        tris[i] = prop >= 0 ? geometry->MapPrimitiveId(prop, SamplePrimitiveId(t)) : -1;
      }
    });
  return true;
}

// READ_BACK_IDS: ids from the primitive target, position and normal from the triangle and
// the pixel's camera ray in double precision. Samples that cannot be rebuilt are flagged in
// Fallback for ReadFallbacks().
void vtkPenumbraViewSamplesPass::Internals::RebuildFromTriangles(
  vtkPenumbraViewSamples* target, vtkIdType first)
{
  const int w = this->Width;
  const vtkIdType n = static_cast<vtkIdType>(w) * this->Height;
  this->Fallback.assign(static_cast<size_t>(n), 0);
  float* pos = target->GetPositions()->GetPointer(3 * first);
  float* nrm = target->GetNormals()->GetPointer(3 * first);
  int* props = target->GetPropIndices()->GetPointer(first);
  vtkIdType* tris = target->GetTriangleIds()->GetPointer(first);
  vtkPenumbraSceneGeometry* geometry = this->Geometry;
  const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
  const std::vector<float>& ids = this->ReadBuffers[2];
  unsigned char* fallback = this->Fallback.data();
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        const float* t = &ids[static_cast<size_t>(4 * i)];
        const int prop = SamplePropIndex(t);
        const vtkIdType tri = prop >= 0 ? geometry->MapPrimitiveId(prop, SamplePrimitiveId(t)) : -1;
        props[i] = prop;
        tris[i] = tri;
        std::fill(pos + 3 * i, pos + 3 * i + 3, 0.0f);
        std::fill(nrm + 3 * i, nrm + 3 * i + 3, 0.0f);
        if (prop < 0)
        {
          continue;
        }
        double o[3], d[3];
        this->PixelRay(static_cast<int>(i % w), static_cast<int>(i / w), o, d);
        double v[9];
        if (tri < 0 || (triangles.Get(tri, v), !RebuildSample(v, o, d, pos + 3 * i, nrm + 3 * i)))
        {
          fallback[i] = 1;
        }
      }
    });
}

// The flagged samples keep the G-buffer's float32 position and normal: the rows holding
// them are read from the position and normal targets, in runs of consecutive rows.
void vtkPenumbraViewSamplesPass::Internals::ReadFallbacks(
  vtkPenumbraViewSamples* target, vtkIdType first)
{
  const int w = this->Width, h = this->Height;
  std::vector<char> rowNeeded(static_cast<size_t>(h), 0);
  for (int y = 0; y < h; ++y)
  {
    const unsigned char* row = this->Fallback.data() + static_cast<size_t>(y) * w;
    const vtkIdType count = std::count(row, row + w, static_cast<unsigned char>(1));
    rowNeeded[y] = count > 0;
    this->NumberOfFallbacks += count;
  }
  if (this->NumberOfFallbacks == 0)
  {
    return;
  }
  float* pos = target->GetPositions()->GetPointer(3 * first);
  float* nrm = target->GetNormals()->GetPointer(3 * first);
  auto* win = vtkOpenGLRenderWindow::SafeDownCast(this->FBO->GetContext());
  ScopedReadFramebuffer bound(win->GetState(), this->FBO);
  for (int a = 0; a < 2; ++a)
  {
    this->ReadBuffers[a].resize(static_cast<size_t>(w) * h * 4);
  }
  for (int y0 = 0; y0 < h;)
  {
    if (!rowNeeded[y0])
    {
      ++y0;
      continue;
    }
    int y1 = y0;
    while (y1 < h && rowNeeded[y1])
    {
      ++y1;
    }
    const size_t offset = static_cast<size_t>(y0) * w * 4;
    this->ReadRows(0, y0, y1 - y0, this->ReadBuffers[0].data() + offset);
    this->ReadRows(1, y0, y1 - y0, this->ReadBuffers[1].data() + offset);
    for (vtkIdType i = static_cast<vtkIdType>(y0) * w; i < static_cast<vtkIdType>(y1) * w; ++i)
    {
      if (this->Fallback[i])
      {
        for (int c = 0; c < 3; ++c)
        {
          pos[3 * i + c] = this->ReadBuffers[0][static_cast<size_t>(4 * i + c)];
          nrm[3 * i + c] = this->ReadBuffers[1][static_cast<size_t>(4 * i + c)];
        }
      }
    }
    y0 = y1;
  }
}

bool vtkPenumbraViewSamplesPass::PreReplaceShaderValues(
  std::string&, std::string&, std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp*)
{
  // Once, even when the prop holds this pass twice in its keys (an actor drawn by itself and
  // as the part of an assembly, which lends the part its own keys).
  if (vtkOpenGLPolyDataMapper::SafeDownCast(mapper) &&
    fragmentShader.find("//PENUMBRA::Samples::Dec") == std::string::npos)
  {
    // Our outputs are written last in main(), after VTK's lighting, texturing (which
    // multiplies the colour output), its discard of fragments with alpha <= 0 (an alpha
    // cut-out gives no sample) and its coincident-topology depth: at the end of main(), the
    // last function of VTK's shader templates.
    vtkShaderProgram::Substitute(
      fragmentShader, "//VTK::Light::Dec", "//VTK::Light::Dec\n//PENUMBRA::Samples::Dec\n", false);
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::UniformFlow::Impl",
      std::string("//VTK::UniformFlow::Impl\n") + SurfaceTag + "\n", false);
    const size_t endOfMain = fragmentShader.rfind('}');
    if (endOfMain != std::string::npos)
    {
      fragmentShader.insert(endOfMain, "//PENUMBRA::Samples::Impl\n");
    }
  }
  return true;
}

bool vtkPenumbraViewSamplesPass::PostReplaceShaderValues(
  std::string&, std::string&, std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop)
{
  if (!vtkOpenGLPolyDataMapper::SafeDownCast(mapper))
  {
    return true;
  }
  // Samples are the lit surfaces drawn as triangles (see vtkPenumbraMapperDraws.h).
  if (penumbra_draws::HasViewPosition(fragmentShader) && penumbra_draws::DrawsSurface(mapper, prop))
  {
    std::string dec = vtkPenumbraViewSamplesDec;
    if (fragmentShader.find("uniform int PrimitiveIDOffset") == std::string::npos)
    {
      dec += "uniform int PrimitiveIDOffset;\n";
    }
    AddSurfaceDeclarations(fragmentShader, "//PENUMBRA::Samples::Dec", dec);
    // A template without VTK's uniform-flow tag computes the surface where it writes it.
    const bool uniformFlow = fragmentShader.find(SurfaceTag) != std::string::npos;
    vtkShaderProgram::Substitute(fragmentShader, SurfaceTag, GetSurfaceCall(), false);
    vtkShaderProgram::Substitute(fragmentShader, "//PENUMBRA::Samples::Impl",
      uniformFlow ? std::string(vtkPenumbraViewSamplesImpl)
                  : GetSurfaceCall() + std::string(vtkPenumbraViewSamplesImpl),
      false);
  }
  else
  {
    // Unlit props, lines and points: occlude, but give no sample.
    vtkShaderProgram::Substitute(fragmentShader, "//PENUMBRA::Samples::Dec", "", false);
    vtkShaderProgram::Substitute(fragmentShader, SurfaceTag, "", false);
    vtkShaderProgram::Substitute(fragmentShader, "//PENUMBRA::Samples::Impl",
      "  gl_FragData[0] = vec4(0.0);\n  gl_FragData[1] = vec4(0.0, 0.0, 0.0, -1.0);\n"
      "  gl_FragData[2] = vec4(0.0, 0.0, -1.0, 0.0);\n",
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
  // The samples replace the mapper's colour output, so the compiler drops VTK's colour code
  // and with it `ambientIntensityBF`, whose use is how VTK decides to set the back-face
  // uniforms; but the back-face opacity still decides VTK's discard of alpha-0 fragments
  // (unset, it is 0 and every back face is discarded).
  auto* actor = vtkActor::SafeDownCast(prop);
  if (actor && actor->GetBackfaceProperty() && program->IsUniformUsed("opacityUniformBF") &&
    !program->IsUniformUsed("ambientIntensityBF"))
  {
    program->SetUniformf(
      "opacityUniformBF", static_cast<float>(actor->GetBackfaceProperty()->GetOpacity()));
  }
  if (program->IsUniformUsed("penumbraVCToRebased"))
  {
    this->SetSurfaceUniforms(program);
    // Props that do not receive shadows give no sample: they are lit unshadowed and get no
    // shadow work (they still occlude the samples behind them).
    program->SetUniformf("penumbraPropIndex",
      this->GivesSamples(prop) ? static_cast<float>(impl.FindPropIndex(prop)) : -1.0f);
  }
  return true;
}

void vtkPenumbraViewSamplesPass::IndexProps()
{
  Internals& impl = *this->Impl;
  impl.PropIndex.clear();
  impl.KeysIndex.clear();
  for (int i = 0; impl.Geometry && i < impl.Geometry->GetNumberOfProps(); ++i)
  {
    vtkProp* p = impl.Geometry->GetProp(i);
    impl.PropIndex[p] = i;
    if (p->GetPropertyKeys())
    {
      impl.KeysIndex[p->GetPropertyKeys()] = i;
    }
  }
}

bool vtkPenumbraViewSamplesPass::GivesSamples(vtkProp* prop)
{
  return this->Impl->FindPropIndex(prop) >= 0 && vtkPenumbraShadowKeys::ReceivesShadows(prop);
}

//------------------------------------------------------------------------------
// The camera's part of the samples (what SetSurfaceUniforms() sends): also needed by the
// receivers' shader lookups on a frame whose samples are not rendered.
void vtkPenumbraViewSamplesPass::UpdateView(vtkRenderer* ren)
{
  Internals& impl = *this->Impl;
  if (!impl.Geometry || !ren || !ren->GetActiveCamera())
  {
    return;
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
  impl.ComputeNDCToRebased(ren, vcToWorld);
}

void vtkPenumbraViewSamplesPass::SetSurfaceUniforms(vtkShaderProgram* program)
{
  Internals& impl = *this->Impl;
  program->SetUniformMatrix("penumbraVCToRebased", impl.VCToRebasedTransposed);
  program->SetUniform3f("penumbraCameraRebased", impl.CameraRebased);
  program->SetUniform3f("penumbraViewDirection", impl.ViewDirection);
  program->SetUniformi("penumbraParallel", impl.Parallel);
  if (program->IsUniformUsed("penumbraSampleCount"))
  {
    // The sample layout of the framebuffer this draw renders into (the window's, or a
    // translucency pass's own).
    GLint samples = 0;
    glGetIntegerv(GL_SAMPLES, &samples);
    samples = std::max(1, std::min(static_cast<int>(samples), 16));
    if (samples != impl.SampleCount)
    {
      impl.SampleCount = samples;
      for (int i = 0; i < samples && samples > 1; ++i)
      {
        GLfloat position[2] = { 0.5f, 0.5f };
        glGetMultisamplefv(GL_SAMPLE_POSITION, static_cast<GLuint>(i), position);
        impl.SampleOffsets[2 * i] = position[0] - 0.5f;
        impl.SampleOffsets[2 * i + 1] = position[1] - 0.5f;
      }
    }
    program->SetUniformi("penumbraSampleCount", impl.SampleCount);
    program->SetUniform2fv(
      "penumbraSampleOffsets", 16, reinterpret_cast<const float(*)[2]>(impl.SampleOffsets));
  }
}

const char* vtkPenumbraViewSamplesPass::GetSurfaceDeclarations()
{
  return vtkPenumbraSurfaceDec;
}

void vtkPenumbraViewSamplesPass::AddSurfaceDeclarations(
  std::string& fragmentShader, const std::string& tag, const std::string& more)
{
  // The coverage mask (gl_SampleMaskIn) comes with GLSL 4.00 or gpu_shader5; #extension lines must
  // precede the code, so they go where VTK puts its version.
  if (fragmentShader.find("GL_ARB_gpu_shader5") == std::string::npos)
  {
    vtkShaderProgram::Substitute(fragmentShader, "//VTK::System::Dec",
      "//VTK::System::Dec\n#extension GL_ARB_gpu_shader5 : enable\n", false);
  }
  vtkShaderProgram::Substitute(fragmentShader, tag, vtkPenumbraSurfaceDec + more, false);
}

const char* vtkPenumbraViewSamplesPass::GetSurfaceCall()
{
  // Where VTK keeps control flow uniform (//VTK::UniformFlow::Impl): the facet normal comes
  // from screen-space derivatives, undefined after a discard (clipping planes, alpha).
  return "  vec3 penumbraP;\n  vec3 penumbraN;\n  penumbraSurface(vertexVC, penumbraP, "
         "penumbraN);\n";
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
  os << indent << "ReadBackMode: " << (this->ReadBackMode == READ_BACK_IDS ? "IDS" : "POSITIONS")
     << "\n";
}
