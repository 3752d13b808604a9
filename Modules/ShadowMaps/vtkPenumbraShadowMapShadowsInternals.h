/**
 * @file   vtkPenumbraShadowMapShadowsInternals.h
 * @brief  The state of a vtkPenumbraShadowMapShadows shared by its files: the technique and
 *         its per-light driver (vtkPenumbraShadowMapShadows.cxx), fitting the light views to
 *         the receivers (vtkPenumbraShadowMapFit.cxx), rendering the maps
 *         (vtkPenumbraShadowMapRender.cxx), and the lookup with its soft modes and the
 *         receivers' shader code (vtkPenumbraShadowMapLookup.cxx). Private to the module.
 */

#ifndef vtkPenumbraShadowMapShadowsInternals_h
#define vtkPenumbraShadowMapShadowsInternals_h

#include "vtkPenumbraShadowMapShadows.h"

#include "vtkCamera.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraCasterBuffers.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraGoniometricLight.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraRemoteShadows.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkTextureUnitManager.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

using penumbra_light_views::LightSetup;
using penumbra_light_views::View;

namespace penumbra_shadow_maps
{

using penumbra::Clock;
using penumbra::ElapsedMs;

constexpr unsigned char Decided = 0;
constexpr unsigned char Pending = 1;

// One light's maps, kept until the light, the casters, the view or the settings change.
// Slots: 0 (directional, spot), 2 * axis + negative (cube faces), hemisphere (paraboloid).
struct LightMaps
{
  vtkWeakPointer<vtkLight> Light;
  std::vector<double> Key;
  bool Valid = false;
  bool Paraboloid = false;
  int Width = 0, Height = 0;     // texels (non-square only for one-view lights)
  double Need[2] = { 0.0, 0.0 }; // RESM: the estimate the size came from
  std::vector<View> Views;
  std::vector<std::vector<float>> Maps;                    // CPU lookup
  std::vector<vtkSmartPointer<vtkTextureObject>> Textures; // GPU lookup (compare mode)
  double Centre[3] = { 0, 0, 0 };                          // paraboloid: the light, rebased
  double Far = 1.0;                                        // paraboloid: depth = distance / Far
  double MapScale = 1.0; // paraboloid: paraboloid coordinates -> NDC
};

inline double Norm3(const double* v)
{
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// Slot layouts: one view (directional, spot), six cube faces, two paraboloid hemispheres.
constexpr int SlotsOne = 0;
constexpr int SlotsCube = 1;
constexpr int SlotsParaboloid = 2;

// What fitting a light's views needs to know of its receivers (the pending samples, facing
// the light and inside its cone): Brabec 2003, ch. 4.2. Filled on the CPU from a sample set
// or on the GPU from the G-buffer (the extent shader), merged the same way.
struct ReceiverExtent
{
  std::array<char, 6> Used{};
  double Box[6] = { std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max(), -std::numeric_limits<double>::max() };
  double Lo[3] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max() };
  double Hi[3] = { -std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    -std::numeric_limits<double>::max() };
  double Farthest = 0.0;
  double SpotTan = 0.0;
  vtkIdType Pending = 0;
  // Directional lights fitted with the minimum-area rectangle: the receivers' tile-box
  // corners in the light plane (along LightAxes' axes[0] and axes[1]).
  bool CollectPlane = false;
  bool Square = false; // the shortest longer side instead of the least area
  std::vector<std::array<double, 2>> Plane;
};

using TileOutputs = std::array<std::vector<float>, 4>;

// The scene's triangle vertices in runs of SceneChunks::Size, each with its box, so that the
// scene fit (ExtentFromScene) reads only the runs whose box could move the extent: every
// quantity of the extent is a minimum or maximum over the vertices, and a box bounds its
// vertices. Rebuilt when the triangles change (vtkPenumbraSceneGeometry::GetGeometryTime()),
// kept while only the light moves, which is when the scene fit is recomputed.
struct SceneChunks
{
  static constexpr vtkIdType Size = 256;
  vtkPenumbraSceneGeometry* Geometry = nullptr; // identity only, never dereferenced
  vtkMTimeType Time = 0;
  vtkIdType Count = 0; // vertices (3 per triangle)
  std::vector<std::array<double, 6>> Boxes;

