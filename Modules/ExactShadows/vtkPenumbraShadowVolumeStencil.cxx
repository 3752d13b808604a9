// vtkPenumbraShadowVolumeShadows: the GL passes, the sample depths and the counting of the volumes
// in the stencil (Brabec 2003, ch. 8), one mask channel per light.

#include "vtkPenumbraShadowVolumeInternals.h"

#include "vtkCamera.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMatrix4x4.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowVolumeAdjacencyGS.h"
#include "vtkPenumbraShadowVolumeAdjacencyVS.h"
#include "vtkPenumbraShadowVolumeFS.h"
#include "vtkPenumbraShadowVolumeMaskFS.h"
#include "vtkPenumbraShadowVolumeMaskVS.h"
#include "vtkPenumbraShadowVolumeVS.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace
{
// Fills `buffer` (made here) with the xyz of `count` points, `point(i, xyzw)` each, in slices,
// so that no CPU copy of the whole table is kept.
template <class PointFn>
void UploadXYZ(GLuint& buffer, size_t count, PointFn point)
{
  constexpr size_t Slice = size_t(1) << 16;
  if (!buffer)
  {
    glGenBuffers(1, &buffer);
  }
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(
    GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(3 * count * sizeof(float)), nullptr, GL_STATIC_DRAW);
  std::vector<float> slice;
  for (size_t first = 0; first < count; first += Slice)
  {
    const size_t last = std::min(count, first + Slice);
    slice.resize(3 * (last - first));
    for (size_t i = first; i < last; ++i)
    {
      float xyzw[4];
      point(i, xyzw);
      std::copy(xyzw, xyzw + 3, slice.begin() + static_cast<std::ptrdiff_t>(3 * (i - first)));
    }
    glBufferSubData(GL_ARRAY_BUFFER, static_cast<GLintptr>(3 * first * sizeof(float)),
      static_cast<GLsizeiptr>(slice.size() * sizeof(float)), slice.data());
  }
}

// The other winding for one draw (the dark caps drawn from the light caps' triples): the front
// face swapped, restored after it. vtkOpenGLState does not cache the front face.
class ScopedOtherFrontFace
{
public:
  ScopedOtherFrontFace()
  {
    glGetIntegerv(GL_FRONT_FACE, &this->Saved);
    glFrontFace(this->Saved == GL_CCW ? GL_CW : GL_CCW);
  }
  ~ScopedOtherFrontFace() { glFrontFace(static_cast<GLenum>(this->Saved)); }
  ScopedOtherFrontFace(const ScopedOtherFrontFace&) = delete;
  ScopedOtherFrontFace& operator=(const ScopedOtherFrontFace&) = delete;

private:
  GLint Saved = GL_CCW;
};
}

namespace penumbra_shadow_volume
{
// Pixel of every sample that sees a surface, from `projection` (world -> clip, rebased:
// the geometry's frame) on a width x height view.
void SampleLayout::Place(
  const penumbra_light_views::FrameInputs& in, const double projection[4][4], int width, int height)
{
  const vtkIdType n = in.NumberOfSamples;
  const vtkIdType perLayer = static_cast<vtkIdType>(width) * height;
  this->Width = width;
  this->Height = height;
  this->Layers = 0;
  this->Unplaced = 0;
  this->Pixel.assign(static_cast<size_t>(n), -1);
  this->SampleAt.clear();
  for (vtkIdType s = 0; s < n; ++s)
  {
    if (in.Props[s] < 0)
    {
      continue;
    }
    double clip[4];
    for (int r = 0; r < 4; ++r)
    {
      clip[r] = projection[r][3];
      for (int c = 0; c < 3; ++c)
      {
        clip[r] += projection[r][c] * (static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c]);
      }
    }
    const double fx = 0.5 * (clip[0] / clip[3] + 1.0) * width;
    const double fy = 0.5 * (clip[1] / clip[3] + 1.0) * height;
    const double x = std::floor(fx), y = std::floor(fy);
    if (!(clip[3] > 0.0 && x >= 0.0 && y >= 0.0 && x < width && y < height &&
          std::fabs(fx - x - 0.5) <= CentreTolerance && std::fabs(fy - y - 0.5) <= CentreTolerance))
    {
      ++this->Unplaced;
      continue;
    }
    vtkIdType pixel = static_cast<vtkIdType>(y) * width + static_cast<vtkIdType>(x);
    int layer = 0;
    while (layer < this->Layers && this->SampleAt[static_cast<size_t>(pixel)] >= 0)
    {
      ++layer;
      pixel += perLayer;
    }
    if (layer == MaxLayers)
    {
      ++this->Unplaced;
      continue;
    }
    if (layer == this->Layers)
    {
      ++this->Layers;
      this->SampleAt.resize(static_cast<size_t>(perLayer * this->Layers), -1);
    }
    this->SampleAt[static_cast<size_t>(pixel)] = s;
    this->Pixel[static_cast<size_t>(s)] = pixel;
  }
  this->Layers = std::max(this->Layers, 1);
  this->SampleAt.resize(static_cast<size_t>(perLayer * this->Layers), -1);
}

