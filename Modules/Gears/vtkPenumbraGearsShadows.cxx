// vtkPenumbraGearsShadows (Wang et al. 2014): the technique's entry points and a call's
// set-up, path choice, classification and statistics; the steps are in
// vtkPenumbraGearsGrid.cxx, vtkPenumbraGearsMasks.cxx, vtkPenumbraGearsComputePath.cxx and
// vtkPenumbraGearsTraced.cxx.
#include "vtkPenumbraGearsShadowsInternals.h"

#include "vtkObjectFactory.h"
#include "vtkPenumbraStatistics.h"

vtkStandardNewMacro(vtkPenumbraGearsShadows);

//------------------------------------------------------------------------------
vtkPenumbraGearsShadows::vtkPenumbraGearsShadows()
  : Reference(vtkPenumbraReference::New())
  , Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraGearsShadows::~vtkPenumbraGearsShadows()
{
  this->Reference->Delete();
}

//------------------------------------------------------------------------------
vtkTypeUInt32Array* vtkPenumbraGearsShadows::GetMasks()
{
  return this->Impl->Masks;
}

//------------------------------------------------------------------------------
vtkUnsignedCharArray* vtkPenumbraGearsShadows::GetUncertainSamples()
{
  return this->Impl->Uncertain;
}

//------------------------------------------------------------------------------
double vtkPenumbraGearsShadows::GetUncertainFraction()
{
  return this->NumberOfValidSamples > 0
    ? static_cast<double>(this->NumberOfUncertainSamples + this->NumberOfTracedCellSamples +
        this->NumberOfSamplesWithTracedRays) /
      this->NumberOfValidSamples
    : 0.0;
}

//------------------------------------------------------------------------------
const char* vtkPenumbraGearsShadows::GetPathMessage()
{
  return this->Impl->PathMessage.c_str();
}

//------------------------------------------------------------------------------
void vtkPenumbraGearsShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Compute.Release(window);
}

//------------------------------------------------------------------------------
double vtkPenumbraGearsShadows::GetBlockingShare()
{
  return this->NumberOfAssignments > 0
    ? static_cast<double>(this->NumberOfNecessaryAssignments) / this->NumberOfAssignments
    : 0.0;
}

//------------------------------------------------------------------------------
// Wang et al. 2014, §3, for one area light: the input checks and light set-up, the sample
// classification, then per side of the light plane the grid (A.1-A.2), the triangle lists
// (A.3) and the masks (step 4), and last the reference for whatever stayed undecided.
int vtkPenumbraGearsShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  if (!geometry || !samples || !light || !visibility)
  {
    PENUMBRA_FAIL("needs scene geometry, view samples, a light and an output array");
  }
  this->Reference->SetGeometry(geometry);
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  this->LastLightWasArea = area != nullptr;
  if (!area)
  {
    // GEARS is an area-light algorithm; other lights get the exact one-ray answer.
    const int ok = this->Reference->ComputeVisibility(samples, light, visibility);
    this->LastTimeMs = ElapsedMs(start);
    return ok;
  }
  const std::string problem = area->GetValidityMessage();
  if (!problem.empty())
  {
    PENUMBRA_FAIL("invalid area light: " << problem);
  }
  Internals& impl = *this->Impl;
  CallState call;
  const std::string sampleProblem = impl.ReadSamples(samples, call);
  if (!sampleProblem.empty())
  {
    PENUMBRA_FAIL(sampleProblem);
  }
  impl.UpdateCasters(geometry, this->DenseCells == DENSE_TREE);
  if (!impl.SetUpLight(this, area, geometry, samples, call))
  {
    PENUMBRA_FAIL("unsupported light sampling: " << call.Light.K << " samples per axis");
  }
  impl.SetUpOutputs(this, visibility, call);
  impl.ChoosePath(this, renderer, call);
  impl.ClassifySamples(this, call);
  // ---- Per side of the light plane: grid, lists, masks.
  call.GridUsed = this->GridResolution;
  for (const int flip : { 1, -1 })
  {
    impl.ProcessSide(this, call, flip);
  }
  if (!impl.TraceUndecided(this, samples, visibility, call))
  {
    return 0;
  }
  impl.StoreStatistics(this, call);
  visibility->Modified();
  impl.Uncertain->Modified();
  impl.Masks->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