  void Update(vtkPenumbraSceneGeometry* geometry)
  {
    const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
    const vtkIdType count = 3 * triangles.Size();
    if (geometry == this->Geometry && geometry->GetGeometryTime() == this->Time &&
      count == this->Count)
    {
      return;
    }
    this->Geometry = geometry;
    this->Time = geometry->GetGeometryTime();
    this->Count = count;
    this->Boxes.assign(static_cast<size_t>((count + Size - 1) / Size), {});
    vtkSMPTools::For(0, static_cast<vtkIdType>(this->Boxes.size()),
      [&](vtkIdType first, vtkIdType last)
      {
        for (vtkIdType c = first; c < last; ++c)
        {
          std::array<double, 6>& box = this->Boxes[static_cast<size_t>(c)];
          box = { std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
            std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
            std::numeric_limits<double>::max(), -std::numeric_limits<double>::max() };
          for (vtkIdType v = c * Size; v < std::min(count, (c + 1) * Size); ++v)
          {
            double p[3];
            triangles.GetCorner(v / 3, static_cast<int>(v % 3), p);
            for (int k = 0; k < 3; ++k)
            {
              box[2 * k] = std::min(box[2 * k], p[k]);
              box[2 * k + 1] = std::max(box[2 * k + 1], p[k]);
            }
          }
        }
      });
  }
};

constexpr int Tile = 4; // samples per side of a tile box (see ExtentFromTiles)

// The settings a lookup program is compiled for. The uniforms that only choose a branch
// (the slot layout, the projection, the filter, the facing rules' light kind) become
// constants, so that the compiler drops the branches a light does not take: llvmpipe runs
// every branch of an `if` under a lane mask, texture taps included, so a program that
// carries the soft lookups' and the bilinear filter's taps pays for them on every pixel.
struct LookupVariant
{
  int SlotMode = 0;
  int Perspective = 0;
  int Radius = 0;
  int Bilinear = 0;
  int AreaMode = 0;
  int LightKind = 0;
  int LightOff = 0;
  int AnyCaster = 0;

  std::vector<std::pair<const char*, int>> Constants() const
  {
    return { { "slotMode", this->SlotMode }, { "perspective", this->Perspective },
      { "radius", this->Radius }, { "bilinear", this->Bilinear }, { "areaMode", this->AreaMode },
      { "lightKind", this->LightKind }, { "lightOff", this->LightOff },
      { "anyCaster", this->AnyCaster } };
  }

  std::string Key() const
  {
    std::string key;
    for (const auto& c : this->Constants())
    {
      key += std::to_string(c.second) + ",";
    }
    return key;
  }