// Per counted sample: the depth (`rows`, rebased, reversed) of the point where its pixel-
// centre ray (`unproject`: NDC -> world) meets the sample's own triangle, so that the own
// cap is rasterized at (nearly) the same depth.
void SampleLayout::ComputeDepths(const penumbra_light_views::FrameInputs& in,
  const double rows[4][4], const double unproject[4][4], const double origin[3], double scale)
{
  this->DepthStencil.assign(2 * this->SampleAt.size(), 0.0f);
  const vtkIdType perLayer = static_cast<vtkIdType>(this->Width) * this->Height;
  for (size_t pixel = 0; pixel < this->SampleAt.size(); ++pixel)
  {
    const vtkIdType s = this->SampleAt[pixel];
    if (s < 0)
    {
      continue;
    }
    double p[3];
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c];
    }
    const vtkIdType t = in.Triangles[s];
    if (t >= 0 && t < in.NumberOfTriangles)
    {
      double a[9];
      in.Triangle(t, a);
      const Vec3 va = { a[0], a[1], a[2] };
      const Vec3 nrm = glm::cross(Vec3(a[3], a[4], a[5]) - va, Vec3(a[6], a[7], a[8]) - va);
      // Pixel-centre ray in world coordinates, rebased.
      const vtkIdType inLayer = static_cast<vtkIdType>(pixel) % perLayer;
      const double x = static_cast<double>(inLayer % this->Width);
      const double y = static_cast<double>(inLayer / this->Width);
      const double ndc[2] = { (x + 0.5) * 2.0 / this->Width - 1.0,
        (y + 0.5) * 2.0 / this->Height - 1.0 };
      double ends[2][3];
      for (int e = 0; e < 2; ++e)
      {
        const double q[4] = { ndc[0], ndc[1], e == 0 ? -1.0 : 1.0, 1.0 };
        double h[4];
        for (int r = 0; r < 4; ++r)
        {
          h[r] = unproject[r][0] * q[0] + unproject[r][1] * q[1] + unproject[r][2] * q[2] +
            unproject[r][3] * q[3];
        }
        for (int c = 0; c < 3; ++c)
        {
          ends[e][c] = h[c] / h[3] - origin[c];
        }
      }
      const Vec3 from = { ends[0][0], ends[0][1], ends[0][2] };
      const Vec3 dir = Vec3(ends[1][0], ends[1][1], ends[1][2]) - from;
      const double denom = glm::dot(nrm, dir);
      if (std::fabs(denom) > 1e-12 * std::sqrt(glm::dot(nrm, nrm) * glm::dot(dir, dir)))
      {
        const double u = glm::dot(nrm, va - from) / denom;
        const Vec3 q = { from[0] + u * dir[0], from[1] + u * dir[1], from[2] + u * dir[2] };
        // Only when the intersection stays near the sample (it is the same surface point
        // up to the G-buffer's float rounding).
        const Vec3 d = q - Vec3(p[0], p[1], p[2]);
        if (glm::dot(d, d) <= 1e-6 * scale * scale)
        {
          p[0] = q.x;
          p[1] = q.y;
          p[2] = q.z;
        }
      }
    }
    double clip[4];
    for (int r = 0; r < 4; ++r)
    {
      clip[r] = rows[r][0] * p[0] + rows[r][1] * p[1] + rows[r][2] * p[2] + rows[r][3];
    }
    this->DepthStencil[2 * pixel] =
      static_cast<float>(std::min(1.0, std::max(0.0, clip[2] / clip[3])));
  }
}
}

using namespace penumbra_shadow_volume;

void vtkPenumbraShadowVolumeShadows::Internals::Release(vtkWindow* window)
{
  if (this->Window && (!window || window == this->Window))
  {
    this->Window->MakeCurrent();
    this->ClearVolumes();
    this->CollectGarbage();
    if (this->Framebuffer)
    {
      glDeleteFramebuffers(1, &this->Framebuffer);
      glDeleteTextures(1, &this->DepthStencil);
      glDeleteTextures(1, &this->MaskTexture);
      glDeleteVertexArrays(1, &this->VertexArray);
      glDeleteQueries(1, &this->Query);
      glDeleteVertexArrays(1, &this->PointArray);
      glDeleteBuffers(1, &this->PointBuffer);
    }
  }
  for (auto& set : this->Volumes)
  {
    // Their context is gone.
    set->FarBuffer = set->CapBuffer = set->StreamBuffer = set->AdjacencyBuffer = 0;
  }
  this->Garbage.clear();
  this->Framebuffer = this->DepthStencil = this->MaskTexture = this->VertexArray = 0;
  this->Query = this->PointArray = this->PointBuffer = 0;
  this->PointsUploaded = false;
  this->Width = this->Height = 0;
  this->DepthUploaded = false;
  this->Window = nullptr;
}