// Input check: the view samples' arrays (vtkPenumbraViewSamples::CheckArrays()); "" when
// they are usable, and then read into `call`.
std::string vtkPenumbraGearsShadows::Internals::ReadSamples(
  vtkPenumbraViewSamples* samples, CallState& call)
{
  const std::string problem = samples->CheckArrays();
  if (!problem.empty())
  {
    return problem;
  }
  const vtkIdType n = samples->GetNumberOfSamples();
  vtkFloatArray* posArray = samples->GetPositions();
  vtkFloatArray* nrmArray = samples->GetNormals();
  vtkIntArray* propArray = samples->GetPropIndices();
  vtkIdTypeArray* triArray = samples->GetTriangleIds();
  call.N = n;
  call.Pos = n ? posArray->GetPointer(0) : nullptr;
  call.Nrm = n ? nrmArray->GetPointer(0) : nullptr;
  call.Props = n ? propArray->GetPointer(0) : nullptr;
  call.Tris = n ? triArray->GetPointer(0) : nullptr;
  return std::string();
}

//------------------------------------------------------------------------------
// Light set-up: the light samples in the geometry's rebased frame (differences in double,
// as the reference takes them), the emitter's axes and extent, and the reference's
// constants. False if the light's sampling does not fit a mask row.
bool vtkPenumbraGearsShadows::Internals::SetUpLight(vtkPenumbraGearsShadows* self,
  vtkPenumbraAreaLight* area, vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples,
  CallState& call)
{
  double origin[3], samplesOrigin[3];
  geometry->GetOrigin(origin);
  samples->GetOrigin(samplesOrigin);
  vtkSmartPointer<vtkPenumbraAreaLight> used = area;
  if (self->SamplesPerAxis > 0 && self->SamplesPerAxis != area->GetSamplesPerAxis())
  {
    used = vtkSmartPointer<vtkPenumbraAreaLight>::Take(
      vtkPenumbraAreaLight::SafeDownCast(area->ShallowClone()));
    used->SetSamplesPerAxis(self->SamplesPerAxis);
  }
  call.Used = used;
  LightSamples& ls = call.Light;
  ls.K = used->GetSamplesPerAxis();
  const bool line = used->GetShape() == vtkPenumbraAreaLight::Line;
  ls.Rows = used->GetNumberOfRows();
  ls.Cells = ls.K * ls.Rows;
  ls.Count = used->GetNumberOfSamples();
  if (ls.K > MaxK)
  {
    return false;
  }
  // The masks run over the light's grid; the rows' emitting cells and the samples' numbering
  // come from the light (all cells but a disc's corners).
  int sampleIndex = 0;
  for (int j = 0; j < ls.Rows; ++j)
  {
    int first, last;
    used->GetRowCells(j, first, last);
    ls.Emitting[j] = first <= last ? Span(first, last) : 0;
    ls.RowFirst[j] = sampleIndex;
    sampleIndex += first <= last ? last - first + 1 : 0;
  }
  if (sampleIndex != ls.Count)
  {
    return false;
  }
  ls.Points.resize(3 * static_cast<size_t>(ls.Cells));
  for (int j = 0; j < ls.Rows; ++j)
  {
    for (int i = 0; i < ls.K; ++i)
    {
      double* q = &ls.Points[3 * static_cast<size_t>(j * ls.K + i)];
      used->GetCellPosition(i, j, q);
      for (int c = 0; c < 3; ++c)
      {
        q[c] -= origin[c];
      }
    }
  }
  used->GetAxes(ls.U, ls.V, ls.N);
  used->GetCentre(ls.Centre);
  for (int c = 0; c < 3; ++c)
  {
    ls.Centre[c] -= origin[c];
  }
  const double width = used->GetWidth();
  const double height = used->GetExtentV();
  ls.DSu = width / ls.K;
  ls.Su0 = (0.5 / ls.K - 0.5) * width;
  ls.DSv = line ? 0.0 : height / ls.K;
  ls.Sv0 = line ? 0.0 : (0.5 / ls.K - 0.5) * height;
  ls.HalfU = std::fabs(ls.Su0);
  ls.HalfV = std::fabs(ls.Sv0);
  ls.Diagonal = std::sqrt(width * width + height * height);
  call.Off = !penumbra_rules::LightEmits(used);

  for (int c = 0; c < 3; ++c)
  {
    call.Shift[c] = samplesOrigin[c] - origin[c];
  }
  call.Epsilon = self->Reference->GetRelativeEpsilon();
  call.TieFactor = self->Reference->GetTieFactor();
  call.Diagonal = this->Diagonal;
  return true;
}

