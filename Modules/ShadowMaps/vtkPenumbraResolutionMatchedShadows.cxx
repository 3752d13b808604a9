#include "vtkPenumbraResolutionMatchedShadows.h"

#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkPenumbraResolutionMatchedFS.h"
#include "vtkPenumbraShadowMapClassify.h"
#include "vtkPenumbraShadowMapFS.h"
#include "vtkPenumbraShadowMapVS.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraResolutionMatchedShadows);

using penumbra::Clock;
using penumbra::ElapsedMs;
using penumbra_light_views::LightSetup;
using penumbra_light_views::View;

namespace
{
constexpr int PageBits = 5; // 32 x 32 texel pages
// 8 x 8 pages (256^2 texels) a superpage. Lefohn et al. 2007 (§3.3.3) use 1024^2 to save
// geometry passes; on llvmpipe a pass costs little and rasterizing the unrequested texels of
// a sparse 1024^2 bounding rectangle a lot (docs/benchmarks.md, "Resolution-matched").
constexpr int SuperpageBits = 3;
constexpr int SuperpageSide = 1 << (PageBits + SuperpageBits);
// The scratch holds 2^ScratchCellBits x 2^ScratchCellBits superpages side by side: a batch of
// superpages is rendered before any of their pages is copied into the atlas. On llvmpipe a
// copy out of a texture that pending draws write waits for them to be rasterized; one wait a
// superpage cost more than the superpage's raster (docs/benchmarks.md).
constexpr int ScratchCellBits = 2;
constexpr int ScratchSide = SuperpageSide << ScratchCellBits;
constexpr int BaseLevelCap = 8; // the always-resident level: at most 256^2 texels
// No sample requests a level coarser than 1024^2: a sample needing less (far away, or a small
// frame) still gets 1024^2 texels, so that occluders thinner than a coarse texel do not vanish
// from the map (the edge refinement cannot find what the map does not show). Only the pages
// samples request are rendered, not the whole level.
constexpr int MinRequestLevel = 10;
constexpr double MaxSpotCone = 60.0;  // one perspective view (shadowmap's single-view rule)
constexpr double MaxTangent = 1000.0; // the slope bias's cap, as shadowmap's

int FloorLog2(int v)
{
  int k = 0;
  while ((2 << k) <= v)
  {
    ++k;
  }
  return k;
}

// The page pyramid of levels Base..Finest (2^k texels per side): a page's key is its index
// in level order, then row, then column, so that ascending keys go from coarse to fine.
struct Pyramid
{
  int Base = BaseLevelCap;
  int Finest = 15;

  long long Offset(int k) const
  {
    return ((1LL << (2 * (k - PageBits))) - (1LL << (2 * (this->Base - PageBits)))) / 3;
  }
  int Side(int k) const { return 1 << (k - PageBits); } // pages per side
  long long Size() const { return this->Offset(this->Finest + 1); }
  long long Key(int k, int px, int py) const
  {
    return this->Offset(k) + static_cast<long long>(py) * this->Side(k) + px;
  }
  void Decode(long long key, int& k, int& px, int& py) const
  {
    k = this->Base;
    while (k < this->Finest && key >= this->Offset(k + 1))
    {
      ++k;
    }
    const long long local = key - this->Offset(k);
    px = static_cast<int>(local % this->Side(k));
    py = static_cast<int>(local / this->Side(k));
  }
};

// A page to render: its level, position and atlas slot, and the superpage it is binned in.
struct NewPage
{
  int K, X, Y, Slot;
  bool operator<(const NewPage& o) const
  {
    const int a[4] = { this->K, this->Y >> SuperpageBits, this->X >> SuperpageBits, this->Y };
    const int b[4] = { o.K, o.Y >> SuperpageBits, o.X >> SuperpageBits, o.Y };
    return std::lexicographical_compare(a, a + 4, b, b + 4) || (a[3] == b[3] && this->X < o.X);
  }
  bool SameSuperpage(const NewPage& o) const
  {
    return this->K == o.K && (this->X >> SuperpageBits) == (o.X >> SuperpageBits) &&
      (this->Y >> SuperpageBits) == (o.Y >> SuperpageBits);
  }
};

// A superpage rendered into a cell of the scratch: its pages [First, Last) of the sorted new
// pages, their bounding rectangle's first page (X0, Y0) and the cell's origin in texels.
struct SuperpageCell
{
  size_t First, Last;
  int X0, Y0, CellX, CellY;
};

// `view` with its s and t rows cropped so that the texels [x0, x0 + w) x [y0, y0 + h) of level
// k (2^k texels per side) fill a w x h viewport, texel centres on pixel centres; the depth row
// is untouched, so depths agree across superpages and levels.
View CroppedView(const View& view, int k, int x0, int y0, int w, int h)
{
  View cropped = view;
  const double side = std::ldexp(1.0, k);
  const int origin[2] = { x0, y0 };
  const int size[2] = { w, h };
  for (int r = 0; r < 2; ++r)
  {
    const double a = side / size[r];
    const double b = (side - 2.0 * origin[r]) / size[r] - 1.0;
    for (int c = 0; c < 4; ++c)
    {
      cropped.Row[r][c] = a * view.Row[r][c] + b * view.Row[3][c];
    }
  }
  return cropped;
}

double Norm3(const double* v)
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

vtkSmartPointer<vtkTextureObject> NearestTexture(vtkOpenGLRenderWindow* win)
{
  auto tex = vtkSmartPointer<vtkTextureObject>::New();
  tex->SetContext(win);
  tex->SetMinificationFilter(vtkTextureObject::Nearest);
  tex->SetMagnificationFilter(vtkTextureObject::Nearest);
  tex->SetWrapS(vtkTextureObject::ClampToEdge);
  tex->SetWrapT(vtkTextureObject::ClampToEdge);
  return tex;
}

// `targets` made 2 per layer and w x h: per layer the keys + 1 (`keyFormat`: GL_RGBA32F, four
// keys per pixel, or GL_R32F) and the levels (R32F).
void EnsureKeyTargets(vtkOpenGLRenderWindow* win,
  std::vector<vtkSmartPointer<vtkTextureObject>>& targets, size_t layers, int w, int h,
  int keyFormat)
{
  targets.resize(2 * layers);
  for (size_t t = 0; t < targets.size(); ++t)
  {
    auto& target = targets[t];
    const bool rgba = t % 2 == 0 && keyFormat == GL_RGBA32F;
    if (!target)
    {
      target = NearestTexture(win);
      target->SetInternalFormat(rgba ? GL_RGBA32F : GL_R32F);
      target->SetFormat(rgba ? GL_RGBA : GL_RED);
      target->SetDataType(GL_FLOAT);
    }
    if (static_cast<int>(target->GetWidth()) != w || static_cast<int>(target->GetHeight()) != h)
    {
      target->Allocate2D(w, h, rgba ? 4 : 1, VTK_FLOAT);
    }
  }
}

// A request or lookup program's source: the facing rules in (they need double precision).
// `role`: "RMSM_REQUEST", "RMSM_REFINE", "RMSM_BILINEAR" (the 2 x 2 lookup) or "" (the
// nearest lookup).
std::string FrameShader(const std::string& role)
{
  std::string fs = vtkPenumbraResolutionMatchedFS;
  vtkShaderProgram::Substitute(fs, "//VTK::System::Dec",
    std::string("//VTK::System::Dec\n#extension GL_ARB_gpu_shader_fp64 : require\n"
                "#extension GL_ARB_texture_gather : require\n") +
      (role.empty() ? "" : "#define " + role + "\n"),
    false);
  vtkShaderProgram::Substitute(fs, "//PENUMBRA::Classify", vtkPenumbraShadowMapClassify, false);
  return fs;
}
}

