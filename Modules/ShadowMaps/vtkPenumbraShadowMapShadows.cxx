// vtkPenumbraShadowMapShadows: the technique's entry points, the per-light driver of a
// frame and the maps' cache key; the phases are in vtkPenumbraShadowMapFit.cxx,
// vtkPenumbraShadowMapRender.cxx and vtkPenumbraShadowMapLookup.cxx.
#include "vtkPenumbraShadowMapShadowsInternals.h"

#include "vtkObjectFactory.h"
#include "vtkPenumbraStatistics.h"

vtkStandardNewMacro(vtkPenumbraShadowMapShadows);

namespace
{
// PCSS: an area or linear light's map is a spot light's at its centre along its normal, with
// a cone just under 90 degrees (the widest a single perspective map fits).
constexpr double AreaConeDegrees = 89.0;

int CountViews(const LightMaps& maps)
{
  int views = 0;
  for (size_t slot = 0; slot < maps.Maps.size(); ++slot)
  {
    views += maps.Maps[slot].empty() && !maps.Textures[slot] ? 0 : 1;
  }
  return views;
}

bool AreaAsSpot(vtkPenumbraAreaLight* area, LightSetup& setup, std::string& error)
{
  const std::string problem = area->GetValidityMessage();
  double u[3], v[3], n[3];
  if (!problem.empty() || !area->GetAxes(u, v, n))
  {
    error = "invalid area light: " + problem;
    return false;
  }
  setup.Type = LightSetup::Kind::Spot;
  setup.Area = true;
  // The blocker search and the filter integrate over a rectangle: a disc is taken as the
  // square of its area (side sqrt(pi) / 2 times its diameter), whose mean penumbra is the
  // disc's.
  const bool disc = area->GetShape() == vtkPenumbraAreaLight::Disc;
  const double scale = disc ? 0.5 * std::sqrt(vtkMath::Pi()) : 1.0;
  for (int c = 0; c < 3; ++c)
  {
    setup.HalfU[c] = 0.5 * scale * area->GetWidth() * u[c];
    setup.HalfV[c] = 0.5 * scale * area->GetExtentV() * v[c];
  }
  std::copy(n, n + 3, setup.Axis);
  setup.Cone = AreaConeDegrees;
  setup.CosCone = std::cos(vtkMath::RadiansFromDegrees(AreaConeDegrees));
  return true;
}
}
//------------------------------------------------------------------------------
vtkPenumbraShadowMapShadows::vtkPenumbraShadowMapShadows()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraShadowMapShadows::~vtkPenumbraShadowMapShadows()
{
  this->Impl->Release(nullptr);
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::ParaboloidFromDirection(const double d[3], double xy[2])
{
  const int hemisphere = d[2] >= 0.0 ? 0 : 1;
  const double denominator = 1.0 + std::fabs(d[2]);
  xy[0] = d[0] / denominator;
  xy[1] = d[1] / denominator;
  return hemisphere;
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::DirectionFromParaboloid(
  const double xy[2], int hemisphere, double d[3])
{
  const double r2 = xy[0] * xy[0] + xy[1] * xy[1];
  d[0] = 2.0 * xy[0] / (1.0 + r2);
  d[1] = 2.0 * xy[1] / (1.0 + r2);
  d[2] = (1.0 - r2) / (1.0 + r2) * (hemisphere ? -1.0 : 1.0);
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  this->NumberOfViews = 0;
  this->MapTimeMs = this->LookupTimeMs = 0.0;

  // ---- Input checks: nothing is written before they pass.
  penumbra_light_views::FrameInputs in;
  {
    std::string inputError;
    if (!in.Read(renderer, geometry, samples, light, visibility, inputError))
    {
      PENUMBRA_FAIL("shadow maps: " << inputError);
    }
  }
  const LightSetup& setup = in.Light;
  const vtkIdType n = in.NumberOfSamples;
  // A distributed frame (ComputeFrame()): some process's casters, and the maps all of them
  // composite, whatever this process's samples.
  vtkPenumbraRemoteShadows* processes = impl.Processes;
  bool anyCaster = !setup.Off && impl.UpdateCasters(this, in.Window, geometry);
  anyCaster = processes ? processes->AnyProcess(anyCaster) : anyCaster;

  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  float* vis = n ? visibility->GetPointer(0) : nullptr;
  impl.State.resize(static_cast<size_t>(n));
  unsigned char* state = impl.State.data();
  const penumbra_light_views::FacingCounts facing = penumbra_light_views::ClassifyFacing(setup, n,
    in.Positions, in.Normals, in.Props, in.Shift, anyCaster, vis, state, Pending, Decided);
  if (facing.Pending == 0 && !(processes && anyCaster))
  {
    visibility->Modified();
    this->LastTimeMs = ElapsedMs(start);
    return 1;
  }

  // ---- The maps: kept while everything they depend on is unchanged (see MapKey()).
  const int slotMode = impl.SlotMode(this, setup);
  const bool fitsScene = Internals::FitsScene(this, renderer, geometry, processes);
  std::vector<double> key = impl.MapKey(this, renderer, light, geometry, fitsScene, in.Shift,
    static_cast<double>(n), static_cast<double>(facing.Pending));
  LightMaps* maps = &penumbra_light_views::LightCacheEntry(impl.Cache, light);
  auto receivers = [&](ReceiverExtent& extent, std::string&)
  {
    if (slotMode == SlotsOne)
    {
      // The same tile boxes the GPU frame path fits to, so both lookups use the same maps.
      ExtentFromTiles(setup, TilesFromSamples(in, samples->GetWidth(), samples->GetHeight()),
        TileCount(samples->GetWidth(), samples->GetHeight()), extent);
      return true;
    }
    double axes[3][3];
    LightAxes(setup, axes);
    for (vtkIdType s = 0; s < n; ++s)
    {
      if (state[s] == Pending)
      {
        double p[3];
        SamplePoint(in, s, p);
        AddReceiver(setup, axes, slotMode, p, extent);
      }
    }
    return true;
  };
  const int width = samples->GetWidth(), height = samples->GetHeight();
  auto estimate = [&](const View& view, std::vector<float>& needs, std::string&)
  {
    needs = EstimateSamples(in, width, height, state, view, this->AnalysisStep);
    return true;
  };
  {
    std::string error;
    if (!impl.UpdateMaps(this, in.Window, geometry, processes, setup, fitsScene, key, receivers,
          estimate, maps, error))
    {
      PENUMBRA_FAIL("shadow maps: " << error);
    }
  }
  if (facing.Pending == 0)
  {
    visibility->Modified();
    this->LastTimeMs = ElapsedMs(start);
    return 1;
  }
  this->LastMapSize[0] = maps->Width;
  this->LastMapSize[1] = maps->Height;
  this->NumberOfViews = CountViews(*maps);

  const auto lookupStart = Clock::now();
  if (this->Lookup != LOOKUP_CPU)
  {
    std::string error;
    if (!impl.LookupList(this, in, setup, *maps, state, vis, error))
    {
      PENUMBRA_FAIL("shadow maps: " << error);
    }
  }
  else
  {
    impl.LookupCPU(this, in, setup, *maps, state, vis);
  }
  this->LookupTimeMs = ElapsedMs(lookupStart);
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::ComputeFrame(vtkPenumbraFrame* frame)
{
  if (this->Lookup == LOOKUP_CPU)
  {
    // The maps are compared on the CPU, light by light through ComputeVisibility().
    this->Impl->Processes = frame->GetProcesses();
    const int done = this->Superclass::ComputeFrame(frame);
    this->Impl->Processes = nullptr;
    return done;
  }
  return this->ComputeFrameLights(frame, "shadow maps",
    [this, frame](int k, std::string& error)
    { return this->Impl->FrameLight(this, frame, k, error); });
}

//------------------------------------------------------------------------------
bool vtkPenumbraShadowMapShadows::Internals::UpdateCasters(
  vtkPenumbraShadowMapShadows* self, vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry)
{
  win->MakeCurrent();
  if (this->Window && this->Window != win)
  {
    this->Release(nullptr);
  }
  this->Window = win;
  if (this->Casters.Update(geometry))
  {
    ++self->NumberOfUploads;
  }
  return this->Casters.VertexCount > 0;
}

//------------------------------------------------------------------------------
// The light's maps, rebuilt when their key changed. In a distributed frame (`processes`)
// every process rebuilds when any must, fits to the extent of all the processes' receivers
// (or of the whole scene) and sizes the maps by all their estimates, so that the texels
// agree; each draws its own casters and RenderMaps() composites them.
bool vtkPenumbraShadowMapShadows::Internals::UpdateMaps(vtkPenumbraShadowMapShadows* self,
  vtkOpenGLRenderWindow* win, vtkPenumbraSceneGeometry* geometry,
  vtkPenumbraRemoteShadows* processes, const LightSetup& setup, bool fitsScene,
  std::vector<double>& key, const ExtentFiller& receivers,
  const std::function<bool(const View&, std::vector<float>&, std::string&)>& estimate,
  LightMaps* maps, std::string& error)
{
  const bool rebuild = !maps->Valid || maps->Key != key;
  if (!(processes ? processes->AnyProcess(rebuild) : rebuild))
  {
    return true;
  }
  ReceiverExtent extent;
  extent.CollectPlane = self->FitRectangle != FIT_AXIS;
  extent.Square = self->FitRectangle == FIT_SQUARE;
  bool ok = true;
  if (fitsScene)
  {
    ExtentFromScene(setup, this->SlotMode(self, setup), geometry, this->Chunks, extent);
  }
  else
  {
    ok = receivers(extent, error);
  }
  if (processes)
  {
    if (!processes->AllAgree(ok))
    {
      error = ok ? "another process could not fit this light's maps" : error;
      maps->Valid = false;
      return false;
    }
    ShareExtent(*processes, extent);
    if (self->ResolutionMode == RESOLUTION_ESTIMATED)
    {
      // RESM keeps its current size within a margin of the need: only where every process
      // has the same one (else each would choose by its own).
      const double w = maps->Valid ? maps->Width : 0.0, h = maps->Valid ? maps->Height : 0.0;
      double sizes[4] = { w, h, -w, -h };
      processes->ReduceMinimum(sizes, 4);
      maps->Valid = maps->Valid && sizes[0] == -sizes[2] && sizes[1] == -sizes[3];
    }
  }
  else if (!ok)
  {
    return false;
  }
  maps->Key.swap(key);
  auto shared = [&](const View& view, std::vector<float>& needs, std::string& why)
  {
    bool done = estimate(view, needs, why);
    if (!processes)
    {
      return done;
    }
    // RESM's quantile is taken over every process's needs.
    std::vector<double> all(needs.begin(), needs.end());
    processes->GatherValues(all);
    done = processes->AllAgree(done);
    needs.clear();
    for (double v : all)
    {
      needs.push_back(static_cast<float>(v));
    }
    return done;
  };
  int size[2];
  return this->PlanMaps(self, setup, extent, shared, maps, size, error) &&
    this->RenderMaps(self, win, geometry, processes, setup, extent, size, maps, error);
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowMapShadows::Internals::SlotMode(
  vtkPenumbraShadowMapShadows* self, const LightSetup& setup)
{
  if (setup.Type != LightSetup::Kind::Point)
  {
    return SlotsOne;
  }
  return self->PointMode == POINT_CUBE ? SlotsCube : SlotsParaboloid;
}

//------------------------------------------------------------------------------
// The soft lookup of a light's maps: AREA_NONE for hard lights, else the area light mode.
int vtkPenumbraShadowMapShadows::Internals::SoftMode(
  vtkPenumbraShadowMapShadows* self, const LightMaps& m)
{
  return vtkPenumbraAreaLight::SafeDownCast(m.Light.Get()) ? self->AreaLightMode : AREA_NONE;
}

//------------------------------------------------------------------------------
// Everything the maps depend on, by value (a spurious Modified() on the camera or light does
// not force a re-render; a real change always does): the light, the casters, the frames,
// the view the receivers are fitted to, the window size and the settings.
std::vector<double> vtkPenumbraShadowMapShadows::Internals::MapKey(
  vtkPenumbraShadowMapShadows* self, vtkRenderer* renderer, vtkLight* light,
  vtkPenumbraSceneGeometry* geometry, bool fitsScene, const double shift[3], double samples,
  double pending)
{
  std::vector<double> key;
  double lp[3], lf[3];
  light->GetTransformedPosition(lp);
  light->GetTransformedFocalPoint(lf);
  key.insert(key.end(), lp, lp + 3);
  key.insert(key.end(), lf, lf + 3);
  key.push_back(light->GetPositional());
  key.push_back(light->GetConeAngle());
  key.push_back(static_cast<double>(geometry->GetCastersTime()));
  key.push_back(static_cast<double>(self->GetMTime()));
  if (fitsScene)
  {
    return key; // nothing of the view
  }
  key.insert(key.end(), shift, shift + 3);
  key.push_back(samples);
  key.push_back(pending);
  if (vtkCamera* camera = renderer->GetActiveCamera())
  {
    key.insert(key.end(), camera->GetPosition(), camera->GetPosition() + 3);
    key.insert(key.end(), camera->GetFocalPoint(), camera->GetFocalPoint() + 3);
    key.insert(key.end(), camera->GetViewUp(), camera->GetViewUp() + 3);
    key.push_back(camera->GetViewAngle());
    key.push_back(camera->GetParallelProjection());
    key.push_back(camera->GetParallelScale());
    key.insert(key.end(), camera->GetClippingRange(), camera->GetClippingRange() + 2);
  }
  const int* size = renderer->GetSize();
  key.push_back(size[0]);
  key.push_back(size[1]);
  return key;
}

//------------------------------------------------------------------------------
// One light of a GPU-resident frame: the maps are fitted to the G-buffer's receivers on the
// GPU (a tile reduction, read back as a few kilobytes) when they must be rebuilt, and looked
// up straight from the G-buffer into the light's visibility channel. No sample is read back.
bool vtkPenumbraShadowMapShadows::Internals::FrameLight(
  vtkPenumbraShadowMapShadows* self, vtkPenumbraFrame* frame, int k, std::string& error)
{
  const auto start = Clock::now();
  self->NumberOfViews = 0;
  self->MapTimeMs = self->LookupTimeMs = 0.0;
  vtkLight* light = frame->GetShadowedLight(k);
  vtkPenumbraSceneGeometry* geometry = frame->GetGeometry();
  vtkOpenGLRenderWindow* win = frame->GetWindow();
  if (!light || !geometry || !win)
  {
    error = "the frame has no light, geometry or OpenGL window";
    return false;
  }
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  if (area && self->AreaLightMode == AREA_NONE)
  {
    error = "area and linear lights need a soft-shadow technique (gears, raytraced, pcss, "
            "single-sample-soft)";
    return false;
  }
  double origin[3];
  geometry->GetOrigin(origin);
  LightSetup setup;
  if (!setup.Read(light, origin, error) || (area && !AreaAsSpot(area, setup, error)))
  {
    return false;
  }
  // A distributed frame: some process's casters, and the maps all of them composite.
  vtkPenumbraRemoteShadows* processes = frame->GetProcesses();
  bool anyCaster = !setup.Off && this->UpdateCasters(self, win, geometry);
  anyCaster = processes ? processes->AnyProcess(anyCaster) : anyCaster;
  win->MakeCurrent();
  LightMaps* maps = nullptr;
  if (anyCaster)
  {
    const double noShift[3] = { 0, 0, 0 };
    const double samples = static_cast<double>(frame->GetWidth()) * frame->GetHeight();
    const bool fitsScene = FitsScene(self, frame->GetRenderer(), geometry, processes);
    std::vector<double> key = this->MapKey(self, frame->GetRenderer(), light, geometry, fitsScene,
      noShift, -samples, frame->GetNumberOfLayers());
    maps = &penumbra_light_views::LightCacheEntry(this->Cache, light);
    auto receivers = [&](ReceiverExtent& extent, std::string& why)
    { return this->ReduceExtent(self, frame, setup, extent, why); };
    auto estimate = [&](const View& view, std::vector<float>& needs, std::string& why)
    { return this->EstimateFrame(frame, setup, view, self->AnalysisStep, needs, why); };
    if (!this->UpdateMaps(
          self, win, geometry, processes, setup, fitsScene, key, receivers, estimate, maps, error))
    {
      return false;
    }
    self->LastMapSize[0] = maps->Width;
    self->LastMapSize[1] = maps->Height;
    self->NumberOfViews = CountViews(*maps);
  }
  const auto lookupStart = Clock::now();
  bool ok = true;
  if (self->Lookup == LOOKUP_GPU && maps && CountViews(*maps) == 1 && !maps->Textures.empty() &&
    maps->Textures[0] && SoftMode(self, *maps) == AREA_NONE &&
    !vtkPenumbraGoniometricLight::SafeDownCast(light))
  {
    frame->SetShaderLookup(k, this->ShaderLookup(self, setup, *maps));
  }
  else
  {
    ok = this->LookupFrame(self, frame, k, setup, anyCaster, maps, error);
  }
  self->LookupTimeMs = ElapsedMs(lookupStart);
  self->LastTimeMs = ElapsedMs(start);
  return ok;
}

//------------------------------------------------------------------------------
bool vtkPenumbraShadowMapShadows::GetMapSize(vtkLight* light, int size[2], double need[2])
{
  for (const LightMaps& maps : this->Impl->Cache)
  {
    if (light && maps.Light == light && maps.Valid)
    {
      size[0] = maps.Width;
      size[1] = maps.Height;
      std::copy(maps.Need, maps.Need + 2, need);
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
bool vtkPenumbraShadowMapShadows::GetMapFootprint(vtkLight* light, double sides[2])
{
  for (const LightMaps& maps : this->Impl->Cache)
  {
    if (light && maps.Light == light && maps.Valid && maps.Views.size() == 1 &&
      !maps.Views[0].Perspective && !maps.Paraboloid)
    {
      // Orthographic rows: NDC x = Row[a] . p, so a side of 2 NDC units is 2 / |Row[a]|.
      for (int a = 0; a < 2; ++a)
      {
        sides[a] = 2.0 / Norm3(maps.Views[0].Row[a]);
      }
      return true;
    }
  }
  return false;
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FitTo: " << this->FitTo << "\n";
  os << indent << "Lookup: " << this->Lookup << "\n";
  os << indent << "AreaLightMode: " << this->AreaLightMode << "\n";
  os << indent << "SearchTaps: " << this->SearchTaps << "\n";
  os << indent << "FilterTaps: " << this->FilterTaps << "\n";
  os << indent << "SearchDepth: " << this->SearchDepth << "\n";
  os << indent << "MaxRadius: " << this->MaxRadius << "\n";
  os << indent << "AdaptiveBlock: " << this->AdaptiveBlock << "\n";
  os << indent << "Physical: " << this->Physical << "\n";
  os << indent << "RScale: " << this->RScale << "\n";
  os << indent << "RBias: " << this->RBias << "\n";
  os << indent << "RShrink: " << this->RShrink << "\n";
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "ResolutionMode: " << this->ResolutionMode << "\n";
  os << indent << "MaxResolution: " << this->MaxResolution << "\n";
  os << indent << "Coverage: " << this->Coverage << "\n";
  os << indent << "AnalysisStep: " << this->AnalysisStep << "\n";
  os << indent << "Filter: "
     << (this->Filter == FILTER_PCF           ? "pcf"
            : this->Filter == FILTER_BILINEAR ? "bilinear"
                                              : "none")
     << "\n";
  os << indent << "PCFKernel: " << this->PCFKernel << "\n";
  os << indent << "Bias: " << this->Bias << "\n";
  os << indent << "SlopeBias: " << this->SlopeBias << "\n";
  os << indent << "DepthMode: " << (this->DepthMode == DEPTH_MIDPOINT ? "midpoint" : "linear")
     << "\n";
  os << indent << "FitRectangle: "
     << (this->FitRectangle == FIT_SQUARE
            ? "square"
            : (this->FitRectangle == FIT_MINIMUM ? "minimum" : "axis"))
     << "\n";
  os << indent << "PointMode: " << (this->PointMode == POINT_PARABOLOID ? "paraboloid" : "cube")
     << "\n";
  os << indent << "NumberOfMapRenders: " << this->NumberOfMapRenders << "\n";
  os << indent << "NumberOfViews: " << this->NumberOfViews << "\n";
  os << indent << "NumberOfUploads: " << this->NumberOfUploads << "\n";
  os << indent << "MapTimeMs: " << this->MapTimeMs << "\n";
  os << indent << "LookupTimeMs: " << this->LookupTimeMs << "\n";
}

//------------------------------------------------------------------------------
const char* vtkPenumbraShadowMapShadows::GetTechniqueNameFor(vtkLight* light)
{
  return this->AreaLightMode != AREA_NONE && !vtkPenumbraAreaLight::SafeDownCast(light)
    ? "shadowmap"
    : this->GetTechniqueName();
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowMapShadows::GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  stats->Set("map_renders", this->NumberOfMapRenders);
  stats->Set("views", this->NumberOfViews);
  stats->Set("uploads", this->NumberOfUploads);
  stats->Set("map_ms", this->MapTimeMs);
  stats->Set("lookup_ms", this->LookupTimeMs);
  int size[2];
  double need[2];
  if (light && this->GetMapSize(light, size, need))
  {
    stats->Set("map_width", size[0]);
    stats->Set("map_height", size[1]);
    if (need[0] > 0.0 || need[1] > 0.0)
    {
      stats->Set("needed_width", need[0]);
      stats->Set("needed_height", need[1]);
    }
  }
}