//------------------------------------------------------------------------------
// The outputs, sized and cleared: visibility, the uncertain flags and (if kept) the masks.
void vtkPenumbraGearsShadows::Internals::SetUpOutputs(
  vtkPenumbraGearsShadows* self, vtkFloatArray* visibility, CallState& call)
{
  const vtkIdType n = call.N;
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  call.Vis = n ? visibility->GetPointer(0) : nullptr;
  this->Uncertain->SetNumberOfComponents(1);
  this->Uncertain->SetNumberOfTuples(n);
  call.Uncertain = n ? this->Uncertain->GetPointer(0) : nullptr;
  if (call.Uncertain)
  {
    std::fill(call.Uncertain, call.Uncertain + n, 0);
  }
  call.Words = (call.Light.Count + 31) / 32;
  call.Masks = nullptr;
  if (self->KeepMasks)
  {
    this->Masks->SetNumberOfComponents(call.Words);
    this->Masks->SetNumberOfTuples(n);
    call.Masks = n ? this->Masks->GetPointer(0) : nullptr;
    if (call.Masks)
    {
      std::fill(call.Masks, call.Masks + static_cast<size_t>(n) * call.Words, 0u);
    }
  }
  else
  {
    this->Masks->Initialize();
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraGearsShadows::Internals::ReportPathProblem(
  vtkPenumbraGearsShadows* self, const std::string& why)
{
  this->PathMessage =
    "GEARS compute path unavailable (" + why + "); the CPU path computes the masks";
  if (this->Reported.insert(why).second)
  {
    vtkWarningWithObjectMacro(self, << this->PathMessage);
  }
}

//------------------------------------------------------------------------------
// Where step 4 runs: the compute path when asked for and possible, else the CPU; and the
// list length above which a cell's samples are ray traced whole (CPU path only: the compute
// path has no use for the split).
void vtkPenumbraGearsShadows::Internals::ChoosePath(
  vtkPenumbraGearsShadows* self, vtkRenderer* renderer, CallState& call)
{
  const int requested = self->Path == PATH_AUTO ? PATH_CPU : self->Path;
  bool useGpu = false;
  this->PathMessage.clear();
  if (requested == PATH_GPU && !call.Off && call.N > 0 && !this->Casters.empty())
  {
    std::string why;
    auto* window =
      renderer ? vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow()) : nullptr;
    if (std::any_of(this->Casters.begin(), this->Casters.end(),
          [](const Caster& c) { return c.Id > std::numeric_limits<std::int32_t>::max(); }))
    {
      why = "triangle ids beyond 2^31 do not fit the shader's 32-bit ids";
    }
    else
    {
      useGpu = this->Compute.Prepare(window, call.Light.K, call.Light.Rows, self->KeepMasks, why) &&
        this->Compute.SetCasters(this->CasterData, this->CasterVersion, why) &&
        this->Compute.SetSamples(call.Pos, call.Nrm, call.Tris, call.N, why);
    }
    if (!useGpu)
    {
      this->ReportPathProblem(self, why);
    }
  }
  self->LastPath = PATH_CPU;
  call.UseGpu = useGpu;
  call.TraceLimit =
    !useGpu && self->TraceThreshold > 0.0 ? self->TraceThreshold * call.Light.Count : 0.0;
  call.DenseTree = self->DenseCells == DENSE_TREE;
}

//------------------------------------------------------------------------------
// Classify the samples: invalid, light off, facing away from the whole light, or on a side
// of the light plane (Scratch.Side: 1 front, -1 back, 2 on the plane, 0 decided).
void vtkPenumbraGearsShadows::Internals::ClassifySamples(
  vtkPenumbraGearsShadows* self, CallState& call)
{
  const vtkIdType n = call.N;
  const LightSamples& ls = call.Light;
  float* vis = call.Vis;
  std::vector<signed char>& side = this->Scratch.Side;
  side.assign(static_cast<size_t>(n), 0);
  std::atomic<vtkIdType> validCount(0);
  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType localValid = 0;
      std::uint64_t rows[MaxK];
      for (vtkIdType s = begin; s < end; ++s)
      {
        SampleRays r;
        if (!call.LoadSample(s, r))
        {
          vis[s] = -1.0f;
          continue;
        }
        ++localValid;
        if (call.Off)
        {
          vis[s] = 1.0f; // the reference's rule: nothing to shadow
          for (int j = 0; j < ls.Rows; ++j)
          {
            rows[j] = ls.Emitting[j];
          }
          call.WriteMask(s, rows);
          continue;
        }
        // Facing is affine over the light: below the tangent plane at every corner (with a
        // margin for the per-sample rounding) means below it for every light sample.
        double best = -std::numeric_limits<double>::infinity();
        double reach = 0.0;
        for (int c = 0; c < 4; ++c)
        {
          const double* q = ls.Corner(c);
          const double toLight[3] = { q[0] - r.P[0], q[1] - r.P[1], q[2] - r.P[2] };
          best = std::max(best, vtkMath::Dot(r.Normal, toLight));
          reach = std::max(reach, vtkMath::Norm(toLight));
        }
        if (best < -1e-9 * reach)
        {
          vis[s] = 0.0f;
          continue;
        }
        const double z = vtkMath::Dot(ls.N, r.P) - vtkMath::Dot(ls.N, ls.Centre);
        side[static_cast<size_t>(s)] = z > 0.0 ? 1 : (z < 0.0 ? -1 : 2);
      }
      validCount += localValid;
    });
  self->NumberOfValidSamples = validCount.load();
}