// One light's pages: its virtual map, what the pages depend on, which are resident (its page
// table), and its last requests. The atlas and its free list are shared by the lights.
struct LightPages
{
  vtkWeakPointer<vtkLight> Light;
  View Map;
  std::vector<double> Key;
  std::vector<int> SlotOf;              // per page key: atlas slot, -1 when not resident
  std::vector<int32_t> Table;           // per page key: the entry the lookup reads
  std::vector<unsigned char> Requested; // per page key, the last requests
  std::vector<long long> RequestedKeys;
  std::vector<float> Keys; // read-back requests (key + 1 per pixel, 0: none)
  bool TableDirty = true;
  bool FullTable = true;               // every entry to compute and upload (after a flush)
  std::vector<long long> Changed;      // else the pages made or no longer resident since
  vtkMTimeType RequestSamplesTime = 0; // the view samples the last requests came from
  int RequestFrameSize[2] = { 0, 0 };  // the frame's pixels the last requests came from
  int RequestStep = 1;                 // and its analysis step
  double CoarserShare = 0.0;
  GLuint PageTable = 0;                             // R32I, one mip per level
  vtkSmartPointer<vtkTextureObject> PageTableAlias; // binds PageTable through VTK's units
  // Per layer the request pass's outputs: the keys + 1 (RGBA32F: the analysed sample's page,
  // with 2 x 2 analysis blocks the block's four pages) and the levels (R32F), which the
  // lookup reads.
  std::vector<vtkSmartPointer<vtkTextureObject>> RequestTargets;
  // Per layer the refine pass's outputs, full size: the refined pages' keys + 1 (R32F) and
  // every sample's final level (R32F), which the lookup reads when Refined.
  std::vector<vtkSmartPointer<vtkTextureObject>> RefineTargets;
  std::vector<float> RefineKeys; // read-back refined requests
  bool Refined = false;          // the last requests were refined at shadow edges

  // The levels the lookup reads for `layer`, and pixels per side sharing one.
  vtkTextureObject* LevelTarget(size_t layer, int analysisStep, int& step) const
  {
    step = this->Refined ? 1 : analysisStep;
    return (this->Refined ? this->RefineTargets : this->RequestTargets)[2 * layer + 1];
  }
};

struct vtkPenumbraResolutionMatchedShadows::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  penumbra_light_views::CasterBuffers Casters;

  // The levels of every light's virtual map, the lights' pages and the light at hand.
  Pyramid Levels;
  std::vector<LightPages> Lights;
  LightPages* Cur = nullptr;

  // GL objects.
  vtkSmartPointer<vtkTextureObject> Atlas;   // DEPTH32F, AtlasSize^2
  std::vector<int> FreeSlots;                // the atlas's, popped from the back: slot 0 first
  vtkSmartPointer<vtkTextureObject> Scratch; // DEPTH32F, one superpage
  vtkSmartPointer<vtkOpenGLFramebufferObject> MapFBO;
  int PageTableSide = 0; // the page tables' size and levels
  int PageTableMips = 0;
  vtkSmartPointer<vtkOpenGLFramebufferObject> RequestFBO;
  std::unique_ptr<vtkOpenGLQuadHelper> RequestQuad;
  std::unique_ptr<vtkOpenGLQuadHelper> RefineQuad;
  std::unique_ptr<vtkOpenGLQuadHelper> LookupQuads[2]; // nearest, 2 x 2 (FILTER_BILINEAR)

  // Phases (see the definitions).
  bool FrameLight(
    vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, int k, std::string& error);
  bool EnsureResources(
    vtkPenumbraResolutionMatchedShadows* self, vtkOpenGLRenderWindow* win, std::string& error);
  bool FitMap(vtkPenumbraResolutionMatchedShadows* self, vtkLight* light,
    vtkPenumbraSceneGeometry* geometry, const LightSetup& setup);
  void SelectLight(vtkLight* light);
  bool EnsurePageTable(vtkOpenGLRenderWindow* win);
  void Flush(LightPages& pages);
  void GiveBack(LightPages& pages);
  void ReleaseLight(LightPages& pages);
  void SetMapUniforms(vtkPenumbraResolutionMatchedShadows* self, vtkShaderProgram* program,
    vtkPenumbraViewSamplesPass* gbuffer, const LightSetup& setup, bool anyCaster);
  void SetLookupUniforms(vtkPenumbraResolutionMatchedShadows* self, vtkShaderProgram* program,
    vtkTextureObject* levels, int levelStep, const LightSetup& setup);
  bool KeyPass(vtkPenumbraFrame* frame, vtkOpenGLQuadHelper* quad,
    std::vector<vtkSmartPointer<vtkTextureObject>>& targets, int w, int h, int channels,
    std::vector<float>& keys, const std::function<void(int, vtkShaderProgram*)>& bind,
    const std::function<void(int)>& unbind);
  bool MarkRequests(const std::vector<float>& keys, std::string& error);
  bool Request(vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame,
    const LightSetup& setup, std::string& error);
  bool Refine(vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame,
    const LightSetup& setup, std::string& error);
  bool MakeResident(vtkPenumbraResolutionMatchedShadows* self, std::string& error);
  std::vector<NewPage> Allocate(vtkPenumbraResolutionMatchedShadows* self);
  void CopyPages(const std::vector<NewPage>& pages, const std::vector<SuperpageCell>& cells);
  void UploadTable();
  bool RenderPages(
    vtkPenumbraResolutionMatchedShadows* self, std::vector<NewPage>& pages, std::string& error);
  bool Lookup(vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, int k,
    const LightSetup& setup, bool anyCaster, std::string& error);
  void Release(vtkWindow* window);
};

//------------------------------------------------------------------------------
vtkPenumbraResolutionMatchedShadows::vtkPenumbraResolutionMatchedShadows()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraResolutionMatchedShadows::~vtkPenumbraResolutionMatchedShadows()
{
  this->Impl->Release(nullptr);
}

//------------------------------------------------------------------------------
void vtkPenumbraResolutionMatchedShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
}