void vtkPenumbraShadowVolumeShadows::Internals::CollectGarbage()
{
  if (!this->Garbage.empty())
  {
    glDeleteBuffers(static_cast<GLsizei>(this->Garbage.size()), this->Garbage.data());
    this->Garbage.clear();
  }
}

// The counting framebuffer: DEPTH32F_STENCIL8 and the RGBA8 mask. False when incomplete.
// Bound through vtkOpenGLState: the caller's PopFramebufferBindings() restores from its
// cache, so a binding made behind its back would leave the wrong framebuffer bound.
bool vtkPenumbraShadowVolumeShadows::Internals::Allocate(int w, int h, vtkOpenGLState* ostate)
{
  if (this->Framebuffer && this->Width == w && this->Height == h)
  {
    return true;
  }
  if (!this->Framebuffer)
  {
    glGenFramebuffers(1, &this->Framebuffer);
    glGenTextures(1, &this->DepthStencil);
    glGenTextures(1, &this->MaskTexture);
    glGenVertexArrays(1, &this->VertexArray);
    glGenQueries(1, &this->Query);
    glGenVertexArrays(1, &this->PointArray);
    glGenBuffers(1, &this->PointBuffer);
  }
  glBindTexture(GL_TEXTURE_2D, this->DepthStencil);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH32F_STENCIL8, w, h, 0, GL_DEPTH_STENCIL,
    GL_FLOAT_32_UNSIGNED_INT_24_8_REV, nullptr);
  glBindTexture(GL_TEXTURE_2D, this->MaskTexture);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  this->DepthUploaded = false;
  glBindTexture(GL_TEXTURE_2D, 0);
  ostate->vtkglBindFramebuffer(GL_FRAMEBUFFER, this->Framebuffer);
  glFramebufferTexture2D(
    GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, this->DepthStencil, 0);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, this->MaskTexture, 0);
  ostate->vtkglDrawBuffer(GL_COLOR_ATTACHMENT0);
  ostate->vtkglReadBuffer(GL_COLOR_ATTACHMENT0);
  const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  this->Width = w;
  this->Height = h;
  return complete;
}

// ---- Sample depths. The camera matrix and the sample depths depend on the samples and the
// camera only: one computation and one upload per frame serve every light (Brabec 2003,
// ch. 8: the scene depth once, then per light a cleared stencil and its volumes).
void vtkPenumbraShadowVolumeShadows::Internals::ComputeSampleDepths(
  vtkPenumbraShadowVolumeShadows& self, Group& g)
{
  g.StencilStart = Clock::now();
  vtkCamera* camera = g.Camera;
  vtkPenumbraViewSamples* samples = g.Samples;
  vtkPenumbraSceneGeometry* geometry = g.Geometry;
  const int width = g.Width;
  g.Parallel = camera->GetParallelProjection() != 0;
  // The view's aspect is the renderer's: the samples may hold several surfaces per pixel
  // (see SampleLayout), so their own height says nothing about it. Samples the pass did not
  // make (a renderer without a window) are taken as one image of the view.
  const double aspect = g.Renderer->GetRenderWindow() && g.Renderer->GetTiledAspectRatio() > 0.0
    ? g.Renderer->GetTiledAspectRatio()
    : static_cast<double>(width) / std::max(g.Height, 1);
  const int viewHeight = std::max(1, static_cast<int>(std::lround(width / aspect)));
  auto address = [](const void* p)
  { return static_cast<double>(reinterpret_cast<std::uintptr_t>(p)); };
  const std::vector<double> depthKey = { address(samples), static_cast<double>(samples->GetMTime()),
    static_cast<double>(samples->GetPositions()->GetMTime()),
    static_cast<double>(samples->GetPropIndices()->GetMTime()),
    static_cast<double>(samples->GetTriangleIds()->GetMTime()),
    static_cast<double>(camera->GetMTime()), address(geometry),
    static_cast<double>(geometry->GetGeometryTime()), this->Origin[0], this->Origin[1],
    this->Origin[2], static_cast<double>(width), static_cast<double>(viewHeight),
    static_cast<double>(g.N) };
  if (depthKey != this->DepthKey)
  {
    this->DepthKey = depthKey;
    this->DepthUploaded = false;
    ++self.NumberOfDepthComputations;
    double unproject[4][4];
    double projection[4][4]; // world -> clip as VTK draws it, rebased
    this->CameraRows(camera, aspect, g.Parallel, *g.In, unproject, projection);
    this->Layout.Place(*g.In, projection, width, viewHeight);
    this->Layout.ComputeDepths(*g.In, this->Rows, unproject, this->Origin, g.Scale);
  }

  self.SampleDepthTimeMs += ElapsedMs(g.StencilStart);
}