//------------------------------------------------------------------------------
// One side of the light plane: the grid camera and the sample binning (Wang et al. 2014,
// A.1-A.2), the triangle lists (A.3, with the switch of long-list cells to ray tracing) and
// the masks (§3, step 4) on the compute path or the CPU.
void vtkPenumbraGearsShadows::Internals::ProcessSide(
  vtkPenumbraGearsShadows* self, CallState& call, int flip)
{
  const auto gridStart = Clock::now();
  SideState S;
  if (!this->GatherSide(call, S, flip))
  {
    return;
  }
  // The per-caster arrays of the last side (tens of MB on a 1 M-triangle mesh) are reused:
  // fresh ones cost page faults every frame.
  ScratchArrays& keep = this->Scratch;
  S.ZNear.swap(keep.ZNear);
  S.Foot.swap(keep.Foot);
  S.Range.swap(keep.Range);
  S.Touched.swap(keep.Touched);
  this->PlaceCamera(self, call, S);
  this->CasterFootprints(call, S);
  this->BuildGrid(self, call, S);
  const ScratchArrays& sc = this->Scratch;
  call.GridUsed = std::min(call.GridUsed, S.G);
  const size_t cells = static_cast<size_t>(S.G) * S.G;
  call.Occupied += static_cast<vtkIdType>(sc.Occupied.size());
  call.Cells += static_cast<vtkIdType>(cells);
  call.ListTotal += static_cast<vtkIdType>(sc.CellList.size());
  call.GlobalTotal += static_cast<vtkIdType>(sc.GlobalList.size());
  for (const std::int32_t c : sc.Occupied)
  {
    call.MaxPerCell = std::max<vtkIdType>(call.MaxPerCell, sc.CellStart[c + 1] - sc.CellStart[c]);
  }
  call.GridMs += ElapsedMs(gridStart);

  // ---- Step 4: masks. Every sample considers its cell list and the global list.
  const auto maskStart = Clock::now();
  this->RouteTracedCells(call);
  if (call.DenseTree &&
    std::any_of(sc.Occupied.begin(), sc.Occupied.end(),
      [&](std::int32_t c) { return sc.Traced[static_cast<size_t>(c)] != 0; }))
  {
    this->Tree.Refit(this->Scratch.TriangleBoxes.data(), this->Scratch.TreeBoxes);
  }
  this->Scratch.OnCPU.clear();
  bool allOnCPU = !call.UseGpu;
  if (call.UseGpu && !this->MasksOnComputePath(self, call, S))
  {
    allOnCPU = true;
  }
  this->MasksOnCPU(call, S, allOnCPU);
  call.MaskMs += ElapsedMs(maskStart);
  S.ZNear.swap(keep.ZNear);
  S.Foot.swap(keep.Foot);
  S.Range.swap(keep.Range);
  S.Touched.swap(keep.Touched);
}

