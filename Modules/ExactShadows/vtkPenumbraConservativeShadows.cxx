#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraStatistics.h"

#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkPenumbraCasterBuffers.h"
#include "vtkPenumbraConservativeMapCPU.h"
#include "vtkPenumbraConservativeMapFS.h"
#include "vtkPenumbraConservativeMapGS.h"
#include "vtkPenumbraConservativeMapVS.h"
#include "vtkPenumbraGLPassState.h"
#include "vtkPenumbraLightViews.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraConservativeShadows);

using penumbra_light_views::LightSetup;
using penumbra_light_views::View;

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;

// Per-sample classification states.
enum : unsigned char
{
  Decided = 0,
  Pending = 1,  // needs a map lookup
  Uncertain = 2 // will be traced
};

constexpr std::uint32_t FullBit = 0x80000000u;
// Kept map layers of all lights (see GetNumberOfMapBuilds): a 1024² two-layer map is 16 MB,
// a point light's six faces 96 MB.
constexpr size_t MaxCachedMapBytes = static_cast<size_t>(512) << 20;
constexpr std::uint32_t IdMask = 0x7fffffffu;

using penumbra_rules::Hit;

// The frame's inputs and settings that every view's map build and classification read.
struct FrameContext
{
  const penumbra_light_views::FrameInputs* In = nullptr;
  vtkPenumbraSceneGeometry* Geometry = nullptr;
  int Size = 0;
  int Layers = 0;
  bool Gpu = false;
  double Diagonal = 0.0;
  double Epsilon = 0.0;
  double TieFactor = 0.0;
  float* Vis = nullptr;
  unsigned char* State = nullptr;
  const std::vector<signed char>* SampleView = nullptr;
  const std::vector<vtkIdType>* Pending = nullptr; // the samples pass A left pending, ascending
};

// A sample of a view projected into its map (rule 2 of ClassifyView), waiting for its
// decision: the sample, its point (rebased, double), depth and texel in the view.
struct Projected
{
  vtkIdType S;
  double P[3];
  double Depth;
  size_t Texel;
};
}