// Camera: VTK's world -> clip for this image into `projection` (and Projection) and its
// inverse into `unproject`, rebased; Rows the same with a reversed float depth fitted to the
// samples.
void vtkPenumbraShadowVolumeShadows::Internals::CameraRows(vtkCamera* camera, double aspect,
  bool parallel, const penumbra_light_views::FrameInputs& in, double unproject[4][4],
  double projection[4][4])
{
  double(&rows)[4][4] = this->Rows;
  const double* shift = in.Shift;
  const vtkIdType n = in.NumberOfSamples;
  vtkMatrix4x4* m = camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1);
  vtkNew<vtkMatrix4x4> inverse;
  vtkMatrix4x4::Invert(m, inverse);
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      unproject[r][c] = inverse->GetElement(r, c);
    }
  }
  vtkMatrix4x4* view = camera->GetViewTransformMatrix();
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      rows[r][c] = m->GetElement(r, c);
    }
  }
  // Rebase: x_world = x_rebased + origin.
  for (int r = 0; r < 4; ++r)
  {
    rows[r][3] +=
      rows[r][0] * this->Origin[0] + rows[r][1] * this->Origin[1] + rows[r][2] * this->Origin[2];
  }
  std::copy(&rows[0][0], &rows[0][0] + 16, &projection[0][0]);
  std::copy(&rows[0][0], &rows[0][0] + 16, &this->Projection[0][0]);
  // Eye depth (positive in front) as a row of the rebased frame.
  double eye[4];
  for (int c = 0; c < 4; ++c)
  {
    eye[c] = -view->GetElement(2, c);
  }
  eye[3] += eye[0] * this->Origin[0] + eye[1] * this->Origin[1] + eye[2] * this->Origin[2];
  double nearest = VTK_DOUBLE_MAX, farthest = 0.0;
  for (vtkIdType s = 0; s < n; ++s)
  {
    if (in.Props[s] >= 0)
    {
      double z = eye[3];
      for (int c = 0; c < 3; ++c)
      {
        z += eye[c] * (static_cast<double>(in.Positions[3 * s + c]) + shift[c]);
      }
      nearest = std::min(nearest, z);
      farthest = std::max(farthest, z);
    }
  }
  if (!parallel)
  {
    // d = nearPlane / eye depth (w row unchanged): 1 at half the nearest sample, 0 at
    // infinity; depth clamp keeps what lies closer.
    const double nearPlane = std::max(0.5 * nearest, 1e-9 * (1.0 + std::fabs(farthest)));
    // z_clip = nearPlane * w_vertex: a point at infinity (w = 0) gets depth 0.
    rows[2][0] = rows[2][1] = rows[2][2] = 0.0;
    rows[2][3] = nearPlane;
  }
  else
  {
    const double margin = 0.25 * (farthest - nearest) + 1e-6 * (1.0 + std::fabs(farthest));
    const double zn = nearest - margin, zf = farthest + margin;
    // d = (zf - eye depth) / (zf - zn).
    for (int c = 0; c < 4; ++c)
    {
      rows[2][c] = (c == 3 ? zf : 0.0) - eye[c];
      rows[2][c] /= (zf - zn);
    }
  }
}

// ---- GL: the context, the features the counting needs and its shaders. Null, or why the
// group fails.
const char* vtkPenumbraShadowVolumeShadows::Internals::ReadyGL(Group& g)
{
  vtkOpenGLRenderWindow* win = g.Window;
  win->MakeCurrent();
  if (this->Window && this->Window != win)
  {
    this->Release(nullptr);
  }
  this->Window = win;
  if (!HasDepthClamp())
  {
    return "depth clamping (OpenGL 3.2 or ARB_depth_clamp) is required";
  }
  if (!glClipControl)
  {
    return "glClipControl (OpenGL 4.5 or ARB_clip_control) is required for the "
           "reversed float depth";
  }
  g.Program = ReadyProgram(win, vtkPenumbraShadowVolumeVS, vtkPenumbraShadowVolumeFS, "");
  if (!g.Program)
  {
    return "the shadow volume shaders do not compile or link";
  }
  if (std::any_of(g.Jobs.begin(), g.Jobs.end(),
        [](const Job& j) { return j.Volumes && j.Volumes->AdjacencyCount > 0; }))
  {
    g.GSProgram = ReadyProgram(win, vtkPenumbraShadowVolumeAdjacencyVS, vtkPenumbraShadowVolumeFS,
      vtkPenumbraShadowVolumeAdjacencyGS);
    if (!g.GSProgram)
    {
      return "GPU silhouettes need a geometry shader with triangles_adjacency input, "
             "which does not compile or link here; use CPU silhouettes";
    }
  }
  g.MaskProgram =
    ReadyProgram(win, vtkPenumbraShadowVolumeMaskVS, vtkPenumbraShadowVolumeMaskFS, "");
  if (!g.MaskProgram)
  {
    return "the shadow mask shaders do not compile or link";
  }
  this->CollectGarbage();
  return nullptr;
}

// The program of these shaders, compiled and linked; null if it is not.
vtkShaderProgram* vtkPenumbraShadowVolumeShadows::Internals::ReadyProgram(
  vtkOpenGLRenderWindow* win, const char* vs, const char* fs, const char* gs)
{
  vtkShaderProgram* program = win->GetShaderCache()->ReadyShaderProgram(vs, fs, gs);
  return program && program->GetCompiled() ? program : nullptr;
}

