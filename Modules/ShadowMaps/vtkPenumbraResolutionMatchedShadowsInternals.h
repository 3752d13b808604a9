/**
 * @file   vtkPenumbraResolutionMatchedShadowsInternals.h
 * @brief  The state of a vtkPenumbraResolutionMatchedShadows shared by its files: the
 *         technique, its per-light driver and the virtual map's fit
 *         (vtkPenumbraResolutionMatchedShadows.cxx), the page requests and the page table
 *         (vtkPenumbraResolutionMatchedPages.cxx), rendering the pages
 *         (vtkPenumbraResolutionMatchedRender.cxx) and the lookup through the page table
 *         (vtkPenumbraResolutionMatchedLookup.cxx). Private to the module.
 */

#ifndef vtkPenumbraResolutionMatchedShadowsInternals_h
#define vtkPenumbraResolutionMatchedShadowsInternals_h

#include "vtkPenumbraResolutionMatchedShadows.h"

#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraCasterBuffers.h"
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

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

using penumbra::Clock;
using penumbra::ElapsedMs;
using penumbra_light_views::LightSetup;
using penumbra_light_views::View;

namespace penumbra_rmsm
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

inline int FloorLog2(int v)
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

// GPU resources (vtkPenumbraResolutionMatchedShadows.cxx).
vtkSmartPointer<vtkTextureObject> NearestTexture(vtkOpenGLRenderWindow* win);
}

// The files of the technique use these names as the one file they came from did.
using namespace penumbra_rmsm;

struct vtkPenumbraResolutionMatchedShadows::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  penumbra_casters::CasterBuffers Casters;

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

#endif