struct vtkPenumbraConservativeShadows::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  // The caster triangles on the GPU (shared upload code, rebuilt only when the geometry changes).
  penumbra_casters::CasterBuffers Casters;
  std::vector<GLuint> ViewIndices;
  std::vector<std::uint32_t> ViewCasters; // per primitive of a perspective view's draw: its caster
  std::vector<vtkIdType> PendingList;     // the samples pass A left pending (reused per call)
  std::vector<vtkIdType> UncertainList;   // the call's uncertain samples, ascending

  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  static constexpr int MaxLayers = 4;
  vtkSmartPointer<vtkTextureObject> IdTextures[MaxLayers];
  vtkSmartPointer<vtkTextureObject> Depth;
  int MapSize = 0;

  // CPU builder: beyond this many triangles in a view's apex region its samples are traced.
  static constexpr size_t MaxNearTriangles = 64;

  // One view's map layers, read back (or built) on the CPU, kept with everything they were
  // built from: the view (it covers the pending samples, so it follows the camera), the
  // geometry, the settings. Unchanged, they are reused instead of rebuilt.
  struct ViewMaps
  {
    std::vector<double> Key;
    std::vector<float> Depth[MaxLayers];
    std::vector<std::uint32_t> Ids[MaxLayers];
    std::vector<vtkIdType> Near; // CPU builder: triangles in the view's apex region
    size_t Bytes() const
    {
      size_t bytes = 0;
      for (int k = 0; k < MaxLayers; ++k)
      {
        bytes += this->Depth[k].capacity() * sizeof(float) +
          this->Ids[k].capacity() * sizeof(std::uint32_t);
      }
      return bytes;
    }
  };
  struct LightMaps
  {
    vtkWeakPointer<vtkLight> Light;
    std::vector<ViewMaps> Views;
    std::uint64_t LastUse = 0;
    // The box the views are fitted to, grown by a tenth so that a camera that moves a little
    // keeps the views and so the maps. It costs coarser texels on what is seen: on the bench's
    // city the traced share rose from 5.8 % to 7.6 % (a fifth: 9.2 %).
    penumbra_light_views::KeptBox Fit{ 0.1 };
  };
  std::vector<LightMaps> Cache;
  std::uint64_t Uses = 0;

  LightMaps& Entry(vtkLight* light)
  {
    LightMaps& entry = penumbra_light_views::LightCacheEntry(this->Cache, light);
    entry.LastUse = ++this->Uses;
    return entry;
  }

  // Least recently used lights' maps are dropped while the cache holds more than `budget`
  // bytes; the current light's are always kept.
  void Trim(const LightMaps& current, size_t budget)
  {
    for (;;)
    {
      size_t total = 0;
      LightMaps* oldest = nullptr;
      for (auto& e : this->Cache)
      {
        for (const auto& v : e.Views)
        {
          total += v.Bytes();
        }
        if (&e != &current && !e.Views.empty() && (!oldest || e.LastUse < oldest->LastUse))
        {
          oldest = &e;
        }
      }
      if (total <= budget || !oldest)
      {
        return;
      }
      oldest->Views.clear();
      oldest->Views.shrink_to_fit();
    }
  }

  vtkNew<vtkUnsignedCharArray> Mask;

  void Release(vtkWindow* window)
  {
    if (this->Window && (!window || window == this->Window))
    {
      this->Window->MakeCurrent();
      this->Casters.Release();
      for (auto& tex : this->IdTextures)
      {
        if (tex)
        {
          tex->ReleaseGraphicsResources(this->Window);
        }
      }
      if (this->Depth)
      {
        this->Depth->ReleaseGraphicsResources(this->Window);
      }
      if (this->FBO)
      {
        this->FBO->ReleaseGraphicsResources(this->Window);
      }
    }
    this->Casters.Forget();
    this->FBO = nullptr;
    for (auto& tex : this->IdTextures)
    {
      tex = nullptr;
    }
    this->Depth = nullptr;
    this->MapSize = 0;
    this->Window = nullptr;
  }

  void AllocateMaps(vtkOpenGLRenderWindow* win, int size)
  {
    if (this->FBO && this->MapSize == size)
    {
      return;
    }
    this->FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->FBO->SetContext(win);
    for (auto& tex : this->IdTextures)
    {
      tex = vtkSmartPointer<vtkTextureObject>::New();
      tex->SetContext(win);
      tex->SetRequireTextureInteger(true);
      tex->SetInternalFormat(GL_R32UI);
      tex->SetFormat(GL_RED_INTEGER);
      tex->SetDataType(GL_UNSIGNED_INT);
      tex->SetMinificationFilter(vtkTextureObject::Nearest);
      tex->SetMagnificationFilter(vtkTextureObject::Nearest);
      tex->SetWrapS(vtkTextureObject::ClampToEdge);
      tex->SetWrapT(vtkTextureObject::ClampToEdge);
      tex->Allocate2D(size, size, 1, VTK_UNSIGNED_INT);
    }
    this->Depth = vtkSmartPointer<vtkTextureObject>::New();
    this->Depth->SetContext(win);
    this->Depth->AllocateDepth(size, size, vtkTextureObject::Float32);
    this->MapSize = size;
  }

  // Makes `win` current (releasing another window's resources) and uploads the casters when
  // the geometry changed; true when it uploaded.
  bool UploadCasters(vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry, bool gpu)
  {
    win->MakeCurrent();
    if (this->Window && this->Window != win)
    {
      this->Release(nullptr);
    }
    this->Window = win;
    return this->Casters.Update(geometry, gpu);
  }

  // The cache key of a view's maps: everything they are built from.
  static std::vector<double> MapKey(const FrameContext& f, const View& view)
  {
    std::vector<double> key = { view.Perspective ? 1.0 : 0.0, view.Far, view.NearW, view.TanHalf,
      static_cast<double>(f.Size), static_cast<double>(f.Layers), f.Gpu ? 1.0 : 0.0,
      static_cast<double>(f.Geometry->GetCastersTime()) };
    key.insert(key.end(), &view.Row[0][0], &view.Row[0][0] + 16);
    return key;
  }

  // Builds a view's map layers (CPU or GPU) unless the cached ones have the same key.
  void UpdateMaps(vtkPenumbraConservativeShadows& self, const FrameContext& f, const View& view,
    LightMaps& cached, ViewMaps& maps)
  {
    std::vector<double> key = MapKey(f, view);
    if (maps.Key == key)
    {
      return;
    }
    maps.Key.clear(); // invalid until built
    ++self.NumberOfMapBuilds;
    for (int k = 0; k < MaxLayers; ++k)
    {
      const size_t texels = k < f.Layers ? static_cast<size_t>(f.Size) * f.Size : 0;
      maps.Depth[k].resize(texels);
      maps.Ids[k].resize(texels);
      maps.Depth[k].shrink_to_fit();
      maps.Ids[k].shrink_to_fit();
    }
    maps.Near.clear();
    if (!f.Gpu)
    {
      const penumbra_conservative::CpuMapStats stats =
        penumbra_conservative::BuildConservativeMap(view, f.Size, f.Layers, *f.In->SceneTriangles,
          this->Casters.TriangleIds, maps.Depth, maps.Ids, maps.Near);
      self.NumberOfTexelWrites += stats.TexelWrites;
    }
    else
    {
      this->RenderMaps(f.In->Window, view, f.Size, f.Layers, maps);
    }
    maps.Key = std::move(key);
    this->Trim(cached, MaxCachedMapBytes);
  }

  // Perspective views: fills ViewIndices with the triangles that may reach the frustum.
  void CullToFrustum(const View& view, int size)
  {
    // A cube face sees about a sixth of the scene, and llvmpipe pays per primitive in the
    // geometry stage. Only triangles wholly outside one of the shader's side planes (by more
    // than its rounding) are dropped, so nothing the shader would keep is lost. Indices only;
    // the vertices stay uploaded.
    const double slack = 1.0 + 8.0 / size; // the shader's frustumSlack
    this->ViewIndices.clear();
    this->ViewCasters.clear();
    for (size_t tri = 0; tri < this->Casters.TriangleIds.size(); ++tri)
    {
      int outside[4] = { 0, 0, 0, 0 };
      float xyz[9];
      this->Casters.Float(tri, xyz);
      for (int k = 0; k < 3; ++k)
      {
        const float* fv = xyz + 3 * k;
        const double pv[3] = { fv[0], fv[1], fv[2] };
        const double x = view.Dot(0, pv);
        const double y = view.Dot(1, pv);
        const double w = slack * view.Dot(3, pv);
        // Outside by more than the float rounding of the shader's plane test.
        const double margin = 1e-5 * (std::fabs(x) + std::fabs(y) + std::fabs(w));
        outside[0] += x - w > margin;
        outside[1] += -x - w > margin;
        outside[2] += y - w > margin;
        outside[3] += -y - w > margin;
      }
      if (outside[0] < 3 && outside[1] < 3 && outside[2] < 3 && outside[3] < 3)
      {
        for (int k = 0; k < 3; ++k)
        {
          this->ViewIndices.push_back(this->Casters.Element(tri, k));
        }
        this->ViewCasters.push_back(static_cast<std::uint32_t>(tri));
      }
    }
  }

  // Binds the caster positions and elements (a perspective view's own elements instead).
  void BindCasters(vtkShaderProgram* program, bool perspective)
  {
    this->Casters.Bind(program);
    if (perspective)
    {
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, this->Casters.Indices);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER,
        static_cast<GLsizeiptr>(this->ViewIndices.size() * sizeof(GLuint)),
        this->ViewIndices.empty() ? nullptr : this->ViewIndices.data(), GL_STREAM_DRAW);
    }
  }

  // The map stores the drawn primitive's index + 1 (gl_PrimitiveIDIn); the classifier reads
  // triangle ids + 1. The flag bit (above IdMask) is kept.
  void PrimitivesToTriangles(std::vector<std::uint32_t>& ids, bool perspective) const
  {
    const penumbra_casters::CasterIds& casters = this->Casters.TriangleIds;
    for (std::uint32_t& id : ids)
    {
      const std::uint32_t prim = id & IdMask;
      if (prim != 0)
      {
        const size_t caster = perspective ? this->ViewCasters[prim - 1] : prim - 1;
        id = (id & ~IdMask) | (static_cast<std::uint32_t>(casters[caster]) + 1u);
      }
    }
  }

  // GPU builder: renders the view's id layers by depth peeling and reads them back.
  void RenderMaps(
    vtkOpenGLRenderWindow* win, const View& view, int size, int layers, ViewMaps& maps)
  {
    // Depth is written explicitly and clamped in the shader; clamping is on as a second
    // line of defence (perspective window z loses precision far from the light). Colour (the id
    // layers) is written.
    penumbra_gl::MapRenderState renderState(win->GetState(), this->FBO, size, true);

    vtkShaderProgram* program = win->GetShaderCache()->ReadyShaderProgram(
      vtkPenumbraConservativeMapVS, vtkPenumbraConservativeMapFS, vtkPenumbraConservativeMapGS);
    float matrix[16];
    view.ToFloatMatrix(matrix);
    program->SetUniformMatrix4x4("lightMatrix", matrix);
    const float mapSize[2] = { static_cast<float>(size), static_cast<float>(size) };
    program->SetUniform2f("mapSize", mapSize);
    program->SetUniformi("perspective", view.Perspective ? 1 : 0);
    program->SetUniformf("nearW", static_cast<float>(view.NearW));
    program->SetUniformf("frustumSlack", static_cast<float>(1.0 + 8.0 / size));
    // Half the texel diagonal (enough to cover the texel square; the paper's §4.1 uses the
    // whole diagonal) plus a quarter texel for the float rounding between the GPU
    // projection and the classifier's double one.
    program->SetUniformf("keepRadius", static_cast<float>(0.5 * std::sqrt(2.0) + 0.25));
    program->SetUniformf("invFar", static_cast<float>(1.0 / view.Far));

    // Perspective views draw only the triangles that reach their frustum.
    GLsizei drawCount = this->Casters.VertexCount;
    if (view.Perspective)
    {
      this->CullToFrustum(view, size);
      drawCount = static_cast<GLsizei>(this->ViewIndices.size());
    }
    this->BindCasters(program, view.Perspective);

    const char* previousNames[] = { "layer1", "layer2", "layer3" };
    for (int layer = 0; layer < layers; ++layer)
    {
      this->FBO->AddColorAttachment(0, this->IdTextures[layer]);
      this->FBO->AddDepthAttachment(this->Depth);
      this->FBO->ActivateDrawBuffers(1);
      const GLuint zero[4] = { 0, 0, 0, 0 };
      const GLfloat one = 1.0f;
      glClearBufferuiv(GL_COLOR, 0, zero);
      glClearBufferfv(GL_DEPTH, 0, &one);
      program->SetUniformi("peel", layer);
      // Depth peeling by id: the nearest triangles not yet stored.
      for (int k = 0; k < layer; ++k)
      {
        this->IdTextures[k]->Activate();
        program->SetUniformi(previousNames[k], this->IdTextures[k]->GetTextureUnit());
      }
      glDrawElements(GL_TRIANGLES, drawCount, GL_UNSIGNED_INT, nullptr);
      for (int k = 0; k < layer; ++k)
      {
        this->IdTextures[k]->Deactivate();
      }
      this->FBO->ActivateReadBuffer(0);
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, size, size, GL_RED_INTEGER, GL_UNSIGNED_INT, maps.Ids[layer].data());
      this->PrimitivesToTriangles(maps.Ids[layer], view.Perspective);
      glReadPixels(0, 0, size, size, GL_DEPTH_COMPONENT, GL_FLOAT, maps.Depth[layer].data());
    }
  }

  // Rules 3a-3c (and the apex region's triangles) for one projected sample of the view;
  // leaves it Uncertain when none decides it.
  static void DecideSample(const FrameContext& f, const ViewMaps& maps,
    penumbra_casters::ExactTriangles& exact, const Projected& q,
    penumbra_rules::ExactTriangle& scratch, vtkIdType& localLit, vtkIdType& localShadowed)
  {
    const std::vector<vtkIdType>& nearTriangles = maps.Near;
    const bool nearTestable = nearTriangles.size() <= MaxNearTriangles;
    const penumbra::SceneTriangles& tv = *f.In->SceneTriangles;
    const vtkIdType nTriangles = f.In->NumberOfTriangles;
    float* vis = f.Vis;
    unsigned char* state = f.State;
    // The exact test of rule 3c (and of the apex region's triangles) against one blocker.
    auto TestBlocker = [&exact](const penumbra_light_views::ShadowRay& ray, vtkIdType blocker,
                         const penumbra::SceneTriangles& vertices,
                         penumbra_rules::ExactTriangle& triangle)
    {
      const penumbra_rules::ExactTriangle* made = exact.Get(blocker, vertices, triangle);
      return made ? penumbra_light_views::TestShadowRay(ray, *made) : Hit::Unknown;
    };
    const vtkIdType s = q.S;
    const double* p = q.P;
    const double depth = q.Depth;
    const size_t texel = q.Texel;
    const double margin = 1e-6 * (1.0 + std::fabs(depth));

    // The reference's ray: same direction, same scale-relative epsilons; made when the
    // first exact test needs it (most samples are decided by the first layer's depth).
    // Its Ok flag is known without it: a positional light's ray needs a non-zero
    // direction (MakeShadowRay normalizes it).
    penumbra_light_views::ShadowRay ray;
    bool rayMade = false;
    auto shadowRay = [&]() -> const penumbra_light_views::ShadowRay&
    {
      if (!rayMade)
      {
        ray =
          penumbra_light_views::MakeShadowRay(f.In->Light, p, f.Diagonal, f.Epsilon, f.TieFactor);
        rayMade = true;
      }
      return ray;
    };
    bool rayOk = true;
    if (f.In->Light.Type != LightSetup::Kind::Directional)
    {
      double d2 = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        const double d = f.In->Light.Position[c] - p[c];
        d2 += d * d;
      }
      rayOk = d2 > 0.0;
    }

    bool nearClear = true;
    for (size_t k = 0; k < nearTriangles.size() && rayOk && nearClear; ++k)
    {
      const vtkIdType blocker = nearTriangles[k];
      const bool ownCaster = f.In->OwnCaster(blocker, s);
      const Hit hit = nearTestable && !ownCaster ? TestBlocker(shadowRay(), blocker, tv, scratch)
                                                 : (ownCaster ? Hit::Miss : Hit::Unknown);
      if (hit == Hit::Clear)
      {
        vis[s] = 0.0f;
        state[s] = Decided;
        ++localShadowed;
      }
      nearClear = hit == Hit::Miss;
    }
    for (int k = 0; k < f.Layers && rayOk && nearClear; ++k)
    {
      const std::uint32_t id = maps.Ids[k][texel] & IdMask;
      if (id == 0 || maps.Depth[k][texel] > depth + margin)
      {
        state[s] = Decided;
        ++localLit;
        break;
      }
      const vtkIdType blocker = static_cast<vtkIdType>(id) - 1;
      if (blocker >= nTriangles)
      {
        break;
      }
      if (f.In->OwnCaster(blocker, s))
      {
        continue;
      }
      const Hit hit = TestBlocker(shadowRay(), blocker, tv, scratch);
      if (hit == Hit::Clear)
      {
        vis[s] = 0.0f;
        state[s] = Decided;
        ++localShadowed;
        break;
      }
      if (hit == Hit::Unknown)
      {
        break;
      }
    }
  }

  // Classifies the pending samples of view `viewIndex` with its maps: lit, shadowed or
  // uncertain. `exact` holds the casters' exact triangles (kept between frames).
  static void ClassifyView(const FrameContext& f, const View& view, signed char viewIndex,
    const ViewMaps& maps, penumbra_casters::ExactTriangles& exact, std::atomic<vtkIdType>& viewLit,
    std::atomic<vtkIdType>& viewShadowed)
  {
    // The classification of Hertel et al. 2009, §4.2, with its rules made exact:
    //  1. facing away from the light / outside the spot cone -> shadowed (Classify's pass A);
    //  2. project into the map (double); outside the map or behind the apex -> uncertain;
    //  3. walk the texel's layers k = 1..Layers (layer k: the nearest triangle no earlier
    //     layer holds, with its conservative depth z_k):
    //     a. empty, or z_k > sample depth + margin -> lit: every triangle not yet seen is
    //        deeper than the sample, and the shadow ray projects to this one texel, so
    //        only seen triangles could block it;
    //     b. the sample's own triangle, or a caster piece it owns -> skip it (the reference
    //        never lets it block; replaces the paper's inexact "own id -> lit" rule);
    //     c. exact double-precision ray-triangle test with margins beyond the tie band
    //        and float rounding: clear hit -> shadowed (the conservative depth alone
    //        never shadows, "fully covered" or not: the paper's fully-covered rule is
    //        not exact); clear miss -> skip it (e.g. a coplanar neighbour at a shared
    //        edge); else uncertain;
    //  4. layers exhausted -> uncertain (traced).
    // The CPU builder keeps the triangles that reach a perspective view's apex region out
    // of the map (they would cover all of it); each is tested exactly against the sample's
    // ray first, with rule 3b/3c above. Beyond MaxNearTriangles of them the view's samples
    // are all traced.
    const int size = f.Size;
    const int layers = f.Layers;
    const double* shift = f.In->Shift;
    const float* pos = f.In->Positions;
    const std::vector<signed char>& sampleView = *f.SampleView;
    unsigned char* state = f.State;
    const std::vector<vtkIdType>& pending = *f.Pending;
    // Samples are projected a batch at a time and their texels' first two layers fetched
    // ahead (prefetch) before any is decided: the map lookups miss the cache (a 1024^2 layer
    // is 8 MB), and waiting for each in turn would be most of the classification's time.
    constexpr vtkIdType Batch = 32;
    vtkSMPTools::For(0, static_cast<vtkIdType>(pending.size()),
      [&](vtkIdType begin, vtkIdType end)
      {
        vtkIdType localLit = 0, localShadowed = 0;
        penumbra_rules::ExactTriangle scratch;
        Projected batch[Batch];
        for (vtkIdType first = begin; first < end; first += Batch)
        {
          int count = 0;
          for (vtkIdType i = first; i < std::min(end, first + Batch); ++i)
          {
            const vtkIdType s = pending[static_cast<size_t>(i)];
            if (state[s] != Pending || sampleView[static_cast<size_t>(s)] != viewIndex)
            {
              continue;
            }
            state[s] = Uncertain;
            Projected& q = batch[count];
            for (int c = 0; c < 3; ++c)
            {
              q.P[c] = static_cast<double>(pos[3 * s + c]) + shift[c];
            }
            double ms, mt;
            if (!view.Project(q.P, ms, mt, q.Depth) || !(std::fabs(ms) <= 1.0) ||
              !(std::fabs(mt) <= 1.0))
            {
              continue;
            }
            const int ix =
              std::min(size - 1, std::max(0, static_cast<int>((ms * 0.5 + 0.5) * size)));
            const int iy =
              std::min(size - 1, std::max(0, static_cast<int>((mt * 0.5 + 0.5) * size)));
            q.S = s;
            q.Texel = static_cast<size_t>(iy) * size + ix;
            for (int k = 0; k < std::min(layers, 2); ++k)
            {
              __builtin_prefetch(maps.Ids[k].data() + q.Texel);
              __builtin_prefetch(maps.Depth[k].data() + q.Texel);
            }
            ++count;
          }
          for (int j = 0; j < count; ++j)
          {
            DecideSample(f, maps, exact, batch[j], scratch, localLit, localShadowed);
          }
        }
        viewLit += localLit;
        viewShadowed += localShadowed;
      });
  }

  // The per-view phase of Classify: each view's maps (UpdateMaps), then its samples
  // (ClassifyView); their lit and shadowed samples are added to `lit` and `shadowed`, the
  // times to `mapMs` and `classifyMs`.
  void MapAndClassifyViews(vtkPenumbraConservativeShadows& self, const FrameContext& frame,
    const std::vector<View>& views, LightMaps& cached, std::atomic<vtkIdType>& lit,
    std::atomic<vtkIdType>& shadowed, double& mapMs, double& classifyMs)
  {
    std::atomic<vtkIdType> viewLit(0), viewShadowed(0);

    for (size_t vi = 0; vi < views.size(); ++vi)
    {
      const View& view = views[vi];
      const auto renderStart = Clock::now();
      ViewMaps& maps = cached.Views[vi];
      this->UpdateMaps(self, frame, view, cached, maps);
      mapMs += ElapsedMs(renderStart);

      const auto classifyStart = Clock::now();
      ClassifyView(frame, view, static_cast<signed char>(vi), maps, this->Casters.Exact, viewLit,
        viewShadowed);
      classifyMs += ElapsedMs(classifyStart);
    }
    lit += viewLit.load();
    shadowed += viewShadowed.load();
  }

  // The last phase of Classify: the uncertain samples into UncertainList, with state 1 (the
  // others 0). Only pass A's pending samples can be other than Decided (0) here.
  void ListUncertain(unsigned char* state)
  {
    std::vector<vtkIdType>& uncertainList = this->UncertainList;
    uncertainList.clear();
    for (vtkIdType s : this->PendingList)
    {
      // Samples still pending here had no view (cannot happen with full coverage) and are
      // uncertain too, so nothing is ever left undecided.
      state[s] = (state[s] == Uncertain || state[s] == Pending) ? 1 : 0;
      if (state[s])
      {
        uncertainList.push_back(s);
      }
    }
  }
};

