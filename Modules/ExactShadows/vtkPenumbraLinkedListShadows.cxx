#include "vtkPenumbraLinkedListShadows.h"
#include "vtkPenumbraLinkedListInternals.h"
#include "vtkPenumbraStatistics.h"

#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <array>

vtkStandardNewMacro(vtkPenumbraLinkedListShadows);

using namespace penumbra_llsm;

//------------------------------------------------------------------------------
vtkPenumbraLinkedListShadows::vtkPenumbraLinkedListShadows()
  : Classifier(vtkPenumbraConservativeShadows::New())
  , Reference(vtkPenumbraReference::New())
  , Impl(new Internals)
{
  this->Classifier->SetLayers(3); // see GetClassifier()
}

//------------------------------------------------------------------------------
vtkPenumbraLinkedListShadows::~vtkPenumbraLinkedListShadows()
{
  this->Classifier->Delete();
  this->Reference->Delete();
}

//------------------------------------------------------------------------------
int vtkPenumbraLinkedListShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  this->NumberOfValidSamples = this->NumberOfListedSamples = this->MaxListLength = 0;
  this->NumberOfTests = this->NumberOfTracedSamples = 0;
  this->MeanListLength = 0.0;
  this->NumberOfPasses = this->NumberOfViews = this->NumberOfOverflows = 0;
  this->NumberOfSparsePasses = 0;
  impl.Recorded->SetNumberOfComponents(3);
  impl.Recorded->SetNumberOfTuples(0);
  this->NumberOfCulledCasters = this->NumberOfRasterizedCasters = 0;
  this->ClassifyTimeMs = this->ListTimeMs = this->RasterTimeMs = this->TraceTimeMs = 0.0;

  penumbra_light_views::FrameInputs in;
  {
    std::string inputError;
    if (!in.Read(renderer, geometry, samples, light, visibility, inputError))
    {
      PENUMBRA_FAIL("linked-list shadows: " << inputError);
    }
  }
  const vtkIdType n = in.NumberOfSamples;
  impl.Casters.Update(geometry, false);
  impl.CastersTime = geometry->GetCastersTime();
  const bool anyCaster = !impl.Casters.TriangleIds.empty();

  // ---- 1. The samples to decide (Pending): facing the light, or the hybrid's hard ones
  // (the classifier's uncertain samples, mask value 1).
  const auto classifyStart = Clock::now();
  vtkUnsignedCharArray* mask = impl.State;
  if (this->Hybrid &&
    !this->Classifier->Classify(renderer, geometry, samples, light, visibility, mask))
  {
    PENUMBRA_FAIL("linked-list shadows: the hybrid's classification failed");
  }
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  mask->SetNumberOfComponents(1);
  mask->SetNumberOfTuples(n);
  float* vis = n ? visibility->GetPointer(0) : nullptr;
  unsigned char* state = n ? mask->GetPointer(0) : nullptr;
  // The pending samples, listed once: every later phase visits only them. The hybrid's
  // classifier lists and counts them already (its uncertain samples, mask value 1 =
  // Pending; lit + shadowed + uncertain = the valid samples), so its samples are not scanned
  // again.
  impl.ToDecide.clear();
  if (this->Hybrid)
  {
    const std::vector<vtkIdType>& uncertain = this->Classifier->GetUncertainSamples();
    impl.ToDecide.assign(uncertain.begin(), uncertain.end());
    this->NumberOfValidSamples = this->Classifier->GetNumberOfLitSamples() +
      this->Classifier->GetNumberOfShadowedSamples() + static_cast<vtkIdType>(uncertain.size());
  }
  else
  {
    penumbra_light_views::ClassifyFacing(in.Light, n, in.Positions, in.Normals, in.Props, in.Shift,
      anyCaster, vis, state, Pending, Settled);
    for (vtkIdType s = 0; s < n; ++s)
    {
      this->NumberOfValidSamples += vis[s] >= 0.0f;
      if (state[s] == Pending)
      {
        impl.ToDecide.push_back(s);
      }
    }
  }
  std::vector<View> views;
  std::vector<signed char> sampleView;
  penumbra_light_views::FitViews(
    in.Light, n, in.Positions, in.Shift, state, Pending, views, sampleView, &impl.ToDecide);
  this->NumberOfViews = static_cast<int>(views.size());
  this->ClassifyTimeMs = ElapsedMs(classifyStart);

  // ---- 2.-4. Per view and pass: lists, irregular rasterization, apex-region triangles.
  impl.Depth.resize(static_cast<size_t>(n));
  impl.Texel.resize(static_cast<size_t>(n));
  impl.Point.resize(2 * static_cast<size_t>(n));
  const TestContext ctx = { &in, penumbra_rules::SceneDiagonal(geometry),
    this->Reference->GetRelativeEpsilon(), this->Reference->GetTieFactor(), state,
    impl.Depth.data() };
  vtkIdType rows = 0;
  impl.ChooseListPath(this, renderer, n);
  for (size_t vi = 0; vi < views.size(); ++vi)
  {
    const auto listStart = Clock::now();
    impl.Listed.clear();
    ProjectSamples(views[vi], this->Resolution, static_cast<signed char>(vi), sampleView, ctx,
      impl.ToDecide, impl.Texel, impl.Depth, impl.Point, impl.Listed);
    this->ListTimeMs += ElapsedMs(listStart);
    impl.ListView(this, views[vi], static_cast<int>(vi), ctx, rows);
    this->NumberOfListedSamples += static_cast<vtkIdType>(impl.Listed.size());
  }
  this->LastListBuilder = impl.UseGpu ? LISTS_GPU : LISTS_CPU;
  this->MeanListLength = rows > 0 ? static_cast<double>(this->NumberOfListedSamples) / rows : 0.0;

  impl.ReleaseLists();

  // ---- 5. Settle the lists' answers; the unknown and unlisted samples are traced.
  vtkIdType traced = 0;
  // Only pending samples changed state; the others are settled (0) already.
  for (vtkIdType s : impl.ToDecide)
  {
    if (state[s] == Shadowed)
    {
      vis[s] = 0.0f;
    }
    state[s] = (state[s] == Pending || state[s] == Unknown) ? 1 : 0;
    traced += state[s];
  }
  if (traced > 0)
  {
    const auto traceStart = Clock::now();
    this->Reference->SetGeometry(geometry);
    if (!this->Reference->ComputeVisibility(samples, light, visibility, mask))
    {
      PENUMBRA_FAIL("tracing the unknown samples failed: " << this->Reference->GetErrorMessage());
    }
    this->TraceTimeMs = ElapsedMs(traceStart);
  }
  this->NumberOfTracedSamples = traced;
  std::vector<vtkIdType>().swap(impl.ToDecide);
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
// The lists and what was made for them, once every view is done: none of it is kept between
// calls (a moving camera makes them anew), so that a frame's other phases (the view samples'
// read-back, the tracer) do not hold them too. The caster clusters, made from the casters
// alone, stay.
void vtkPenumbraLinkedListShadows::Internals::ReleaseLists()
{
  std::vector<double>().swap(this->Depth);
  std::vector<vtkIdType>().swap(this->Texel);
  std::vector<float>().swap(this->Point);
  std::vector<vtkIdType>().swap(this->Listed);
  std::vector<vtkIdType>().swap(this->Pick);
  std::vector<vtkIdType>().swap(this->Near);
  std::vector<unsigned char>().swap(this->Keep);
  this->Kept = penumbra_casters::CasterIds();
  this->Grid = penumbra_llsm::Lists();
  this->Cells = penumbra_llsm::SampleCells();
  this->Bands = penumbra_llsm::CasterGrid();
}