//------------------------------------------------------------------------------
void vtkPenumbraResolutionMatchedShadows::SetMaxResolution(int resolution)
{
  const int value = 1 << FloorLog2(std::min(32768, std::max(2048, resolution)));
  if (value != this->MaxResolution)
  {
    this->MaxResolution = value;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraResolutionMatchedShadows::SetAtlasSize(int size)
{
  const int value = 1 << FloorLog2(std::min(8192, std::max(512, size)));
  if (value != this->AtlasSize)
  {
    this->AtlasSize = value;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
int vtkPenumbraResolutionMatchedShadows::GetBaseLevel()
{
  // The base level may take at most a quarter of the atlas, so that requests always have room.
  return std::min({ BaseLevelCap, FloorLog2(this->AtlasSize) - 1, FloorLog2(this->MaxResolution) });
}

//------------------------------------------------------------------------------
int vtkPenumbraResolutionMatchedShadows::GetMinimumRequestLevel()
{
  return std::min(MinRequestLevel, FloorLog2(this->MaxResolution));
}

//------------------------------------------------------------------------------
bool vtkPenumbraResolutionMatchedShadows::CanShadow(vtkLight* light)
{
  return light && !vtkPenumbraAreaLight::SafeDownCast(light) &&
    (!light->GetPositional() || light->GetConeAngle() <= MaxSpotCone);
}

//------------------------------------------------------------------------------
int vtkPenumbraResolutionMatchedShadows::ComputeVisibility(
  vtkRenderer*, vtkPenumbraSceneGeometry*, vtkPenumbraViewSamples*, vtkLight*, vtkFloatArray*)
{
  vtkErrorMacro("rmsm answers on the GPU-resident frame only (vtkPenumbraShadowPass), not on "
                "view samples read back to the CPU");
  return 0;
}

//------------------------------------------------------------------------------
int vtkPenumbraResolutionMatchedShadows::ComputeFrame(vtkPenumbraFrame* frame)
{
  return this->ComputeFrameLights(frame, "rmsm",
    [this, frame](int k, std::string& error)
    { return this->Impl->FrameLight(this, frame, k, error); });
}

//------------------------------------------------------------------------------
// One light of a GPU-resident frame: requests from the G-buffer, the pages they need made
// resident (rendered by superpage), the lookup into the light's visibility channel.
bool vtkPenumbraResolutionMatchedShadows::Internals::FrameLight(
  vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, int k, std::string& error)
{
  const auto start = Clock::now();
  self->RequestTimeMs = self->PageTimeMs = self->LookupTimeMs = 0.0;
  self->NumberOfRenderedPages = self->NumberOfSuperpages = self->NumberOfRefinedPages = 0;
  vtkLight* light = frame->GetShadowedLight(k);
  vtkPenumbraSceneGeometry* geometry = frame->GetGeometry();
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  if (!light || !geometry || !win)
  {
    error = "the frame has no light, geometry or OpenGL window";
    return false;
  }
  if (!self->CanShadow(light))
  {
    error = "only directional lights and spot lights with a cone of at most 60 degrees have "
            "resolution-matched shadow maps (point and area lights: use shadowmap, gears or "
            "raytraced)";
    return false;
  }
  double origin[3];
  geometry->GetOrigin(origin);
  LightSetup setup;
  if (!setup.Read(light, origin, error))
  {
    return false;
  }
  win->MakeCurrent();
  if (this->Window && this->Window != win)
  {
    this->Release(nullptr);
  }
  this->Window = win;
  if (!this->EnsureResources(self, win, error))
  {
    return false;
  }
  this->SelectLight(light);
  this->EnsurePageTable(win);
  this->Casters.Update(geometry);
  const bool anyCaster = !setup.Off && this->Casters.VertexCount > 0;
  if (anyCaster)
  {
    // Cached pages for the same view samples that all fitted: the requests are the last ones
    // and all resident, nothing to do before the lookup.
    const bool flushed = this->FitMap(self, light, geometry, setup);
    const bool same = !flushed && frame->GetSamplesTime() == this->Cur->RequestSamplesTime &&
      this->Cur->CoarserShare == 0.0;
    this->Cur->RequestSamplesTime = frame->GetSamplesTime();
    if (same)
    {
      // Nothing to request, allocate or render (the allocation's pass over every sample's
      // keys alone cost a few ms a light): only the statistics.
      self->NumberOfResidentPages =
        self->GetAtlasCapacity() - static_cast<int>(this->FreeSlots.size());
      self->CoarserShare = this->Cur->CoarserShare;
    }
    else
    {
      // The requested pages, then the shadow edges they show take their finer pages.
      this->Cur->Refined = self->RefineLevels > 0;
      if (!(this->Request(self, frame, setup, error) && this->MakeResident(self, error) &&
            (!this->Cur->Refined ||
              (this->Refine(self, frame, setup, error) && this->MakeResident(self, error)))))
      {
        return false;
      }
    }
  }
  const auto lookupStart = Clock::now();
  const bool ok = this->Lookup(self, frame, k, setup, anyCaster, error);
  self->LookupTimeMs = ElapsedMs(lookupStart);
  self->LastTimeMs = ElapsedMs(start);
  return ok;
}

//------------------------------------------------------------------------------
// The atlas, the superpage scratch, the page table (re-created when the levels change) and
// the two frame programs.
bool vtkPenumbraResolutionMatchedShadows::Internals::EnsureResources(
  vtkPenumbraResolutionMatchedShadows* self, vtkOpenGLRenderWindow* win, std::string& error)
{
  if (!glCopyImageSubData)
  {
    error = "copying pages into the atlas needs glCopyImageSubData (OpenGL 4.3 or "
            "GL_ARB_copy_image)";
    return false;
  }
  if (!this->Atlas || static_cast<int>(this->Atlas->GetWidth()) != self->AtlasSize)
  {
    if (this->Atlas)
    {
      this->Atlas->ReleaseGraphicsResources(win);
    }
    this->Atlas = NearestTexture(win);
    this->Atlas->AllocateDepth(self->AtlasSize, self->AtlasSize, vtkTextureObject::Float32);
    const int capacity = self->GetAtlasCapacity();
    this->FreeSlots.resize(static_cast<size_t>(capacity));
    for (int i = 0; i < capacity; ++i)
    {
      this->FreeSlots[static_cast<size_t>(i)] = capacity - 1 - i;
    }
    for (LightPages& pages : this->Lights)
    {
      pages.Key.clear(); // every page is gone
      pages.SlotOf.clear();
    }
  }
  if (!this->Scratch)
  {
    this->Scratch = NearestTexture(win);
    this->Scratch->AllocateDepth(ScratchSide, ScratchSide, vtkTextureObject::Float32);
    this->MapFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->MapFBO->SetContext(win);
    this->RequestFBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->RequestFBO->SetContext(win);
    this->RequestQuad.reset(new vtkOpenGLQuadHelper(
      win, vtkPenumbraFrame::GetSurfaceQuadVS(), FrameShader("RMSM_REQUEST").c_str(), ""));
    this->RefineQuad.reset(new vtkOpenGLQuadHelper(
      win, vtkPenumbraFrame::GetSurfaceQuadVS(), FrameShader("RMSM_REFINE").c_str(), ""));
  }
  auto& lookup = this->LookupQuads[self->Filter == FILTER_BILINEAR ? 1 : 0];
  if (!lookup)
  {
    lookup.reset(new vtkOpenGLQuadHelper(win, vtkPenumbraFrame::GetSurfaceQuadVS(),
      FrameShader(self->Filter == FILTER_BILINEAR ? "RMSM_BILINEAR" : "").c_str(), ""));
  }
  for (auto* quad : { this->RequestQuad.get(), this->RefineQuad.get(), lookup.get() })
  {
    if (!quad->Program || !quad->Program->GetCompiled())
    {
      error = "the request or lookup program does not compile on this OpenGL implementation "
              "(GL_ARB_gpu_shader_fp64, GL_ARB_texture_gather and integer textures are required)";
      return false;
    }
  }
  this->Levels.Base = self->GetBaseLevel();
  this->Levels.Finest = FloorLog2(self->MaxResolution);
  const int side = this->Levels.Side(this->Levels.Finest);
  const int mips = this->Levels.Finest - this->Levels.Base + 1;
  if (this->PageTableSide != side || this->PageTableMips != mips)
  {
    for (LightPages& pages : this->Lights)
    {
      this->ReleaseLight(pages); // new levels: new tables, no page kept
    }
    this->PageTableSide = side;
    this->PageTableMips = mips;
  }
  return true;
}

//------------------------------------------------------------------------------
// Cur = the pages of `light`; the pages of deleted lights are given back first.
void vtkPenumbraResolutionMatchedShadows::Internals::SelectLight(vtkLight* light)
{
  for (LightPages& pages : this->Lights)
  {
    if (!pages.Light)
    {
      this->ReleaseLight(pages);
    }
  }
  this->Cur = &penumbra_light_views::LightCacheEntry(this->Lights, light);
}

//------------------------------------------------------------------------------
// The light's page table: an R32I texture of PageTableSide^2 with PageTableMips levels.
bool vtkPenumbraResolutionMatchedShadows::Internals::EnsurePageTable(vtkOpenGLRenderWindow* win)
{
  LightPages& pages = *this->Cur;
  if (pages.PageTable)
  {
    return false;
  }
  glCreateTextures(GL_TEXTURE_2D, 1, &pages.PageTable);
  glTextureStorage2D(
    pages.PageTable, this->PageTableMips, GL_R32I, this->PageTableSide, this->PageTableSide);
  // Integer textures are complete only with nearest filtering.
  glTextureParameteri(pages.PageTable, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
  glTextureParameteri(pages.PageTable, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  // An alias (not owning the handle) that only binds it through VTK's texture units.
  pages.PageTableAlias = vtkSmartPointer<vtkTextureObject>::New();
  pages.PageTableAlias->SetContext(win);
  pages.PageTableAlias->SetAutoParameters(0);
  pages.PageTableAlias->AssignToExistingTexture(pages.PageTable, GL_TEXTURE_2D);
  pages.Key.clear(); // the table must be filled again
  return true;
}

//------------------------------------------------------------------------------
// Gives a light's atlas slots back to the free list: none of its pages is resident.
void vtkPenumbraResolutionMatchedShadows::Internals::GiveBack(LightPages& pages)
{
  for (int slot : pages.SlotOf)
  {
    if (slot >= 0)
    {
      this->FreeSlots.push_back(slot);
    }
  }
  pages.SlotOf.clear();
}

//------------------------------------------------------------------------------
// Gives a light's slots back to the atlas and frees its GL objects (context current).
void vtkPenumbraResolutionMatchedShadows::Internals::ReleaseLight(LightPages& pages)
{
  this->GiveBack(pages);
  if (pages.PageTable)
  {
    glDeleteTextures(1, &pages.PageTable);
  }
  pages.PageTable = 0;
  pages.PageTableAlias = nullptr;
  for (auto* targets : { &pages.RequestTargets, &pages.RefineTargets })
  {
    for (auto& tex : *targets)
    {
      tex->ReleaseGraphicsResources(this->Window);
    }
    targets->clear();
  }
  pages.Key.clear();
}

//------------------------------------------------------------------------------
// The virtual map of the light, fitted to the whole scene (Lefohn et al. 2007 use a fixed
// light frustum): directional lights an orthographic view along the light, spot lights the
// perspective view circumscribing the cone. When it, the light, the casters or the settings
// changed, or in uncached mode, every page is dropped (true).
bool vtkPenumbraResolutionMatchedShadows::Internals::FitMap(
  vtkPenumbraResolutionMatchedShadows* self, vtkLight* light, vtkPenumbraSceneGeometry* geometry,
  const LightSetup& setup)
{
  double origin[3], box[6];
  geometry->GetOrigin(origin);
  geometry->GetBounds(box);
  for (int c = 0; c < 6; ++c)
  {
    box[c] -= origin[c / 2];
  }
  if (setup.Type == LightSetup::Kind::Directional)
  {
    const double travel[3] = { -setup.Direction[0], -setup.Direction[1], -setup.Direction[2] };
    this->Cur->Map = penumbra_light_views::OrthographicView(travel, box);
  }
  else
  {
    this->Cur->Map = penumbra_light_views::PerspectiveView(
      setup.Position, setup.Axis, std::tan(vtkMath::RadiansFromDegrees(setup.Cone + 1.0)), box);
  }
  std::vector<double> key(&this->Cur->Map.Row[0][0], &this->Cur->Map.Row[0][0] + 16);
  key.push_back(this->Cur->Map.Far);
  key.push_back(static_cast<double>(reinterpret_cast<std::uintptr_t>(light)));
  key.push_back(static_cast<double>(geometry->GetGeometryTime()));
  key.push_back(static_cast<double>(geometry->GetFlagsTime()));
  key.push_back(static_cast<double>(self->GetMTime()));
  key.push_back(this->Levels.Base);
  key.push_back(this->Levels.Finest);
  if (!self->Cached || key != this->Cur->Key)
  {
    this->Cur->Key.swap(key);
    this->Flush(*this->Cur);
    return true;
  }
  return false;
}

//------------------------------------------------------------------------------
// Gives every page of `pages` back to the atlas; the whole base level is then made resident
// again (Allocate()). When the atlas cannot hold that base level, the other lights' pages
// are dropped too (they rebuild when their turn comes).
void vtkPenumbraResolutionMatchedShadows::Internals::Flush(LightPages& pages)
{
  this->GiveBack(pages);
  pages.SlotOf.assign(static_cast<size_t>(this->Levels.Size()), -1);
  const size_t base = static_cast<size_t>(this->Levels.Offset(this->Levels.Base + 1));
  for (LightPages& other : this->Lights)
  {
    if (this->FreeSlots.size() < base && &other != &pages)
    {
      this->GiveBack(other);
      other.Key.clear();
    }
  }
  // Slots popped from the back in ascending order: pages allocated one after another (row by
  // row) then sit side by side in the atlas, and their copies merge (CopyPages()).
  std::sort(this->FreeSlots.begin(), this->FreeSlots.end(), std::greater<int>());
  pages.Table.assign(pages.SlotOf.size(), 0);
  pages.TableDirty = true;
  pages.FullTable = true;
  pages.Changed.clear();
}

//------------------------------------------------------------------------------
// The uniforms the request and lookup programs share: the G-buffer, the facing rules and the
// virtual map's view and levels.
void vtkPenumbraResolutionMatchedShadows::Internals::SetMapUniforms(
  vtkPenumbraResolutionMatchedShadows* self, vtkShaderProgram* program,
  vtkPenumbraViewSamplesPass* gbuffer, const LightSetup& setup, bool anyCaster)
{
  program->SetUniformi("samplePositions", gbuffer->GetPositionTexture()->GetTextureUnit());
  program->SetUniformi("sampleNormals", gbuffer->GetNormalTexture()->GetTextureUnit());
  program->SetUniformi("lightKind", setup.Type == LightSetup::Kind::Directional ? 0 : 2);
  program->SetUniformi("lightOff", setup.Off ? 1 : 0);
  program->SetUniformi("anyCaster", anyCaster ? 1 : 0);
  penumbra_light_views::SetClassifyUniforms(program, setup);
  float matrix[16];
  this->Cur->Map.ToFloatMatrix(matrix);
  program->SetUniformMatrix4x4("lightMatrix", matrix);
  program->SetUniformi("perspective", this->Cur->Map.Perspective ? 1 : 0);
  program->SetUniformf("invFar", static_cast<float>(1.0 / this->Cur->Map.Far));
  program->SetUniformi("baseLevel", this->Levels.Base);
  program->SetUniformi("minLevel", self->GetMinimumRequestLevel());
  program->SetUniformi("finestLevel", this->Levels.Finest);
  program->SetUniformi("lodBias", self->LODBias);
  program->SetUniformi("analysisStep", self->AnalysisStep);
  program->SetUniformi("footprintWidth", self->Footprint == FOOTPRINT_WIDTH ? 1 : 0);
}

//------------------------------------------------------------------------------
// One full-screen pass per layer of the frame into that layer's two `targets` (keys + 1 and
// levels, w x h), each layer's keys read back into `keys` (`channels` per pixel, layer after
// layer). `bind` binds the layer's inputs and sets the program's uniforms, `unbind` releases
// them.
bool vtkPenumbraResolutionMatchedShadows::Internals::KeyPass(vtkPenumbraFrame* frame,
  vtkOpenGLQuadHelper* quad, std::vector<vtkSmartPointer<vtkTextureObject>>& targets, int w, int h,
  int channels, std::vector<float>& keys, const std::function<void(int, vtkShaderProgram*)>& bind,
  const std::function<void(int)>& unbind)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  const size_t perLayer = static_cast<size_t>(w) * h * channels;
  keys.resize(perLayer * static_cast<size_t>(frame->GetNumberOfLayers()));
  vtkShaderProgram* program = quad->Program;
  for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
  {
    vtkPenumbraViewSamplesPass* gbuffer = frame->GetLayer(layer);
    // At full size the G-buffer's depth test leaves the background out (see
    // vtkPenumbraFrame::BindVisibilityTarget()); its keys and levels are cleared to 0.
    const bool full = w == frame->GetWidth() && h == frame->GetHeight();
    penumbra_light_views::QuadPassState pass(win->GetState(), this->RequestFBO,
      { targets[2 * layer].Get(), targets[2 * layer + 1].Get() }, w, h,
      full ? gbuffer->GetDepthTexture() : nullptr);
    if (full)
    {
      const GLfloat zero[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
      glClearBufferfv(GL_COLOR, 0, zero);
      glClearBufferfv(GL_COLOR, 1, zero);
    }
    win->GetShaderCache()->ReadyShaderProgram(program);
    gbuffer->GetPositionTexture()->Activate();
    gbuffer->GetNormalTexture()->Activate();
    bind(layer, program);
    quad->Render();
    unbind(layer);
    gbuffer->GetPositionTexture()->Deactivate();
    gbuffer->GetNormalTexture()->Deactivate();
    this->RequestFBO->ActivateReadBuffer(0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, h, channels == 4 ? GL_RGBA : GL_RED, GL_FLOAT,
      keys.data() + perLayer * static_cast<size_t>(layer));
  }
  return true;
}

//------------------------------------------------------------------------------
// The read-back `keys` (key + 1 per pixel, 0: none) marked in one byte per page of the
// pyramid and appended to the requested keys (Lefohn et al. 2007's connected components,
// compaction and sort, §3.2, on the CPU); false when a key lies outside the table.
bool vtkPenumbraResolutionMatchedShadows::Internals::MarkRequests(
  const std::vector<float>& keys, std::string& error)
{
  const long long size = static_cast<long long>(this->Cur->Requested.size());
  bool outside = false;
  for (float value : keys)
  {
    const long long key = static_cast<long long>(value) - 1;
    outside = outside || key >= size;
    if (key < 0 || key >= size)
    {
      continue;
    }
    if (!this->Cur->Requested[static_cast<size_t>(key)])
    {
      this->Cur->Requested[static_cast<size_t>(key)] = 1;
      this->Cur->RequestedKeys.push_back(key);
    }
  }
  if (outside)
  {
    error = "a page request lies outside the page table";
  }
  return !outside;
}

//------------------------------------------------------------------------------
// Lefohn et al. 2007, §3.3.2 (Algorithm 2, steps 1-8): every layer's pending samples write
// the key of the page they need; the keys are read back and de-duplicated with one byte per
// page (the paper's connected components, compaction and sort serve a GPU that cannot
// afford the read-back of every request; on llvmpipe it costs a copy in host memory).
bool vtkPenumbraResolutionMatchedShadows::Internals::Request(
  vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, const LightSetup& setup,
  std::string& error)
{
  const auto start = Clock::now();
  const int step = self->AnalysisStep;
  const int w = (frame->GetWidth() + step - 1) / step, h = (frame->GetHeight() + step - 1) / step;
  this->Cur->RequestFrameSize[0] = frame->GetWidth();
  this->Cur->RequestFrameSize[1] = frame->GetHeight();
  this->Cur->RequestStep = step;
  const size_t layers = static_cast<size_t>(frame->GetNumberOfLayers());
  // Per layer the keys (RGBA: the block's samples) and the levels.
  EnsureKeyTargets(frame->GetWindow(), this->Cur->RequestTargets, layers, w, h, GL_RGBA32F);
  this->Cur->Requested.assign(this->Cur->SlotOf.size(), 0);
  this->Cur->RequestedKeys.clear();
  this->Cur->RefineKeys.clear();
  // One key per pixel, or the four of each 2 x 2 block.
  this->KeyPass(
    frame, this->RequestQuad.get(), this->Cur->RequestTargets, w, h, step == 2 ? 4 : 1,
    this->Cur->Keys,
    [&](int layer, vtkShaderProgram* program)
    { this->SetMapUniforms(self, program, frame->GetLayer(layer), setup, true); },
    [](int) {});
  if (!this->MarkRequests(this->Cur->Keys, error))
  {
    return false;
  }
  std::sort(this->Cur->RequestedKeys.begin(), this->Cur->RequestedKeys.end());
  self->NumberOfRequestedPages = static_cast<int>(this->Cur->RequestedKeys.size());
  self->RequestedLevels[0] = self->RequestedLevels[1] = 0;
  if (!this->Cur->RequestedKeys.empty())
  {
    int px, py;
    this->Levels.Decode(this->Cur->RequestedKeys.front(), self->RequestedLevels[0], px, py);
    this->Levels.Decode(this->Cur->RequestedKeys.back(), self->RequestedLevels[1], px, py);
  }
  self->RequestTimeMs = ElapsedMs(start);
  return true;
}

//------------------------------------------------------------------------------
// Shadow-edge refinement (the refine program, RMSM_REFINE in the shader): with the requested
// pages resident, the samples whose 2 x 2 taps straddle a shadow edge request the page
// RefineLevels levels finer; every sample's final level goes to RefineTargets for the
// lookup. The new keys join the requested ones (so allocation never evicts them).
bool vtkPenumbraResolutionMatchedShadows::Internals::Refine(
  vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, const LightSetup& setup,
  std::string& error)
{
  const auto start = Clock::now();
  const int w = frame->GetWidth(), h = frame->GetHeight();
  EnsureKeyTargets(frame->GetWindow(), this->Cur->RefineTargets,
    static_cast<size_t>(frame->GetNumberOfLayers()), w, h, GL_R32F);
  const size_t before = this->Cur->RequestedKeys.size();
  this->KeyPass(
    frame, this->RefineQuad.get(), this->Cur->RefineTargets, w, h, 1, this->Cur->RefineKeys,
    [&](int layer, vtkShaderProgram* program)
    {
      vtkTextureObject* levels = this->Cur->RequestTargets[2 * static_cast<size_t>(layer) + 1];
      levels->Activate();
      this->SetMapUniforms(self, program, frame->GetLayer(layer), setup, true);
      this->SetLookupUniforms(self, program, levels, self->AnalysisStep, setup);
      program->SetUniformi("refineLevels", self->RefineLevels);
    },
    [&](int layer)
    {
      this->Cur->PageTableAlias->Deactivate();
      this->Atlas->Deactivate();
      this->Cur->RequestTargets[2 * static_cast<size_t>(layer) + 1]->Deactivate();
    });
  if (!this->MarkRequests(this->Cur->RefineKeys, error))
  {
    return false;
  }
  std::sort(this->Cur->RequestedKeys.begin() + static_cast<std::ptrdiff_t>(before),
    this->Cur->RequestedKeys.end());
  self->NumberOfRefinedPages = static_cast<int>(this->Cur->RequestedKeys.size() - before);
  self->RequestTimeMs += ElapsedMs(start);
  return true;
}

//------------------------------------------------------------------------------
// The requested pages made resident: allocated, the page table uploaded, the new pages
// rendered.
bool vtkPenumbraResolutionMatchedShadows::Internals::MakeResident(
  vtkPenumbraResolutionMatchedShadows* self, std::string& error)
{
  const auto start = Clock::now();
  std::vector<NewPage> pages = this->Allocate(self);
  this->UploadTable();
  const bool ok = this->RenderPages(self, pages, error);
  self->PageTimeMs += ElapsedMs(start);
  return ok;
}

//------------------------------------------------------------------------------
// §3.3.3-3.3.5: atlas slots for the whole base level (when flushed) and the requested pages
// that are not resident, coarse levels first. When the free list runs out, the pages no
// sample requested this frame are evicted once; what still does not fit stays out, and its
// samples read the finest resident coarser page. Returns the pages to render.
std::vector<NewPage> vtkPenumbraResolutionMatchedShadows::Internals::Allocate(
  vtkPenumbraResolutionMatchedShadows* self)
{
  std::vector<long long> wanted;
  const int base = this->Levels.Base;
  for (long long key = 0; key < this->Levels.Offset(base + 1); ++key)
  {
    if (this->Cur->SlotOf[static_cast<size_t>(key)] < 0)
    {
      wanted.push_back(key);
    }
  }
  for (long long key : this->Cur->RequestedKeys)
  {
    if (key >= this->Levels.Offset(base + 1) && this->Cur->SlotOf[static_cast<size_t>(key)] < 0)
    {
      wanted.push_back(key);
    }
  }
  bool evicted = false;
  std::vector<NewPage> pages;
  for (long long key : wanted)
  {
    if (this->FreeSlots.empty() && !evicted)
    {
      evicted = true;
      for (long long r = this->Levels.Offset(base + 1); r < this->Levels.Size(); ++r)
      {
        int& slot = this->Cur->SlotOf[static_cast<size_t>(r)];
        if (slot >= 0 && !this->Cur->Requested[static_cast<size_t>(r)])
        {
          this->FreeSlots.push_back(slot);
          slot = -1;
          this->Cur->TableDirty = true;
          this->Cur->Changed.push_back(r);
        }
      }
    }
    if (this->FreeSlots.empty())
    {
      break; // the finer requests stay out: coarser pages serve them
    }
    NewPage page;
    this->Levels.Decode(key, page.K, page.X, page.Y);
    page.Slot = this->FreeSlots.back();
    this->FreeSlots.pop_back();
    this->Cur->SlotOf[static_cast<size_t>(key)] = page.Slot;
    pages.push_back(page);
    this->Cur->TableDirty = true;
    this->Cur->Changed.push_back(key);
  }
  const int capacity = self->GetAtlasCapacity();
  self->NumberOfResidentPages = capacity - static_cast<int>(this->FreeSlots.size());
  size_t requesting = 0, coarser = 0;
  for (const auto* keys : { &this->Cur->Keys, &this->Cur->RefineKeys })
  {
    for (float value : *keys)
    {
      const long long key = static_cast<long long>(value) - 1;
      if (key >= 0)
      {
        ++requesting;
        coarser += this->Cur->SlotOf[static_cast<size_t>(key)] < 0 ? 1 : 0;
      }
    }
  }
  this->Cur->CoarserShare = requesting ? static_cast<double>(coarser) / requesting : 0.0;
  self->CoarserShare = this->Cur->CoarserShare;
  return pages;
}

//------------------------------------------------------------------------------
// The page table's entries, level by level from the base: a resident page's own slot, else
// its parent's entry (the finest resident coarser page), uploaded when anything changed. After
// a flush every entry is computed and uploaded; otherwise only the subtrees of the pages made
// or no longer resident since the last upload, each level's bounding rectangle of them
// uploaded (the refined pages of a frame are a few dozen: the whole table, 1.4 million
// entries at 32768^2, cost a few ms to compute and upload).
void vtkPenumbraResolutionMatchedShadows::Internals::UploadTable()
{
  LightPages& cur = *this->Cur;
  if (!cur.TableDirty)
  {
    return;
  }
  const Pyramid& p = this->Levels;
  const int levels = p.Finest - p.Base + 1;
  // Per level the rectangle to upload, [x0, x1) x [y0, y1).
  std::vector<int> rect(4 * static_cast<size_t>(levels), 0);
  // The entries of level k in [x0, x1) x [y0, y1), their parents' being up to date.
  auto compute = [&](int k, int x0, int x1, int y0, int y1)
  {
    const int side = p.Side(k);
    const int32_t tag = (k - p.Base) << 24;
    for (int y = y0; y < y1; ++y)
    {
      const size_t row = static_cast<size_t>(p.Offset(k)) + static_cast<size_t>(y) * side;
      const int* slots = cur.SlotOf.data() + row;
      int32_t* entries = cur.Table.data() + row;
      // The base level is always resident (it takes at most a quarter of the atlas).
      const int32_t* parents = k == p.Base
        ? nullptr
        : cur.Table.data() + p.Offset(k - 1) + static_cast<size_t>(y >> 1) * (side >> 1);
      for (int x = x0; x < x1; ++x)
      {
        entries[x] = slots[x] >= 0 || !parents ? (tag | std::max(slots[x], 0)) : parents[x >> 1];
      }
    }
    int* r = rect.data() + 4 * (k - p.Base);
    if (r[0] == r[1])
    {
      r[0] = x0, r[1] = x1, r[2] = y0, r[3] = y1;
    }
    else
    {
      r[0] = std::min(r[0], x0), r[1] = std::max(r[1], x1);
      r[2] = std::min(r[2], y0), r[3] = std::max(r[3], y1);
    }
  };
  if (cur.FullTable || cur.Changed.size() > 65536)
  {
    for (int k = p.Base; k <= p.Finest; ++k)
    {
      compute(k, 0, p.Side(k), 0, p.Side(k));
    }
  }
  else
  {
    // Each changed page's subtree, coarse to fine (an overlap is computed twice, alike).
    for (long long key : cur.Changed)
    {
      int k, x, y;
      p.Decode(key, k, x, y);
      for (int kk = k; kk <= p.Finest; ++kk)
      {
        const int d = kk - k;
        compute(kk, x << d, (x + 1) << d, y << d, (y + 1) << d);
      }
    }
  }
  // Direct state access: no texture unit's binding changes under VTK's bookkeeping.
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  for (int k = p.Base; k <= p.Finest; ++k)
  {
    const int* r = rect.data() + 4 * (k - p.Base);
    if (r[0] == r[1])
    {
      continue;
    }
    glPixelStorei(GL_UNPACK_ROW_LENGTH, p.Side(k));
    glTextureSubImage2D(cur.PageTable, p.Finest - k, r[0], r[2], r[1] - r[0], r[3] - r[2],
      GL_RED_INTEGER, GL_INT,
      cur.Table.data() + p.Offset(k) + static_cast<size_t>(r[2]) * p.Side(k) + r[0]);
  }
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  cur.Changed.clear();
  cur.FullTable = false;
  cur.TableDirty = false;
}

//------------------------------------------------------------------------------
// §3.3.3 (steps 10-12): the new pages binned into superpages (32 x 32 pages of one level);
// per superpage one pass of the casters into the scratch, cropped to the bounding rectangle
// of its new pages, then each page copied into its atlas slot.
bool vtkPenumbraResolutionMatchedShadows::Internals::RenderPages(
  vtkPenumbraResolutionMatchedShadows* self, std::vector<NewPage>& pages, std::string& error)
{
  if (pages.empty())
  {
    return true;
  }
  vtkOpenGLRenderWindow* win = this->Window;
  std::string vs = vtkPenumbraShadowMapVS, fs = vtkPenumbraShadowMapFS;
  if (!this->Cur->Map.Perspective)
  {
    // Orthographic depth is linear already: the rasterizer writes it (early depth test).
    for (std::string* source : { &vs, &fs })
    {
      vtkShaderProgram::Substitute(*source, "//VTK::System::Dec",
        "//VTK::System::Dec\n#define PENUMBRA_HARDWARE_DEPTH\n", false);
    }
  }
  vtkShaderProgram* program = win->GetShaderCache()->ReadyShaderProgram(vs.c_str(), fs.c_str(), "");
  if (!program || !program->GetCompiled())
  {
    error = "the shadow map shaders do not compile or link on this OpenGL implementation";
    return false;
  }
  std::sort(pages.begin(), pages.end());
  vtkOpenGLState* ostate = win->GetState();
  penumbra_light_views::MapRenderState renderState(
    ostate, this->MapFBO, ScratchSide, ScratchSide, false);
  vtkOpenGLState::ScopedglScissor scissor(ostate);
  this->MapFBO->AddDepthAttachment(this->Scratch);
  ostate->vtkglDrawBuffer(GL_NONE);
  ostate->vtkglReadBuffer(GL_NONE);
  ostate->vtkglEnable(GL_SCISSOR_TEST);
  this->Casters.Bind(program);
  program->SetUniformi("perspective", this->Cur->Map.Perspective ? 1 : 0);
  program->SetUniformf("invFar", static_cast<float>(1.0 / this->Cur->Map.Far));
  program->SetUniformi("peel", 0);
  program->SetUniformf("peelGap", 0.0f);
  const size_t perBatch = size_t(1) << (2 * ScratchCellBits);
  std::vector<SuperpageCell> cells;
  std::vector<int> sizes; // per cell of the batch, the bounding rectangle's w and h
  for (size_t first = 0; first < pages.size();)
  {
    // A batch: up to perBatch superpages, each in its cell of the scratch.
    cells.clear();
    sizes.clear();
    while (first < pages.size() && cells.size() < perBatch)
    {
      SuperpageCell cell{ first, first, pages[first].X, pages[first].Y, 0, 0 };
      int x1 = cell.X0, y1 = cell.Y0;
      while (cell.Last < pages.size() && pages[cell.Last].SameSuperpage(pages[first]))
      {
        cell.X0 = std::min(cell.X0, pages[cell.Last].X);
        x1 = std::max(x1, pages[cell.Last].X);
        cell.Y0 = std::min(cell.Y0, pages[cell.Last].Y);
        y1 = std::max(y1, pages[cell.Last].Y);
        ++cell.Last;
      }
      const int index = static_cast<int>(cells.size());
      cell.CellX = (index & ((1 << ScratchCellBits) - 1)) * SuperpageSide;
      cell.CellY = (index >> ScratchCellBits) * SuperpageSide;
      cells.push_back(cell);
      sizes.push_back((x1 - cell.X0 + 1) << PageBits);
      sizes.push_back((y1 - cell.Y0 + 1) << PageBits);
      first = cell.Last;
    }
    // Only the cells' rectangles cleared, before the batch's draws (the previous batch's copies
    // waited for its draws: nothing pending writes the scratch). A clear of the whole 1024^2
    // scratch makes llvmpipe process every tile of it; a scissored clear is a quad drawn.
    // grazing_light, moving light: about 2-3 % of the frame.
    const GLfloat one = 1.0f;
    if (glClearTexSubImage)
    {
      for (size_t c = 0; c < cells.size(); ++c)
      {
        glClearTexSubImage(this->Scratch->GetHandle(), 0, cells[c].CellX, cells[c].CellY, 0,
          sizes[2 * c], sizes[2 * c + 1], 1, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
      }
    }
    else
    {
      ostate->vtkglDisable(GL_SCISSOR_TEST);
      glClearBufferfv(GL_DEPTH, 0, &one);
      ostate->vtkglEnable(GL_SCISSOR_TEST);
    }
    for (size_t c = 0; c < cells.size(); ++c)
    {
      const SuperpageCell& cell = cells[c];
      const int w = sizes[2 * c], h = sizes[2 * c + 1];
      const View crop = CroppedView(
        this->Cur->Map, pages[cell.First].K, cell.X0 << PageBits, cell.Y0 << PageBits, w, h);
      float matrix[16];
      crop.ToFloatMatrix(matrix);
      program->SetUniformMatrix4x4("lightMatrix", matrix);
      ostate->vtkglViewport(cell.CellX, cell.CellY, w, h);
      ostate->vtkglScissor(cell.CellX, cell.CellY, w, h);
      glDrawArrays(GL_TRIANGLES, 0, this->Casters.VertexCount);
      ++self->NumberOfSuperpages;
    }
    this->CopyPages(pages, cells);
  }
  self->NumberOfRenderedPages += static_cast<int>(pages.size());
  self->TotalRenderedPages += static_cast<long long>(pages.size());
  return true;
}

//------------------------------------------------------------------------------
// §3.3.3 (step 12): the pages of a batch of rendered superpages copied from their scratch
// cells into their atlas slots (the first copy waits for the batch's draws).
void vtkPenumbraResolutionMatchedShadows::Internals::CopyPages(
  const std::vector<NewPage>& pages, const std::vector<SuperpageCell>& cells)
{
  const GLuint scratch = this->Scratch->GetHandle(), atlas = this->Atlas->GetHandle();
  const int slotsPerRow = static_cast<int>(this->Atlas->GetWidth()) >> PageBits;
  for (const SuperpageCell& cell : cells)
  {
    for (size_t i = cell.First; i < cell.Last;)
    {
      // A run of pages side by side in one row whose slots follow each other in one atlas row
      // (the free list hands out consecutive slots, and allocation goes row by row) is one
      // copy: on llvmpipe each copy costs more than its texels.
      const NewPage& page = pages[i];
      size_t end = i + 1;
      while (end < cell.Last && pages[end].Y == page.Y &&
        pages[end].X == page.X + static_cast<int>(end - i) &&
        pages[end].Slot == page.Slot + static_cast<int>(end - i) &&
        pages[end].Slot / slotsPerRow == page.Slot / slotsPerRow)
      {
        ++end;
      }
      glCopyImageSubData(scratch, GL_TEXTURE_2D, 0, cell.CellX + ((page.X - cell.X0) << PageBits),
        cell.CellY + ((page.Y - cell.Y0) << PageBits), 0, atlas, GL_TEXTURE_2D, 0,
        (page.Slot % slotsPerRow) << PageBits, (page.Slot / slotsPerRow) << PageBits, 0,
        static_cast<int>(end - i) << PageBits, PageSize, 1);
      i = end;
    }
  }
}

//------------------------------------------------------------------------------
// §3.3.1: every layer's samples looked up through the page table into light k's visibility
// channel (the facing rules decide the others).
bool vtkPenumbraResolutionMatchedShadows::Internals::Lookup(
  vtkPenumbraResolutionMatchedShadows* self, vtkPenumbraFrame* frame, int k,
  const LightSetup& setup, bool anyCaster, std::string& error)
{
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  vtkOpenGLQuadHelper* quad = this->LookupQuads[self->Filter == FILTER_BILINEAR ? 1 : 0].get();
  vtkShaderProgram* program = quad->Program;
  if (!anyCaster)
  {
    // The programs read the textures only for pending samples, which there are none of; the
    // uniforms still need a view (the identity).
    this->Cur->Map = View();
    for (int r = 0; r < 4; ++r)
    {
      this->Cur->Map.Row[r][r] = 1.0;
    }
  }
  else if (this->Cur->RequestTargets.size() < 2 * static_cast<size_t>(frame->GetNumberOfLayers()))
  {
    error = "the lookup has no requests for some layer of the frame";
    return false;
  }
  for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
  {
    vtkPenumbraViewSamplesPass* gbuffer = frame->GetLayer(layer);
    vtkPenumbraFrame::VisibilityTarget target = frame->BindVisibilityTarget(layer, k);
    win->GetShaderCache()->ReadyShaderProgram(program);
    gbuffer->GetPositionTexture()->Activate();
    gbuffer->GetNormalTexture()->Activate();
    int step = 1;
    vtkTextureObject* levels = anyCaster
      ? this->Cur->LevelTarget(static_cast<size_t>(layer), self->AnalysisStep, step)
      : gbuffer->GetPositionTexture(); // not read: no sample is pending
    levels->Activate();
    this->SetMapUniforms(self, program, gbuffer, setup, anyCaster);
    this->SetLookupUniforms(self, program, levels, step, setup);
    quad->Render();
    this->Cur->PageTableAlias->Deactivate();
    this->Atlas->Deactivate();
    if (anyCaster)
    {
      levels->Deactivate();
    }
    gbuffer->GetPositionTexture()->Deactivate();
    gbuffer->GetNormalTexture()->Deactivate();
  }
  return true;
}

//------------------------------------------------------------------------------
// The uniforms of the programs that read the pages (refine and lookup): the sample levels
// (`levels`, bound, one per levelStep x levelStep pixels), the atlas and page table (bound
// here), and the bias.
void vtkPenumbraResolutionMatchedShadows::Internals::SetLookupUniforms(
  vtkPenumbraResolutionMatchedShadows* self, vtkShaderProgram* program, vtkTextureObject* levels,
  int levelStep, const LightSetup& setup)
{
  this->Atlas->Activate();
  this->Cur->PageTableAlias->Activate();
  program->SetUniformi("requests", levels->GetTextureUnit());
  program->SetUniformi("levelStep", levelStep);
  program->SetUniformi("atlas", this->Atlas->GetTextureUnit());
  program->SetUniformi("pageTable", this->Cur->PageTableAlias->GetTextureUnit());
  program->SetUniformi(
    "slotsPerRowBits", FloorLog2(static_cast<int>(this->Atlas->GetWidth()) >> PageBits));
  program->SetUniformf("tanHalf", static_cast<float>(this->Cur->Map.TanHalf));
  program->SetUniformf("footprintScale",
    static_cast<float>(
      std::max(2.0 / Norm3(this->Cur->Map.Row[0]), 2.0 / Norm3(this->Cur->Map.Row[1]))));
  program->SetUniformf("depthPerLengthOrtho", static_cast<float>(Norm3(this->Cur->Map.Row[2])));
  penumbra_light_views::SetLightUniforms(program, setup);
  program->SetUniformf("constantBias", static_cast<float>(self->Bias));
  program->SetUniformf("slopeBias", static_cast<float>(self->SlopeBias));
  program->SetUniformf("maxTangent", static_cast<float>(MaxTangent));
}

//------------------------------------------------------------------------------
bool vtkPenumbraResolutionMatchedShadows::GetSampleLevels(vtkLight* light, vtkIntArray* levels)
{
  levels->SetNumberOfComponents(1);
  levels->SetNumberOfTuples(0);
  Internals& impl = *this->Impl;
  auto pages = std::find_if(impl.Lights.begin(), impl.Lights.end(),
    [light](const LightPages& p) { return light && p.Light == light; });
  if (!impl.Window || pages == impl.Lights.end() || pages->RequestTargets.size() < 2)
  {
    return false;
  }
  int step = 1;
  vtkTextureObject* target = pages->LevelTarget(0, pages->RequestStep, step);
  const int w = static_cast<int>(target->GetWidth()), h = static_cast<int>(target->GetHeight());
  std::vector<float> analysed(static_cast<size_t>(w) * h);
  impl.Window->MakeCurrent();
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(target->GetHandle(), 0, GL_RED, GL_FLOAT,
    static_cast<GLsizei>(analysed.size() * sizeof(float)), analysed.data());
  const int width = pages->RequestFrameSize[0], height = pages->RequestFrameSize[1];
  levels->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
  for (int y = 0; y < height; ++y)
  {
    for (int x = 0; x < width; ++x)
    {
      levels->SetValue(static_cast<vtkIdType>(y) * width + x,
        static_cast<int>(analysed[static_cast<size_t>(y / step) * w + x / step]));
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkPenumbraResolutionMatchedShadows::Internals::Release(vtkWindow* window)
{
  if (!this->Window || (window && window != this->Window))
  {
    return;
  }
  this->Window->MakeCurrent();
  this->Casters.Release();
  for (auto* tex : { this->Atlas.Get(), this->Scratch.Get() })
  {
    if (tex)
    {
      tex->ReleaseGraphicsResources(this->Window);
    }
  }
  for (LightPages& pages : this->Lights)
  {
    this->ReleaseLight(pages);
  }
  this->Lights.clear();
  this->Cur = nullptr;
  this->FreeSlots.clear();
  this->PageTableSide = this->PageTableMips = 0;
  for (auto* fbo : { this->MapFBO.Get(), this->RequestFBO.Get() })
  {
    if (fbo)
    {
      fbo->ReleaseGraphicsResources(this->Window);
    }
  }
  for (auto* quad : { this->RequestQuad.get(), this->RefineQuad.get(), this->LookupQuads[0].get(),
         this->LookupQuads[1].get() })
  {
    if (quad)
    {
      quad->ReleaseGraphicsResources(this->Window);
    }
  }
  this->Atlas = this->Scratch = nullptr;
  this->MapFBO = this->RequestFBO = nullptr;
  this->RequestQuad.reset();
  this->RefineQuad.reset();
  this->LookupQuads[0].reset();
  this->LookupQuads[1].reset();
  this->Window = nullptr;
}

//------------------------------------------------------------------------------
void vtkPenumbraResolutionMatchedShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "MaxResolution: " << this->MaxResolution << "\n";
  os << indent << "AtlasSize: " << this->AtlasSize << "\n";
  os << indent << "Cached: " << this->Cached << "\n";
  os << indent << "Bias: " << this->Bias << "\n";
  os << indent << "SlopeBias: " << this->SlopeBias << "\n";
  os << indent << "RefineLevels: " << this->RefineLevels << "\n";
  os << indent << "NumberOfRequestedPages: " << this->NumberOfRequestedPages << "\n";
  os << indent << "NumberOfRenderedPages: " << this->NumberOfRenderedPages << "\n";
  os << indent << "NumberOfSuperpages: " << this->NumberOfSuperpages << "\n";
  os << indent << "NumberOfResidentPages: " << this->NumberOfResidentPages << "\n";
  os << indent << "CoarserShare: " << this->CoarserShare << "\n";
}