//------------------------------------------------------------------------------
vtkPenumbraConservativeShadows::vtkPenumbraConservativeShadows()
  : Reference(vtkPenumbraReference::New())
  , Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraConservativeShadows::~vtkPenumbraConservativeShadows()
{
  this->Impl->Release(nullptr);
  this->Reference->Delete();
}

//------------------------------------------------------------------------------
void vtkPenumbraConservativeShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
}

//------------------------------------------------------------------------------
int vtkPenumbraConservativeShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  if (!this->Classify(renderer, geometry, samples, light, visibility, impl.Mask))
  {
    return 0;
  }

  // ---- Rays only for the uncertain samples. On the CPU with Embree rather than the paper's
  // GPU kD-tree (Hertel et al. 2009, §5): on llvmpipe the "GPU" runs on the same CPU cores,
  // and a divergent per-fragment traversal in its SIMD fragment pipeline loses to Embree's
  // SIMD-optimised BVH over a compact list of samples.
  const auto traceStart = Clock::now();
  if (this->NumberOfUncertainSamples > 0)
  {
    this->Reference->SetGeometry(geometry);
    if (!this->Reference->ComputeVisibility(samples, light, visibility, impl.Mask))
    {
      PENUMBRA_FAIL("tracing the uncertain samples failed: " << this->Reference->GetErrorMessage());
    }
    this->TraceTimeMs = ElapsedMs(traceStart);
  }
  this->NumberOfRays = this->NumberOfUncertainSamples;
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraConservativeShadows::Classify(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility, vtkUnsignedCharArray* uncertainMask)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  if (!uncertainMask)
  {
    PENUMBRA_FAIL("conservative shadows: an uncertain-sample mask array is required");
  }
  this->NumberOfLitSamples = this->NumberOfShadowedSamples = this->NumberOfUncertainSamples = 0;
  this->NumberOfRays = 0;
  this->MapTimeMs = this->ClassifyTimeMs = this->TraceTimeMs = 0.0;
  this->NumberOfViews = 0;
  this->NumberOfMapBuilds = 0;
  this->NumberOfTexelWrites = 0;
  impl.UncertainList.clear();

  // ---- Input checks: nothing is written before they pass.
  penumbra_light_views::FrameInputs in;
  {
    std::string inputError;
    if (!in.Read(renderer, geometry, samples, light, visibility, inputError))
    {
      PENUMBRA_FAIL("conservative shadows: " << inputError);
    }
  }
  vtkOpenGLRenderWindow* win = in.Window;
  const vtkIdType n = in.NumberOfSamples;
  const vtkIdType nTriangles = in.NumberOfTriangles;
  if (nTriangles >= static_cast<vtkIdType>(IdMask))
  {
    PENUMBRA_FAIL("scene geometry has too many triangles for 31-bit map ids: " << nTriangles);
  }
  const double* shift = in.Shift;
  const LightSetup& setup = in.Light;

  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  float* vis = n ? visibility->GetPointer(0) : nullptr;
  uncertainMask->SetNumberOfComponents(1);
  uncertainMask->SetNumberOfTuples(n);
  unsigned char* state = n ? uncertainMask->GetPointer(0) : nullptr;
  const float* pos = in.Positions;
  const float* nrm = in.Normals;
  const int* props = in.Props;

  // ---- Upload the casters once per geometry change.
  const auto mapStart = Clock::now();
  const bool gpu = this->MapBuilder == MAP_GPU;
  if (impl.UploadCasters(win, geometry, gpu))
  {
    ++this->NumberOfUploads;
  }
  const bool anyCaster = impl.Casters.VertexCount > 0;
  const double uploadMs = ElapsedMs(mapStart);

  // ---- Pass A (Hertel et al. 2009, §4.2 and §5: facing and projection, plus the
  // reference's light rules): decide what needs no map, and find the box the light cameras
  // must cover.
  const double diagonal = penumbra_rules::SceneDiagonal(geometry);
  // The pending samples, listed once by the same pass: the later phases visit only them (at
  // 1280 x 720 a scene covers a fraction of the pixels).
  std::vector<vtkIdType>& pending = impl.PendingList;
  const penumbra_light_views::FacingCounts facing = penumbra_light_views::ClassifyFacing(
    setup, n, pos, nrm, props, shift, anyCaster, vis, state, Pending, Decided, &pending);
  std::atomic<vtkIdType> lit(facing.Lit), shadowed(facing.Shadowed);

  // ---- Light cameras.
  // The views cover the pending samples only (FitViews): casters nearer the light than the
  // samples' depth range keep a conservative (clamped or negative) depth, and a map fitted
  // to the whole scene would waste its texels.
  std::vector<View> views;
  std::vector<signed char> sampleView;
  Internals::LightMaps& cached = impl.Entry(light);
  penumbra_light_views::FitViews(
    setup, n, pos, shift, state, Pending, views, sampleView, &pending, &cached.Fit);
  this->NumberOfViews = static_cast<int>(views.size());

  // ---- Per view: render both CSM layers, read them back, classify its samples.
  double classifyMs = 0.0;
  double mapMs = 0.0;
  if (!views.empty())
  {
    const int size = this->Resolution;
    vtkShaderProgram* program = gpu
      ? win->GetShaderCache()->ReadyShaderProgram(
          vtkPenumbraConservativeMapVS, vtkPenumbraConservativeMapFS, vtkPenumbraConservativeMapGS)
      : nullptr;
    if (gpu && (!program || !program->GetCompiled()))
    {
      PENUMBRA_FAIL("the conservative shadow map shaders do not compile or link on this "
                    "OpenGL implementation (a geometry shader is required)");
    }
    if (gpu)
    {
      impl.AllocateMaps(win, size);
    }
    cached.Views.resize(views.size());

    FrameContext frame;
    frame.In = &in;
    frame.Geometry = geometry;
    frame.Size = size;
    frame.Layers = this->Layers;
    frame.Gpu = gpu;
    frame.Diagonal = diagonal;
    frame.Epsilon = this->Reference->GetRelativeEpsilon();
    frame.TieFactor = this->Reference->GetTieFactor();
    frame.Vis = vis;
    frame.State = state;
    frame.SampleView = &sampleView;
    frame.Pending = &pending;
    impl.MapAndClassifyViews(*this, frame, views, cached, lit, shadowed, mapMs, classifyMs);
  }

  // ---- The uncertain samples, for the caller to resolve.
  impl.ListUncertain(state);
  const vtkIdType uncertain = static_cast<vtkIdType>(impl.UncertainList.size());
  this->MapTimeMs = uploadMs + mapMs;
  this->ClassifyTimeMs = classifyMs;
  this->NumberOfLitSamples = lit.load();
  this->NumberOfShadowedSamples = shadowed.load();
  this->NumberOfUncertainSamples = uncertain;
  uncertainMask->Modified();
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
const std::vector<vtkIdType>& vtkPenumbraConservativeShadows::GetUncertainSamples()
{
  return this->Impl->UncertainList;
}