//------------------------------------------------------------------------------
// Per pass of one view: the lists, caster culling, the irregular rasterization and the apex
// region's triangles.
void vtkPenumbraLinkedListShadows::Internals::ListView(vtkPenumbraLinkedListShadows* self,
  const View& view, int vi, const TestContext& ctx, vtkIdType& rows)
{
  const int size = self->Resolution;
  const vtkIdType listed = static_cast<vtkIdType>(this->Listed.size());
  const vtkIdType capacity =
    self->ListCapacity > 0 ? self->ListCapacity : std::max<vtkIdType>(listed, 1);
  for (vtkIdType remaining = listed; remaining > 0;)
  {
    const auto listStart = Clock::now();
    const bool any = this->BuildPass(self, vi, capacity, ctx.State, rows);
    self->ListTimeMs += ElapsedMs(listStart);
    if (!any)
    {
      break;
    }
    const vtkIdType count = static_cast<vtkIdType>(this->Grid.Samples.size());
    remaining -= count;
    const auto rasterStart = Clock::now();
    const penumbra_casters::CasterIds* casters = &this->Casters.TriangleIds;
    // Sparse lists (the hybrid's hard samples) are tested caster by caster box (CasterGrid),
    // which needs no coarse culling first: its bands skip the casters whose box meets no
    // listed texel, and MayBlock's depth test is per sample. Dense ones, where the per-caster
    // setup of the footprints pays off, are culled and rasterized.
    const bool sparse = count < SparseFactor * static_cast<vtkIdType>(casters->size());
    if (self->CullCasters && !sparse)
    {
      // Only casters that can reach a listed sample are rasterized (see SampleCells). The
      // clusters are made for the first dense pass (8 bytes a caster; sparse passes do not
      // cull) and kept while the casters are unchanged.
      this->Clusters.Update(this->Casters.TriangleIds, ctx.In->SceneTriangles, this->CastersTime);
      this->Cells.Build(size, this->Grid.Samples.data(), count, this->Texel, this->Depth.data());
      self->NumberOfCulledCasters += this->Clusters.Cull(
        view, size, this->Cells, *ctx.In->SceneTriangles, this->Keep, this->Kept);
      casters = &this->Kept;
    }
    self->NumberOfRasterizedCasters += static_cast<vtkIdType>(casters->size());
    this->Near.clear();
    if (sparse)
    {
      this->Bands.Build(view, size, ctx, *casters, this->Grid, this->Near);
      self->NumberOfTests += TestListsByBands(
        size, ctx, *casters, this->Grid, this->Bands, this->Point.data(), this->Casters.Exact);
      ++self->NumberOfSparsePasses;
    }
    else
    {
      self->NumberOfTests +=
        RasterizeLists(view, size, ctx, *casters, this->Grid, this->Casters.Exact, this->Near);
    }
    self->NumberOfTests += TestNearTriangles(ctx, this->Grid.Samples.data(), count, this->Near);
    this->Grid.Clear();
    self->RasterTimeMs += ElapsedMs(rasterStart);
    ++self->NumberOfPasses;
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraLinkedListShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Compute.Release(window);
}

//------------------------------------------------------------------------------
vtkIdTypeArray* vtkPenumbraLinkedListShadows::GetRecordedLists()
{
  vtkIdTypeArray* recorded = this->Impl->Recorded;
  // Sorted tuples: the per-texel sample sets, independent of node order and pass split.
  const vtkIdType n = recorded->GetNumberOfTuples();
  std::vector<std::array<vtkIdType, 3>> tuples(static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    recorded->GetTypedTuple(i, tuples[static_cast<size_t>(i)].data());
  }
  std::sort(tuples.begin(), tuples.end());
  for (vtkIdType i = 0; i < n; ++i)
  {
    recorded->SetTypedTuple(i, tuples[static_cast<size_t>(i)].data());
  }
  return recorded;
}

//------------------------------------------------------------------------------
double vtkPenumbraLinkedListShadows::GetListedFraction()
{
  return this->NumberOfValidSamples > 0
    ? static_cast<double>(this->NumberOfListedSamples) / this->NumberOfValidSamples
    : 0.0;
}

//------------------------------------------------------------------------------
double vtkPenumbraLinkedListShadows::GetUncertainFraction()
{
  if (this->Hybrid)
  {
    return this->GetListedFraction();
  }
  return this->NumberOfValidSamples > 0
    ? static_cast<double>(this->NumberOfTracedSamples) / this->NumberOfValidSamples
    : 0.0;
}

//------------------------------------------------------------------------------
void vtkPenumbraLinkedListShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  if (this->Classifier)
  {
    os << indent << "Classifier: resolution " << this->Classifier->GetResolution() << ", layers "
       << this->Classifier->GetLayers() << "\n";
  }
  os << indent << "Resolution: " << this->Resolution << "\n";
  os << indent << "ListCapacity: " << this->ListCapacity << "\n";
  os << indent << "Hybrid: " << (this->Hybrid ? "on" : "off") << "\n";
  os << indent << "NumberOfValidSamples: " << this->NumberOfValidSamples << "\n";
  os << indent << "NumberOfListedSamples: " << this->NumberOfListedSamples << "\n";
  os << indent << "MaxListLength: " << this->MaxListLength << "\n";
  os << indent << "MeanListLength: " << this->MeanListLength << "\n";
  os << indent << "NumberOfTests: " << this->NumberOfTests << "\n";
  os << indent << "NumberOfTracedSamples: " << this->NumberOfTracedSamples << "\n";
  os << indent << "NumberOfPasses: " << this->NumberOfPasses << "\n";
  os << indent << "NumberOfViews: " << this->NumberOfViews << "\n";
  os << indent << "ListBuilder: " << (this->ListBuilder == LISTS_GPU ? "gpu" : "cpu") << "\n";
  os << indent << "NumberOfOverflows: " << this->NumberOfOverflows << "\n";
  os << indent << "NumberOfSparsePasses: " << this->NumberOfSparsePasses << "\n";
  os << indent << "CullCasters: " << (this->CullCasters ? "on" : "off") << "\n";
  os << indent << "NumberOfCulledCasters: " << this->NumberOfCulledCasters << "\n";
  os << indent << "NumberOfRasterizedCasters: " << this->NumberOfRasterizedCasters << "\n";
  os << indent << "ClassifyTimeMs: " << this->ClassifyTimeMs << "\n";
  os << indent << "ListTimeMs: " << this->ListTimeMs << "\n";
  os << indent << "RasterTimeMs: " << this->RasterTimeMs << "\n";
  os << indent << "TraceTimeMs: " << this->TraceTimeMs << "\n";
}