// Depth clamping (GL 3.2 core, or ARB_depth_clamp) keeps the volumes' far parts.
bool vtkPenumbraShadowVolumeShadows::Internals::HasDepthClamp()
{
  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  bool clamp = major * 10 + minor >= 32;
  GLint extensions = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &extensions);
  for (GLint i = 0; i < extensions && !clamp; ++i)
  {
    const GLubyte* name = glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i));
    clamp = name && std::strcmp(reinterpret_cast<const char*>(name), "GL_ARB_depth_clamp") == 0;
  }
  return clamp;
}

// ---- Brabec 2003, ch. 8: the scene depth once, then per light a cleared stencil, its
// volumes and a copy of "count != 0" into its channel of one RGBA mask; one read-back per
// mask. False when the counting framebuffer is incomplete.
bool vtkPenumbraShadowVolumeShadows::Internals::CountInStencil(
  vtkPenumbraShadowVolumeShadows& self, const Group& g)
{
  vtkOpenGLState* ostate = g.Window->GetState();
  ostate->PushFramebufferBindings();
  bool complete;
  {
    vtkOpenGLState::ScopedglEnableDisable blend(ostate, GL_BLEND);
    vtkOpenGLState::ScopedglEnableDisable depthTest(ostate, GL_DEPTH_TEST);
    vtkOpenGLState::ScopedglEnableDisable scissor(ostate, GL_SCISSOR_TEST);
    vtkOpenGLState::ScopedglEnableDisable cull(ostate, GL_CULL_FACE);
    vtkOpenGLState::ScopedglEnableDisable stencilTest(ostate, GL_STENCIL_TEST);
    vtkOpenGLState::ScopedglViewport viewport(ostate);
    vtkOpenGLState::ScopedglDepthFunc depthFunc(ostate);
    vtkOpenGLState::ScopedglDepthMask depthMask(ostate);
    vtkOpenGLState::ScopedglColorMask colorMask(ostate);
    const SampleLayout& layout = this->Layout;
    const int channels = g.Counted == 1 ? 1 : 4;
    this->MaskPixels.resize(static_cast<size_t>(channels) * layout.SampleAt.size());
    complete = this->Allocate(layout.Width, layout.Height, ostate);
    if (complete)
    {
      this->CountLayers(self, g, ostate);
    }
  }
  ostate->PopFramebufferBindings();
  return complete;
}

// CountInStencil in its complete framebuffer, inside its state savers: every layer.
void vtkPenumbraShadowVolumeShadows::Internals::CountLayers(
  vtkPenumbraShadowVolumeShadows& self, const Group& g, vtkOpenGLState* ostate)
{
  const SampleLayout& layout = this->Layout;
  ostate->vtkglBindFramebuffer(GL_FRAMEBUFFER, this->Framebuffer);
  ostate->vtkglStencilMask(0xff);

  ostate->vtkglDisable(GL_BLEND);
  ostate->vtkglDisable(GL_SCISSOR_TEST);
  ostate->vtkglDisable(GL_CULL_FACE);
  ostate->vtkglEnable(GL_STENCIL_TEST);
  ostate->vtkglViewport(0, 0, layout.Width, layout.Height);
  ostate->vtkglDepthMask(GL_FALSE);
  const GLboolean hadClamp = glIsEnabled(GL_DEPTH_CLAMP);
  glEnable(GL_DEPTH_CLAMP);
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);

  float matrix[16];
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      matrix[4 * c + r] = static_cast<float>(this->Rows[r][c]);
    }
  }
  // One pass per layer of samples (see SampleLayout), each in the same view-sized
  // framebuffer.
  for (int layer = 0; layer < layout.Layers; ++layer)
  {
    this->CountLayer(self, g, ostate, layer, matrix);
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  glBindVertexArray(0);

  glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  if (!hadClamp)
  {
    glDisable(GL_DEPTH_CLAMP);
  }
  ostate->vtkglStencilOpSeparate(GL_FRONT_AND_BACK, GL_KEEP, GL_KEEP, GL_KEEP);
  ostate->vtkglStencilFunc(GL_ALWAYS, 0, 0xff);

  ++self.NumberOfMasks;
}

// The welded points as the GPU draws them (VolumeSet::TablePoint of identity 2i: xyz, w = 1),
// once per connectivity: the caps' near corners and the GPU silhouettes' input.
void vtkPenumbraShadowVolumeShadows::Internals::UploadPoints()
{
  const Connectivity& mesh = this->Mesh;
  UploadXYZ(this->PointBuffer, mesh.Points.size(),
    [&](size_t i, float xyzw[4]) { VolumeSet::NearPoint(mesh.Points[i], xyzw); });
  this->PointsUploaded = true;
}

