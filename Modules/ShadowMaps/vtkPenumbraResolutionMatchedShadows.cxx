// vtkPenumbraResolutionMatchedShadows (Lefohn et al. 2007): the technique's entry points,
// the per-light driver of a frame, its GPU resources and the virtual map's fit; the pages are
// in vtkPenumbraResolutionMatchedPages.cxx, vtkPenumbraResolutionMatchedRender.cxx and
// vtkPenumbraResolutionMatchedLookup.cxx.
#include "vtkPenumbraResolutionMatchedShadowsInternals.h"

#include "vtkObjectFactory.h"
#include "vtkPenumbraResolutionMatchedFS.h"
#include "vtkPenumbraShadowMapClassify.h"
#include "vtkPenumbraStatistics.h"

vtkStandardNewMacro(vtkPenumbraResolutionMatchedShadows);

namespace
{
// No sample requests a level coarser than 1024^2: a sample needing less (far away, or a small
// frame) still gets 1024^2 texels, so that occluders thinner than a coarse texel do not vanish
// from the map (the edge refinement cannot find what the map does not show). Only the pages
// samples request are rendered, not the whole level.
constexpr int MinRequestLevel = 10;
constexpr double MaxSpotCone = 60.0; // one perspective view (shadowmap's single-view rule)
}

namespace penumbra_rmsm
{
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
}

namespace
{
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
  key.push_back(static_cast<double>(geometry->GetCastersTime()));
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
  os << indent << "Filter: " << this->Filter << "\n";
  os << indent << "Footprint: " << this->Footprint << "\n";
  os << indent << "LODBias: " << this->LODBias << "\n";
  os << indent << "AnalysisStep: " << this->AnalysisStep << "\n";
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

//------------------------------------------------------------------------------
void vtkPenumbraResolutionMatchedShadows::GetStatistics(
  vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  stats->Set("requested_pages", this->NumberOfRequestedPages);
  stats->Set("coarsest_level", this->RequestedLevels[0]);
  stats->Set("finest_level", this->RequestedLevels[1]);
  stats->Set("refined_pages", this->NumberOfRefinedPages);
  stats->Set("rendered_pages", this->NumberOfRenderedPages);
  stats->Set("superpages", this->NumberOfSuperpages);
  stats->Set("resident_pages", this->NumberOfResidentPages);
  stats->Set("coarser_share", this->CoarserShare);
  stats->Set("request_ms", this->RequestTimeMs);
  stats->Set("page_ms", this->PageTimeMs);
  stats->Set("lookup_ms", this->LookupTimeMs);
}