  // The composed source with each of these uniforms declared as a constant instead (the
  // ones a program does not declare are left out).
  std::string Specialize(std::string source) const
  {
    for (const auto& c : this->Constants())
    {
      vtkShaderProgram::Substitute(source, std::string("uniform int ") + c.first + ";",
        std::string("const int ") + c.first + " = " + std::to_string(c.second) + ";", false);
    }
    return source;
  }
};

// Lookup programs by variant, compiled on first use and kept with the technique.
class VariantPrograms
{
public:
  vtkOpenGLQuadHelper* Get(
    vtkOpenGLRenderWindow* win, const char* vs, const std::string& fs, const LookupVariant& variant)
  {
    std::unique_ptr<vtkOpenGLQuadHelper>& quad = this->Quads[variant.Key()];
    if (!quad)
    {
      quad.reset(new vtkOpenGLQuadHelper(win, vs, variant.Specialize(fs).c_str(), ""));
    }
    return quad.get();
  }
  void ReleaseGraphicsResources(vtkWindow* win)
  {
    for (auto& quad : this->Quads)
    {
      quad.second->ReleaseGraphicsResources(win);
    }
  }
  void Reset() { this->Quads.clear(); }

private:
  std::map<std::string, std::unique_ptr<vtkOpenGLQuadHelper>> Quads;
};

// Receivers and their extent (vtkPenumbraShadowMapFit.cxx).
void LightAxes(const LightSetup& setup, double axes[3][3]);
int SlotOf(const LightSetup& setup, int slotMode, const double p[3]);
void AddReceiver(const LightSetup& setup, const double axes[3][3], int slotMode, const double p[3],
  ReceiverExtent& e);
void SamplePoint(const penumbra_light_views::FrameInputs& in, vtkIdType s, double p[3]);
void ExtentFromTiles(
  const LightSetup& setup, const TileOutputs& data, int tiles, ReceiverExtent& e);
void ExtentFromScene(const LightSetup& setup, int slotMode, vtkPenumbraSceneGeometry* geometry,
  SceneChunks& chunks, ReceiverExtent& e);
int TileCount(int width, int height);
TileOutputs TilesFromSamples(const penumbra_light_views::FrameInputs& in, int width, int height);
std::vector<float> EstimateSamples(const penumbra_light_views::FrameInputs& in, int width,
  int height, const unsigned char* state, const View& view, int step);
bool SceneInView(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry);
void ShareExtent(vtkPenumbraRemoteShadows& processes, ReceiverExtent& e);

// Shader sources (vtkPenumbraShadowMapLookup.cxx).
std::string ComposeShader(const char* source);
}

// The files of the technique use these names as the one file they came from did.
using namespace penumbra_shadow_maps;

struct vtkPenumbraShadowMapShadows::Internals
{
  // Half width of the PCF kernel (0 without PCF): the taps of the box filter.
  static int TapRadius(vtkPenumbraShadowMapShadows* self)
  {
    return self->Filter == FILTER_PCF ? (self->PCFKernel | 1) / 2 : 0;
  }
  // Texels the filter reaches from the sample's texel, for the slope bias: Fast PCF's
  // 2 x 2 taps reach one texel.
  static int BiasRadius(vtkPenumbraShadowMapShadows* self)
  {
    return self->Filter == FILTER_BILINEAR ? 1 : TapRadius(self);
  }

  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  penumbra_casters::CasterBuffers Casters;
  vtkSmartPointer<vtkOpenGLFramebufferObject> FBO;
  vtkSmartPointer<vtkTextureObject> DepthTextures[2]; // first layer, second (midpoint) layer
  int MapSize[2] = { 0, 0 };

  // Paraboloid casters: per hemisphere, clipped and tessellated, relative to the light
  // (3 floats position + 4 floats plane per vertex).
  GLuint ParaboloidArray = 0;
  GLuint ParaboloidBuffers[2] = { 0, 0 };
  GLsizei ParaboloidCounts[2] = { 0, 0 };
  std::vector<double> ParaboloidKey;

  std::vector<LightMaps> Cache;
  SceneChunks Chunks; // the scene fit's vertex runs (ExtentFromScene)
  std::vector<unsigned char> State;
  std::vector<float> SecondLayer;
  std::vector<float> Composited; // a distributed frame's slot layers (CompositeSlot())
  // GPU lookup staging (pending-sample list, its positions, normals and answers), kept between
  // frames: allocated afresh they cost more in page faults than the lookup itself.
  std::vector<vtkIdType> List;
  std::vector<float> ListPositionData, ListNormalData, ListResult;

  // GPU lookup: the compacted pending samples, their visibility, and the programs.
  vtkSmartPointer<vtkOpenGLFramebufferObject> LookupFBO;
  vtkSmartPointer<vtkTextureObject> ListPositions, ListNormals, ListVisibility;
  VariantPrograms LookupPrograms;
  std::unique_ptr<vtkOpenGLQuadHelper> MidpointQuad;