// ---- One layer of samples: its depth, every counted light into its channel, one read-back
// for the whole group (the red channel alone for a single light).
void vtkPenumbraShadowVolumeShadows::Internals::CountLayer(vtkPenumbraShadowVolumeShadows& self,
  const Group& g, vtkOpenGLState* ostate, int layer, float matrix[16])
{
  const SampleLayout& layout = this->Layout;
  const size_t perLayer = static_cast<size_t>(layout.Width) * static_cast<size_t>(layout.Height);
  const int channels = g.Counted == 1 ? 1 : 4;
  bool stencilClear = false;
  if (!this->DepthUploaded || layout.Layers > 1)
  {
    // This layer's depth and a zero stencil in one upload.
    glBindTexture(GL_TEXTURE_2D, this->DepthStencil);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, layout.Width, layout.Height, GL_DEPTH_STENCIL,
      GL_FLOAT_32_UNSIGNED_INT_24_8_REV,
      layout.DepthStencil.data() + 2 * perLayer * static_cast<size_t>(layer));
    glBindTexture(GL_TEXTURE_2D, 0);
    this->DepthUploaded = layout.Layers == 1; // one layer: kept for the next call
    stencilClear = true;
  }
  // Every channel starts lit.
  ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  const GLfloat lit[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
  glClearBufferfv(GL_COLOR, 0, lit);
  for (const Job& job : g.Jobs)
  {
    if (!job.Volumes)
    {
      continue;
    }
    if (stencilClear)
    {
      stencilClear = false; // the upload left it zero
    }
    else
    {
      const GLint zero = 0;
      glClearBufferiv(GL_STENCIL, 0, &zero);
    }
    this->CountLight(self, g, ostate, job, matrix);
  }
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, layout.Width, layout.Height, channels == 1 ? GL_RED : GL_RGBA,
    GL_UNSIGNED_BYTE,
    this->MaskPixels.data() +
      static_cast<size_t>(channels) * perLayer * static_cast<size_t>(layer));
}