//------------------------------------------------------------------------------
double vtkPenumbraConservativeShadows::GetUncertainFraction()
{
  const vtkIdType valid =
    this->NumberOfLitSamples + this->NumberOfShadowedSamples + this->NumberOfUncertainSamples;
  return valid > 0 ? static_cast<double>(this->NumberOfUncertainSamples) / valid : 0.0;
}

//------------------------------------------------------------------------------
void vtkPenumbraConservativeShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Layers: " << this->Layers << "\n";
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "MapBuilder: " << (this->MapBuilder == MAP_GPU ? "gpu" : "cpu") << "\n";
  os << indent << "NumberOfTexelWrites: " << this->NumberOfTexelWrites << "\n";
  os << indent << "NumberOfLitSamples: " << this->NumberOfLitSamples << "\n";
  os << indent << "NumberOfShadowedSamples: " << this->NumberOfShadowedSamples << "\n";
  os << indent << "NumberOfUncertainSamples: " << this->NumberOfUncertainSamples << "\n";
  os << indent << "NumberOfRays: " << this->NumberOfRays << "\n";
  os << indent << "MapTimeMs: " << this->MapTimeMs << "\n";
  os << indent << "ClassifyTimeMs: " << this->ClassifyTimeMs << "\n";
  os << indent << "TraceTimeMs: " << this->TraceTimeMs << "\n";
  os << indent << "NumberOfUploads: " << this->NumberOfUploads << "\n";
  os << indent << "NumberOfViews: " << this->NumberOfViews << "\n";
}

//------------------------------------------------------------------------------
void vtkPenumbraConservativeShadows::GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  stats->Set("lit_samples", static_cast<double>(this->NumberOfLitSamples));
  stats->Set("shadowed_samples", static_cast<double>(this->NumberOfShadowedSamples));
  stats->Set("uncertain_samples", static_cast<double>(this->NumberOfUncertainSamples));
  stats->Set("rays", static_cast<double>(this->NumberOfRays));
  stats->Set("views", this->NumberOfViews);
  stats->Set("map_builds", this->NumberOfMapBuilds);
  stats->Set("texel_writes", static_cast<double>(this->NumberOfTexelWrites));
  stats->Set("uploads", this->NumberOfUploads);
  stats->Set("map_ms", this->MapTimeMs);
  stats->Set("classify_ms", this->ClassifyTimeMs);
  stats->Set("trace_ms", this->TraceTimeMs);
}