  // GPU-resident frames: the receiver-extent reduction (tile results and their read-back)
  // and the G-buffer lookup with its stand-in map.
  std::unique_ptr<vtkOpenGLQuadHelper> ExtentQuad;
  VariantPrograms FramePrograms;
  vtkSmartPointer<vtkOpenGLFramebufferObject> ExtentFBO;
  vtkSmartPointer<vtkTextureObject> ExtentTextures[4];
  std::vector<TileOutputs> ExtentData; // per layer: the point-light reduction's outputs
  // Per-view tile boxes for directional and spot lights, and the view they belong to.
  std::unique_ptr<vtkOpenGLQuadHelper> TilesQuad;
  // RESM: the per-light resolution estimate over the G-buffer (tile needs and read-back).
  std::unique_ptr<vtkOpenGLQuadHelper> EstimateQuad;
  std::vector<TileOutputs> EstimateData;
  std::vector<TileOutputs> TileData;
  std::vector<double> TileKey;
  vtkSmartPointer<vtkTextureObject> NoMap;
  GLuint RawDepthSampler = 0; // soft lookups: read the compare-mode maps as raw depth
  // The soft lookups' adaptive sampling: the block corners' values.
  vtkSmartPointer<vtkOpenGLFramebufferObject> CoarseFBO;
  vtkSmartPointer<vtkTextureObject> CoarseValues;
  static constexpr int ExtentTile = Tile;

  // Phases (see the definitions).
  bool UpdateCasters(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    vtkPenumbraSceneGeometry* geometry);
  int SlotMode(vtkPenumbraShadowMapShadows* self, const LightSetup& setup);
  static int SoftMode(vtkPenumbraShadowMapShadows* self, const LightMaps& m);
  LookupVariant Variant(vtkPenumbraShadowMapShadows* self, const LightSetup& setup, bool anyCaster,
    const LightMaps* maps);
  std::vector<double> MapKey(vtkPenumbraShadowMapShadows* self, vtkRenderer* renderer,
    vtkLight* light, vtkPenumbraSceneGeometry* geometry, bool fitsScene, const double shift[3],
    double samples, double pending);
  // Whether the maps are fitted to the scene (SetFitTo()), not to the view.
  // In a distributed frame (`processes`), the whole scene is in view when every process's
  // piece is.
  static bool FitsScene(vtkPenumbraShadowMapShadows* self, vtkRenderer* renderer,
    vtkPenumbraSceneGeometry* geometry, vtkPenumbraRemoteShadows* processes)
  {
    if (self->ResolutionMode != RESOLUTION_FIXED || self->FitTo == FIT_TO_VIEW)
    {
      return false;
    }
    if (self->FitTo == FIT_TO_SCENE)
    {
      return true;
    }
    const bool inView = SceneInView(renderer, geometry);
    return processes ? processes->AllAgree(inView) : inView;
  }
  // A light's maps brought up to date: rebuilt when their key changed (on any process of a
  // distributed frame), fitted to the extent `receivers` fills (or the scene's), sized by
  // `estimate`, drawn, and composited across the processes.
  using ExtentFiller = std::function<bool(ReceiverExtent&, std::string&)>;
  bool UpdateMaps(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    vtkPenumbraSceneGeometry* geometry, vtkPenumbraRemoteShadows* processes,
    const LightSetup& setup, bool fitsScene, std::vector<double>& key,
    const ExtentFiller& receivers,
    const std::function<bool(const View&, std::vector<float>&, std::string&)>& estimate,
    LightMaps* maps, std::string& error);
  void CompositeSlot(vtkPenumbraShadowMapShadows* self, vtkPenumbraRemoteShadows* processes,
    vtkTextureObject* slotTexture, LightMaps* maps, int slot);
  // The CPU lookup's distributed frame (ComputeFrame() sets it around the per-light path).
  vtkPenumbraRemoteShadows* Processes = nullptr;
  void FitViews(
    const LightSetup& setup, const ReceiverExtent& e, int slotMode, int size, LightMaps* maps);
  using Estimator = std::function<bool(const View&, std::vector<float>&, std::string&)>;
  bool PlanMaps(vtkPenumbraShadowMapShadows* self, const LightSetup& setup,
    const ReceiverExtent& extent, const Estimator& estimate, LightMaps* maps, int size[2],
    std::string& error);
  bool RenderMaps(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    vtkPenumbraSceneGeometry* geometry, vtkPenumbraRemoteShadows* processes,
    const LightSetup& setup, const ReceiverExtent& extent, const int size[2], LightMaps* maps,
    std::string& error);
  vtkShaderProgram* MapProgram(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    const LightSetup& setup, bool paraboloid);
  void BindCasters(vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program,
    vtkPenumbraSceneGeometry* geometry, const LightSetup& setup, const LightMaps& maps);
  GLsizei BindSlot(vtkShaderProgram* program, const LightMaps& maps, int slot);
  vtkTextureObject* SlotTexture(
    vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, LightMaps* maps, int slot);
  void DrawSlotLayers(vtkPenumbraShadowMapShadows* self, vtkOpenGLState* ostate,
    vtkShaderProgram* program, GLsizei count, vtkTextureObject* slotTexture, LightMaps* maps,
    int slot);
  void ResolveMidpoint(vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win,
    vtkShaderProgram* program, vtkTextureObject* slotTexture, LightMaps* maps, int slot);
  bool EstimateFrame(vtkPenumbraFrame* frame, const LightSetup& setup, const View& view, int step,
    std::vector<float>& needs, std::string& error);
  void SetCompareUniforms(vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program,
    const LightSetup& setup, const LightMaps& m, const std::string& suffix = "");
  std::shared_ptr<vtkPenumbraFrame::ShaderLookup> ShaderLookup(
    vtkPenumbraShadowMapShadows* self, const LightSetup& setup, const LightMaps& maps);
  void SetSoftUniforms(
    vtkPenumbraShadowMapShadows* self, vtkShaderProgram* program, const LightMaps& m);
  static void SetAreaUniforms(vtkShaderProgram* program, const LightSetup& setup);
  void DrawLookup(vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int layer,
    const LightSetup& setup, const LightMaps* maps, const std::vector<int>& slots,
    vtkOpenGLQuadHelper* quad, int adaptivePass, int block);
  bool LookupList(vtkPenumbraShadowMapShadows* self, const penumbra_light_views::FrameInputs& in,
    const LightSetup& setup, const LightMaps& m, const unsigned char* state, float* vis,
    std::string& error);
  void LookupCPU(vtkPenumbraShadowMapShadows* self, const penumbra_light_views::FrameInputs& in,
    const LightSetup& setup, const LightMaps& m, const unsigned char* state, float* vis);
  bool FrameLight(
    vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int k, std::string& error);
  bool ReduceExtent(vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame,
    const LightSetup& setup, ReceiverExtent& extent, std::string& error);
  bool TilePass(vtkPenumbraFrame* frame, vtkOpenGLQuadHelper& quad,
    const std::function<void(vtkShaderProgram*)>& uniforms, std::vector<TileOutputs>& data);
  bool LookupFrame(vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int k,
    const LightSetup& setup, bool anyCaster, const LightMaps* maps, std::string& error);