// One light on a cleared stencil: its volumes counted (z-pass or Carmack's reverse), then
// "count != 0" into its channel.
void vtkPenumbraShadowVolumeShadows::Internals::CountLight(vtkPenumbraShadowVolumeShadows& self,
  const Group& g, vtkOpenGLState* ostate, const Job& job, float matrix[16])
{
  VolumeSet& vs = *job.Volumes;
  const VolumeLight& vl = job.VL;
  ostate->vtkglEnable(GL_DEPTH_TEST);
  ostate->vtkglColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  // Reversed depth: nearer is greater.
  ostate->vtkglDepthFunc(GL_GREATER);
  ostate->vtkglStencilMask(0xff);
  ostate->vtkglStencilFunc(GL_ALWAYS, 0, 0xff);
  if (job.ZPass)
  {
    // Count faces in front of the sample: entering +1, leaving -1.
    ostate->vtkglStencilOpSeparate(GL_FRONT, GL_KEEP, GL_KEEP, GL_INCR_WRAP);
    ostate->vtkglStencilOpSeparate(GL_BACK, GL_KEEP, GL_KEEP, GL_DECR_WRAP);
  }
  else
  {
    // Carmack's reverse: count faces behind the sample (depth fails).
    ostate->vtkglStencilOpSeparate(GL_FRONT, GL_KEEP, GL_DECR_WRAP, GL_KEEP);
    ostate->vtkglStencilOpSeparate(GL_BACK, GL_KEEP, GL_INCR_WRAP, GL_KEEP);
  }

  this->BindVolumeBuffers(g, vs);
  glBeginQuery(GL_SAMPLES_PASSED, this->Query);
  this->DrawVolumes(g, vs, vl, matrix, static_cast<float>(1.0 - self.CapOffset));
  glEndQuery(GL_SAMPLES_PASSED);
  GLuint passed = 0;
  glGetQueryObjectuiv(this->Query, GL_QUERY_RESULT, &passed);
  self.NumberOfPassedFragments += static_cast<vtkIdType>(passed);
  if (self.MeasureFill)
  {
    // Every rasterized volume fragment, with the stencil left as counted.
    ostate->vtkglDepthFunc(GL_ALWAYS);
    ostate->vtkglStencilMask(0x00);
    glBeginQuery(GL_SAMPLES_PASSED, this->Query);
    this->DrawVolumes(g, vs, vl, matrix, 1.0f);
    glEndQuery(GL_SAMPLES_PASSED);
    GLuint fill = 0;
    glGetQueryObjectuiv(this->Query, GL_QUERY_RESULT, &fill);
    self.NumberOfFillFragments += static_cast<vtkIdType>(fill);
    ostate->vtkglStencilMask(0xff);
  }

  // Step 3 of ch. 8: 0 into this light's channel where the count is not zero (the
  // count wraps modulo 256).
  ostate->vtkglDisable(GL_DEPTH_TEST);
  ostate->vtkglStencilOpSeparate(GL_FRONT_AND_BACK, GL_KEEP, GL_KEEP, GL_KEEP);
  ostate->vtkglStencilFunc(GL_NOTEQUAL, 0, 0xff);
  ostate->vtkglColorMask(job.Channel == 0, job.Channel == 1, job.Channel == 2, job.Channel == 3);
  g.Window->GetShaderCache()->ReadyShaderProgram(g.MaskProgram);
  glBindVertexArray(this->VertexArray);
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

// One light's buffers, uploaded once per volume build (the extruded copies and the caps'
// indices made here, in slices, so that no CPU copy of them is kept), bound for drawing.
void vtkPenumbraShadowVolumeShadows::Internals::BindVolumeBuffers(const Group& g, VolumeSet& vs)
{
  const bool gsDraws = g.GSProgram && vs.AdjacencyCount > 0;
  if (!this->PointsUploaded && (vs.CapFaces > 0 || gsDraws))
  {
    this->UploadPoints();
  }
  glBindVertexArray(this->VertexArray);
  if (!vs.FarBuffer && vs.CapFaces > 0)
  {
    this->UploadCaps(vs);
  }
  if (!vs.StreamBuffer)
  {
    // Made and filled at once: LightCaps, then Rest.
    BindBuffer(GL_ARRAY_BUFFER, vs.StreamBuffer,
      static_cast<GLsizeiptr>(4 * static_cast<size_t>(vs.StreamVertices()) * sizeof(float)),
      nullptr);
    const GLsizeiptr capBytes = static_cast<GLsizeiptr>(vs.LightCaps.V.size() * sizeof(float));
    glBufferSubData(GL_ARRAY_BUFFER, 0, capBytes, vs.LightCaps.V.data());
    glBufferSubData(GL_ARRAY_BUFFER, capBytes,
      static_cast<GLsizeiptr>(vs.Rest.V.size() * sizeof(float)), vs.Rest.V.data());
  }
  glBindBuffer(GL_ARRAY_BUFFER, vs.StreamBuffer);
  if (gsDraws)
  {
    glBindVertexArray(this->PointArray);
    const GLint pointLoc = glGetAttribLocation(g.GSProgram->GetHandle(), "vertexRebased");
    if (pointLoc >= 0)
    {
      glBindBuffer(GL_ARRAY_BUFFER, this->PointBuffer);
      glEnableVertexAttribArray(static_cast<GLuint>(pointLoc));
      glVertexAttribPointer(static_cast<GLuint>(pointLoc), 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
    BindBuffer(GL_ELEMENT_ARRAY_BUFFER, vs.AdjacencyBuffer,
      static_cast<GLsizeiptr>(vs.AdjacencyIndices.size() * sizeof(GLuint)),
      vs.AdjacencyIndices.data());
  }
}

// The set's extruded copies (VolumeSet::TablePoint of identity 2i + 1 at i, xyz: their w is
// FarW, or 1, for every point) and the caps' indices: one triple per face with a set, in face
// order, as the light cap winds (VolumeBuilder::CapAndDark: t0, t1, t2; the dark cap t0, t2,
// t1 is the same triple drawn with the front face swapped).
void vtkPenumbraShadowVolumeShadows::Internals::UploadCaps(VolumeSet& vs)
{
  const Connectivity& mesh = this->Mesh;
  UploadXYZ(vs.FarBuffer, mesh.Points.size(),
    [&](size_t i, float xyzw[4])
    { vs.TablePoint(mesh, VolumeStream::FarId(static_cast<int>(i)), xyzw); });
  constexpr size_t Slice = size_t(1) << 16;
  glGenBuffers(1, &vs.CapBuffer);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, vs.CapBuffer);
  const size_t capIndices = 3 * static_cast<size_t>(vs.CapFaces);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(capIndices * sizeof(GLuint)),
    nullptr, GL_STATIC_DRAW);
  std::vector<GLuint> indices;
  size_t written = 0;
  auto flush = [&]()
  {
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLintptr>(written * sizeof(GLuint)),
      static_cast<GLsizeiptr>(indices.size() * sizeof(GLuint)), indices.data());
    written += indices.size();
    indices.clear();
  };
  for (size_t ci = 0; ci < mesh.Components.size(); ++ci)
  {
    const std::vector<signed char>& set = vs.Sets[ci];
    for (size_t f = 0; f < set.size(); ++f)
    {
      if (set[f] == 0)
      {
        continue;
      }
      const std::array<int, 3> t = VolumeSet::CapCorners(mesh.Components[ci], f, set[f]);
      indices.insert(indices.end(),
        { static_cast<GLuint>(t[0]), static_cast<GLuint>(t[1]), static_cast<GLuint>(t[2]) });
      if (indices.size() >= 3 * Slice)
      {
        flush();
      }
    }
  }
  flush();
}

// Binds `buffer` to `target`, first creating it with `bytes` of `data` if it does not exist.
void vtkPenumbraShadowVolumeShadows::Internals::BindBuffer(
  GLenum target, GLuint& buffer, GLsizeiptr bytes, const void* data)
{
  if (!buffer)
  {
    glGenBuffers(1, &buffer);
    glBindBuffer(target, buffer);
    glBufferData(target, bytes, data, GL_STATIC_DRAW);
  }
  glBindBuffer(target, buffer);
}