//------------------------------------------------------------------------------
// Statistics: the call's counts and times, for the getters.
void vtkPenumbraGearsShadows::Internals::StoreStatistics(
  vtkPenumbraGearsShadows* self, const CallState& call)
{
  self->TraceTimeMs = call.TraceMs;
  self->NumberOfTracedCellSamples = call.TracedCellSamples;
  self->NumberOfTreeSamples = call.TreeSamples;
  self->NumberOfTracedRays = call.TracedRays;
  self->NumberOfSamplesWithTracedRays = call.SamplesWithTracedRays;
  self->GridTimeMs = call.GridMs;
  self->MaskTimeMs = call.MaskMs;
  self->NumberOfUncertainSamples = call.UncertainSamples;
  self->NumberOfFlaggedSamples = call.Flagged;
  self->NumberOfOccupiedCells = call.Occupied;
  self->NumberOfCells = call.Cells;
  self->MaxTrianglesPerCell = call.MaxPerCell;
  self->AverageTrianglesPerCell =
    call.Occupied > 0 ? static_cast<double>(call.ListTotal) / call.Occupied : 0.0;
  self->NumberOfGlobalTriangles = call.GlobalTotal;
  self->NumberOfAssignments = call.Assignments.load();
  self->NumberOfNecessaryAssignments = call.Necessary.load();
  self->NumberOfSegmentTests = call.SegmentTests.load();
  self->EffectiveGridResolution = call.GridUsed;
}

//------------------------------------------------------------------------------
void vtkPenumbraGearsShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "DenseCells: " << this->DenseCells << "\n";
  os << indent << "SamplesPerAxis: " << this->SamplesPerAxis << "\n";
  os << indent << "GridResolution: " << this->GridResolution << "\n";
  os << indent << "CameraDistanceFactor: " << this->CameraDistanceFactor << "\n";
  os << indent << "MaxListEntries: " << this->MaxListEntries << "\n";
  os << indent << "TraceThreshold: " << this->TraceThreshold << "\n";
  os << indent << "KeepMasks: " << this->KeepMasks << "\n";
  os << indent << "Path: " << this->Path << " (last " << this->LastPath << ")\n";
  os << indent << "NumberOfFlaggedSamples: " << this->NumberOfFlaggedSamples << "\n";
  os << indent << "NumberOfUncertainSamples: " << this->NumberOfUncertainSamples << "\n";
  os << indent << "NumberOfAssignments: " << this->NumberOfAssignments << "\n";
  os << indent << "NumberOfNecessaryAssignments: " << this->NumberOfNecessaryAssignments << "\n";
}

//------------------------------------------------------------------------------
const char* vtkPenumbraGearsShadows::GetTechniqueNameFor(vtkLight* light)
{
  return vtkPenumbraAreaLight::SafeDownCast(light) ? this->GetTechniqueName() : "raytraced";
}

//------------------------------------------------------------------------------
void vtkPenumbraGearsShadows::GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  if (!this->LastLightWasArea)
  {
    return; // a hard light was traced at its point: no grid, masks or light samples
  }
  stats->Set("gpu_masks", this->LastPath == PATH_GPU ? 1.0 : 0.0);
  stats->Set("cells", static_cast<double>(this->NumberOfCells));
  stats->Set("occupied_cells", static_cast<double>(this->NumberOfOccupiedCells));
  stats->Set("grid_resolution", this->EffectiveGridResolution);
  stats->Set("max_triangles_per_cell", static_cast<double>(this->MaxTrianglesPerCell));
  stats->Set("mean_triangles_per_cell", this->AverageTrianglesPerCell);
  stats->Set("global_triangles", static_cast<double>(this->NumberOfGlobalTriangles));
  stats->Set("assignments", static_cast<double>(this->NumberOfAssignments));
  stats->Set("necessary_assignments", static_cast<double>(this->NumberOfNecessaryAssignments));
  stats->Set("blocking_share", this->GetBlockingShare());
  stats->Set("uncertain_samples", static_cast<double>(this->NumberOfUncertainSamples));
  stats->Set("traced_cell_samples", static_cast<double>(this->NumberOfTracedCellSamples));
  stats->Set("tree_samples", static_cast<double>(this->NumberOfTreeSamples));
  stats->Set("traced_rays", static_cast<double>(this->NumberOfTracedRays));
  stats->Set("samples_with_traced_rays", static_cast<double>(this->NumberOfSamplesWithTracedRays));
  stats->Set("segment_tests", static_cast<double>(this->NumberOfSegmentTests));
  stats->Set("flagged_samples", static_cast<double>(this->NumberOfFlaggedSamples));
  stats->Set("grid_ms", this->GridTimeMs);
  stats->Set("mask_ms", this->MaskTimeMs);
  stats->Set("trace_ms", this->TraceTimeMs);
}