  static vtkSmartPointer<vtkTextureObject> FloatTexture(vtkOpenGLRenderWindow* win)
  {
    auto tex = vtkSmartPointer<vtkTextureObject>::New();
    tex->SetContext(win);
    tex->SetMinificationFilter(vtkTextureObject::Nearest);
    tex->SetMagnificationFilter(vtkTextureObject::Nearest);
    tex->SetWrapS(vtkTextureObject::ClampToEdge);
    tex->SetWrapT(vtkTextureObject::ClampToEdge);
    return tex;
  }

  // A depth texture the lookup samples with the hardware compare.
  static vtkSmartPointer<vtkTextureObject> CompareTexture(
    vtkOpenGLRenderWindow* win, int width, int height)
  {
    auto tex = FloatTexture(win);
    tex->SetDepthTextureCompare(true);
    tex->SetDepthTextureCompareFunction(vtkTextureObject::Lequal);
    tex->AllocateDepth(width, height, vtkTextureObject::Float32);
    return tex;
  }

  void Release(vtkWindow* window)
  {
    if (this->Window && (!window || window == this->Window))
    {
      this->Window->MakeCurrent();
      this->Casters.Release();
      if (this->ParaboloidArray)
      {
        glDeleteVertexArrays(1, &this->ParaboloidArray);
        glDeleteBuffers(2, this->ParaboloidBuffers);
      }
      for (auto& tex : this->DepthTextures)
      {
        if (tex)
        {
          tex->ReleaseGraphicsResources(this->Window);
        }
      }
      if (this->FBO)
      {
        this->FBO->ReleaseGraphicsResources(this->Window);
      }
      for (auto& entry : this->Cache)
      {
        for (auto& tex : entry.Textures)
        {
          if (tex)
          {
            tex->ReleaseGraphicsResources(this->Window);
          }
        }
      }
      for (vtkTextureObject* tex :
        { this->ListPositions.Get(), this->ListNormals.Get(), this->ListVisibility.Get() })
      {
        if (tex)
        {
          tex->ReleaseGraphicsResources(this->Window);
        }
      }
      if (this->LookupFBO)
      {
        this->LookupFBO->ReleaseGraphicsResources(this->Window);
      }
      for (vtkTextureObject* tex : { this->ExtentTextures[0].Get(), this->ExtentTextures[1].Get(),
             this->ExtentTextures[2].Get(), this->ExtentTextures[3].Get(), this->NoMap.Get() })
      {
        if (tex)
        {
          tex->ReleaseGraphicsResources(this->Window);
        }
      }
      if (this->ExtentFBO)
      {
        this->ExtentFBO->ReleaseGraphicsResources(this->Window);
      }
      this->LookupPrograms.ReleaseGraphicsResources(this->Window);
      this->FramePrograms.ReleaseGraphicsResources(this->Window);
      for (auto* quad : { this->MidpointQuad.get(), this->ExtentQuad.get(), this->TilesQuad.get(),
             this->EstimateQuad.get() })
      {
        if (quad)
        {
          quad->ReleaseGraphicsResources(this->Window);
        }
      }
    }
    if (this->RawDepthSampler && this->Window)
    {
      glDeleteSamplers(1, &this->RawDepthSampler);
    }
    this->RawDepthSampler = 0;
    this->LookupFBO = nullptr;
    this->ListPositions = this->ListNormals = this->ListVisibility = nullptr;
    this->LookupPrograms.Reset();
    this->MidpointQuad.reset();
    this->ExtentQuad.reset();
    this->FramePrograms.Reset();
    this->TilesQuad.reset();
    this->EstimateQuad.reset();
    this->TileKey.clear();
    this->ExtentFBO = nullptr;
    this->NoMap = nullptr;
    for (auto& tex : this->ExtentTextures)
    {
      tex = nullptr;
    }
    this->Casters.Forget();
    this->ParaboloidArray = 0;
    this->ParaboloidBuffers[0] = this->ParaboloidBuffers[1] = 0;
    this->ParaboloidKey.clear();
    this->FBO = nullptr;
    for (auto& tex : this->DepthTextures)
    {
      tex = nullptr;
    }
    this->MapSize[0] = this->MapSize[1] = 0;
    this->Window = nullptr;
    // Cached maps were fitted to this window's samples (and their textures are gone).
    this->Cache.clear();
  }

  void AllocateMaps(vtkOpenGLRenderWindow* win, int width, int height)
  {
    if (this->FBO && this->MapSize[0] == width && this->MapSize[1] == height)
    {
      return;
    }
    this->FBO = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    this->FBO->SetContext(win);
    for (auto& tex : this->DepthTextures)
    {
      tex = vtkSmartPointer<vtkTextureObject>::New();
      tex->SetContext(win);
      tex->SetMinificationFilter(vtkTextureObject::Nearest);
      tex->SetMagnificationFilter(vtkTextureObject::Nearest);
      tex->SetWrapS(vtkTextureObject::ClampToEdge);
      tex->SetWrapT(vtkTextureObject::ClampToEdge);
      tex->AllocateDepth(width, height, vtkTextureObject::Float32);
    }
    this->MapSize[0] = width;
    this->MapSize[1] = height;
  }

  void BuildParaboloidCasters(const double centre[3]);
};

#endif