// Every volume of one light once; light caps pushed back by `capScale` (1: not at all).
void vtkPenumbraShadowVolumeShadows::Internals::DrawVolumes(
  const Group& g, const VolumeSet& vs, const VolumeLight& vl, float matrix[16], float capScale)
{
  g.Window->GetShaderCache()->ReadyShaderProgram(g.Program);
  g.Program->SetUniformMatrix4x4("worldToClip", matrix);
  glBindVertexArray(this->VertexArray);
  const GLint loc = glGetAttribLocation(g.Program->GetHandle(), "vertexRebased");
  // The components' caps from the point table (light caps, then dark caps), the explicit
  // volumes from their stream (light caps, then the rest).
  // `components` values a vertex: 4 (xyzw streams) or 3 (point tables, w = 1).
  auto table = [&](GLuint buffer, GLint components)
  {
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    if (loc >= 0)
    {
      glEnableVertexAttribArray(static_cast<GLuint>(loc));
      glVertexAttribPointer(static_cast<GLuint>(loc), components, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
  };
  const GLsizei capIndices = static_cast<GLsizei>(3 * vs.CapFaces);
  const GLsizei lightCaps = static_cast<GLsizei>(vs.LightCaps.Size());
  const GLsizei stream = vs.StreamVertices();
  g.Program->SetUniformf("pointW", 1.0f);
  g.Program->SetUniformf("capScale", capScale);
  if (capIndices > 0)
  {
    table(this->PointBuffer, 3);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, vs.CapBuffer);
    glDrawElements(GL_TRIANGLES, capIndices, GL_UNSIGNED_INT, nullptr);
  }
  if (lightCaps > 0)
  {
    table(vs.StreamBuffer, 4);
    glDrawArrays(GL_TRIANGLES, 0, lightCaps);
  }
  g.Program->SetUniformf("capScale", 1.0f);
  if (capIndices > 0)
  {
    // The dark caps: the light caps' triples into the extruded copies, wound the other way.
    g.Program->SetUniformf("pointW", vs.FarPointW());
    table(vs.FarBuffer, 3);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, vs.CapBuffer);
    {
      const ScopedOtherFrontFace otherWinding;
      glDrawElements(GL_TRIANGLES, capIndices, GL_UNSIGNED_INT, nullptr);
    }
    g.Program->SetUniformf("pointW", 1.0f);
  }
  if (stream > lightCaps)
  {
    table(vs.StreamBuffer, 4);
    glDrawArrays(GL_TRIANGLES, lightCaps, stream - lightCaps);
  }
  if (g.GSProgram && vs.AdjacencyCount > 0)
  {
    const float lightUniform[4] = { static_cast<float>(
                                      vl.Directional ? vl.Direction[0] : vl.Position[0]),
      static_cast<float>(vl.Directional ? vl.Direction[1] : vl.Position[1]),
      static_cast<float>(vl.Directional ? vl.Direction[2] : vl.Position[2]),
      vl.Directional ? 0.0f : 1.0f };
    g.Window->GetShaderCache()->ReadyShaderProgram(g.GSProgram);
    g.GSProgram->SetUniformMatrix4x4("worldToClip", matrix);
    g.GSProgram->SetUniformf("capScale", capScale);
    g.GSProgram->SetUniform4f("light", lightUniform);
    g.GSProgram->SetUniformf("extrusion", static_cast<float>(vl.Extrusion));
    g.GSProgram->SetUniformf("farW", static_cast<float>(vs.FarW));
    glBindVertexArray(this->PointArray);
    glDrawElements(GL_TRIANGLES_ADJACENCY, vs.AdjacencyCount, GL_UNSIGNED_INT, nullptr);
  }
}

// ---- Every light: the mask read back into its visibility, then the samples the stencil
// could not count and the edge resolve. The lights done.
int vtkPenumbraShadowVolumeShadows::Internals::FinishLights(
  vtkPenumbraShadowVolumeShadows& self, const Group& g)
{
  int done = 0;
  for (const Job& job : g.Jobs)
  {
    ++done;
    if (!job.Volumes)
    {
      continue; // decided without counting
    }
    this->ApplyMask(g, job);
    if (!this->TraceUncertain(self, g, job))
    {
      --done;
      continue;
    }
    job.Visibility->Modified();
  }
  return done;
}

// Mask read-back: one light's channel into the visibility of its counted samples.
void vtkPenumbraShadowVolumeShadows::Internals::ApplyMask(const Group& g, const Job& job)
{
  float* vis = job.Vis;
  const std::vector<unsigned char>& state = job.State;
  const int channels = g.Counted == 1 ? 1 : 4;
  const unsigned char* maskChannel = this->MaskPixels.data() + job.Channel;
  const SampleLayout& layout = this->Layout;
  for (vtkIdType s = 0; s < g.N; ++s)
  {
    const vtkIdType pixel = layout.Pixel[static_cast<size_t>(s)];
    if (state[static_cast<size_t>(s)] == Pending && pixel >= 0)
    {
      vis[s] =
        maskChannel[static_cast<size_t>(channels) * static_cast<size_t>(pixel)] == 0 ? 0.0f : 1.0f;
    }
  }
}