//------------------------------------------------------------------------------
void vtkPenumbraLinkedListShadows::GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  stats->Set("valid_samples", static_cast<double>(this->NumberOfValidSamples));
  stats->Set("listed_samples", static_cast<double>(this->NumberOfListedSamples));
  stats->Set("listed_share", this->GetListedFraction());
  stats->Set("max_list_length", static_cast<double>(this->MaxListLength));
  stats->Set("mean_list_length", this->MeanListLength);
  stats->Set("tests", static_cast<double>(this->NumberOfTests));
  stats->Set("traced_samples", static_cast<double>(this->NumberOfTracedSamples));
  stats->Set("passes", this->NumberOfPasses);
  stats->Set("sparse_passes", this->NumberOfSparsePasses);
  stats->Set("overflows", this->NumberOfOverflows);
  stats->Set("views", this->NumberOfViews);
  stats->Set("culled_casters", static_cast<double>(this->NumberOfCulledCasters));
  stats->Set("rasterized_casters", static_cast<double>(this->NumberOfRasterizedCasters));
  stats->Set("classify_ms", this->ClassifyTimeMs);
  stats->Set("list_ms", this->ListTimeMs);
  stats->Set("raster_ms", this->RasterTimeMs);
  stats->Set("trace_ms", this->TraceTimeMs);
}
