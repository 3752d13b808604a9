#include "vtkPenumbraLinkedListShadows.h"

#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkSMPTools.h"
#include "vtkUnsignedCharArray.h"

#include "vtkPenumbraConservativeMapCPU.h"
#include "vtkPenumbraLightViews.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraLinkedListShadows);

using penumbra_light_views::View;
using penumbra_rules::Hit;

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;

// Per-sample states. The first two are also the values of the mask the reference traces.
enum : unsigned char
{
  Settled = 0, // decided: lit, or shadowed with visibility 0 written
  Pending = 1, // to be listed; after the lists: to be traced
  Open = 2,    // listed, no triangle has decided it yet (lit if it stays so)
  Unknown = 3, // listed, a triangle could not be decided: traced unless another shadows it
  Shadowed = 4 // listed, a triangle provably blocks its ray
};

// Triangles in a perspective view's apex region are tested against every sample of the view;
// beyond this many, the view's open samples are traced instead.
constexpr size_t MaxNearTriangles = 256;

// Everything a sample test needs, for one light and call.
struct TestContext
{
  const penumbra_light_views::FrameInputs* In;
  double Diagonal;
  double Epsilon;
  double TieFactor;
  unsigned char* State;
  const double* Depth; // per sample: its stored depth in its view

  void Position(vtkIdType s, double p[3]) const
  {
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(this->In->Positions[3 * s + c]) + this->In->Shift[c];
    }
  }

  // The reference's decision for sample s and `triangle` (null: a triangle without area,
  // left to the tracer): a clear hit shadows, an undecidable one leaves it to the tracer
  // unless another triangle shadows it.
  void Test(vtkIdType s, const penumbra_rules::ExactTriangle* triangle) const
  {
    double p[3];
    this->Position(s, p);
    const penumbra_light_views::ShadowRay ray = penumbra_light_views::MakeShadowRay(
      this->In->Light, p, this->Diagonal, this->Epsilon, this->TieFactor);
    const Hit hit = triangle ? penumbra_light_views::TestShadowRay(ray, *triangle) : Hit::Unknown;
    if (hit == Hit::Clear)
    {
      this->State[s] = Shadowed;
    }
    else if (hit == Hit::Unknown)
    {
      this->State[s] = Unknown;
    }
  }
};

// The conservative depth test of Hertel et al. 2009, §4.2, as the conservative technique
// uses it: a triangle whose smallest stored depth over the texel lies beyond the sample's
// depth cannot meet the sample's ray, which runs towards smaller depths.
inline bool Behind(float triangleDepth, double sampleDepth)
{
  return triangleDepth > sampleDepth + 1e-6 * (1.0 + std::fabs(sampleDepth));
}

// Projects the view's pending samples into its grid: `texel` and `depth` per listable sample
// (appended to `listed`, ascending); a sample outside the grid or behind the apex, or on a
// positional light, is left to the tracer (Pending).
void ProjectSamples(const View& view, int size, signed char viewIndex,
  const std::vector<signed char>& sampleView, const TestContext& ctx, vtkIdType n,
  std::vector<vtkIdType>& texel, std::vector<double>& depth, std::vector<vtkIdType>& listed)
{
  vtkSMPTools::For(0, n, [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType s = begin; s < end; ++s)
    {
      texel[static_cast<size_t>(s)] = -1;
      if (ctx.State[s] != Pending || sampleView[static_cast<size_t>(s)] != viewIndex)
      {
        continue;
      }
      double p[3], ms, mt, d;
      ctx.Position(s, p);
      if (!view.Project(p, ms, mt, d) || !(std::fabs(ms) <= 1.0) || !(std::fabs(mt) <= 1.0) ||
        !penumbra_light_views::MakeShadowRay(ctx.In->Light, p, 1.0, 0.0, 1.0).Ok)
      {
        continue;
      }
      // The texel rule of the conservative classification: the same map point.
      const int ix = std::min(size - 1, std::max(0, static_cast<int>((ms * 0.5 + 0.5) * size)));
      const int iy = std::min(size - 1, std::max(0, static_cast<int>((mt * 0.5 + 0.5) * size)));
      texel[static_cast<size_t>(s)] = static_cast<vtkIdType>(iy) * size + ix;
      depth[static_cast<size_t>(s)] = d;
    }
  });
  for (vtkIdType s = 0; s < n; ++s)
  {
    if (texel[static_cast<size_t>(s)] >= 0)
    {
      listed.push_back(s);
    }
  }
}

// The per-texel lists of one pass (Johnson et al. 2005's grid of lists; the CPU form of
// Ferko 2014's head pointers and node pool): the nodes sorted by texel, then sample, and per
// texel the index of its first node. Head and Active have a value per texel and are reset
// only where a list was, so a pass with few samples costs no full-grid clear.
struct Lists
{
  std::vector<vtkIdType> Head;        // per texel: first node, -1 when empty
  std::vector<unsigned char> Active;  // per texel: holds an undecided sample
  std::vector<vtkIdType> Nodes;       // sample ids
  std::vector<vtkIdType> NodeTexel;   // per node: its texel
  std::vector<vtkIdType> Counts;      // dense passes: the counting sort's rows

  // Lists the `count` samples from `first` (texel per sample in `texel`), marks them open
  // and their texels active; returns the longest list, and the non-empty texels in `rows`.
  vtkIdType Build(int size, const vtkIdType* first, vtkIdType count,
    const std::vector<vtkIdType>& texel, unsigned char* state, vtkIdType& rows)
  {
    const size_t texels = static_cast<size_t>(size) * size;
    if (this->Head.size() != texels)
    {
      this->Head.assign(texels, -1);
      this->Active.assign(texels, 0);
    }
    this->Nodes.resize(static_cast<size_t>(count));
    this->NodeTexel.resize(static_cast<size_t>(count));
    auto texelOf = [&](vtkIdType i) { return texel[static_cast<size_t>(first[i])]; };
    if (static_cast<size_t>(count) * 8 >= texels)
    {
      // Dense: counting sort (counts, prefix sum, fill), linear in texels and samples.
      this->Counts.assign(texels + 1, 0);
      for (vtkIdType i = 0; i < count; ++i)
      {
        ++this->Counts[static_cast<size_t>(texelOf(i)) + 1];
      }
      for (size_t t = 0; t < texels; ++t)
      {
        this->Counts[t + 1] += this->Counts[t];
      }
      for (vtkIdType i = 0; i < count; ++i)
      {
        const vtkIdType j = this->Counts[static_cast<size_t>(texelOf(i))]++;
        this->Nodes[static_cast<size_t>(j)] = first[i];
        this->NodeTexel[static_cast<size_t>(j)] = texelOf(i);
      }
    }
    else
    {
      // Sparse: sort the few (texel, sample) pairs instead of sweeping the grid.
      std::vector<std::pair<vtkIdType, vtkIdType>> pairs(static_cast<size_t>(count));
      for (vtkIdType i = 0; i < count; ++i)
      {
        pairs[static_cast<size_t>(i)] = { texelOf(i), first[i] };
      }
      std::sort(pairs.begin(), pairs.end());
      for (size_t j = 0; j < pairs.size(); ++j)
      {
        this->NodeTexel[j] = pairs[j].first;
        this->Nodes[j] = pairs[j].second;
      }
    }
    vtkIdType longest = 0;
    rows = 0;
    for (vtkIdType j = 0; j < count;)
    {
      const vtkIdType t = this->NodeTexel[static_cast<size_t>(j)];
      this->Head[static_cast<size_t>(t)] = j;
      this->Active[static_cast<size_t>(t)] = 1;
      const vtkIdType begin = j;
      for (; j < count && this->NodeTexel[static_cast<size_t>(j)] == t; ++j)
      {
        state[this->Nodes[static_cast<size_t>(j)]] = Open;
      }
      longest = std::max(longest, j - begin);
      ++rows;
    }
    return longest;
  }

  // Empties the texels of the last Build.
  void Clear()
  {
    for (vtkIdType t : this->NodeTexel)
    {
      this->Head[static_cast<size_t>(t)] = -1;
      this->Active[static_cast<size_t>(t)] = 0;
    }
  }
};

// Irregular rasterization (Ferko 2014; Johnson et al. 2005): every caster triangle meets the
// samples listed at each texel its conservative footprint touches. A texel whose samples are
// all shadowed drops out. Returns the number of exact tests; the apex region's triangles go
// to `nearTriangles`.
vtkIdType RasterizeLists(const View& view, int size, const TestContext& ctx,
  const std::vector<vtkIdType>& casters, Lists& lists, std::vector<vtkIdType>& nearTriangles)
{
  const std::vector<vtkIdType>& nodes = lists.Nodes;
  const std::vector<vtkIdType>& nodeTexel = lists.NodeTexel;
  const vtkIdType count = static_cast<vtkIdType>(nodes.size());
  std::vector<unsigned char>& active = lists.Active;
  const double* vertices = ctx.In->TriangleVertices;
  const vtkIdType* own = ctx.In->Triangles;
  unsigned char* state = ctx.State;
  const penumbra_conservative::CpuMapStats stats = penumbra_conservative::RasterizeConservative(
    view, size, vertices, casters, active.data(), nearTriangles,
    [&](size_t texel, vtkIdType id, float triangleDepth) -> vtkIdType {
      penumbra_rules::ExactTriangle triangle;
      int made = -1; // -1 not yet, 0 without area, 1 made
      vtkIdType tests = 0;
      bool open = false;
      const vtkIdType row = static_cast<vtkIdType>(texel);
      for (vtkIdType j = lists.Head[texel]; j >= 0 && j < count &&
           nodeTexel[static_cast<size_t>(j)] == row;
           ++j)
      {
        const vtkIdType s = nodes[static_cast<size_t>(j)];
        if (state[s] == Shadowed)
        {
          continue;
        }
        if (own[s] != id && !Behind(triangleDepth, ctx.Depth[s]))
        {
          if (made < 0)
          {
            made = penumbra_rules::MakeExactTriangle(vertices + 9 * id, id, triangle) ? 1 : 0;
          }
          ctx.Test(s, made ? &triangle : nullptr);
          ++tests;
        }
        open = open || state[s] != Shadowed;
      }
      active[texel] = open;
      return tests;
    });
  return stats.VisitWork;
}

// The apex region's triangles would cover the whole view: each is tested against every
// listed sample still undecided (up to MaxNearTriangles; beyond, those samples are traced).
vtkIdType TestNearTriangles(const TestContext& ctx, const vtkIdType* listed, vtkIdType count,
  const std::vector<vtkIdType>& nearTriangles)
{
  if (nearTriangles.empty())
  {
    return 0;
  }
  const bool testable = nearTriangles.size() <= MaxNearTriangles;
  std::vector<penumbra_rules::ExactTriangle> triangles(nearTriangles.size());
  std::vector<unsigned char> made(nearTriangles.size(), 0);
  for (size_t k = 0; testable && k < nearTriangles.size(); ++k)
  {
    const vtkIdType id = nearTriangles[k];
    made[k] = penumbra_rules::MakeExactTriangle(ctx.In->TriangleVertices + 9 * id, id, triangles[k]);
  }
  std::atomic<vtkIdType> tests(0);
  vtkSMPTools::For(0, count, [&](vtkIdType begin, vtkIdType end) {
    vtkIdType local = 0;
    for (vtkIdType i = begin; i < end; ++i)
    {
      const vtkIdType s = listed[i];
      for (size_t k = 0; k < nearTriangles.size() && ctx.State[s] != Shadowed; ++k)
      {
        if (!testable)
        {
          ctx.State[s] = Unknown;
          break;
        }
        if (nearTriangles[k] != ctx.In->Triangles[s])
        {
          ctx.Test(s, made[k] ? &triangles[k] : nullptr);
          ++local;
        }
      }
    }
    tests += local;
  });
  return tests.load();
}
}

struct vtkPenumbraLinkedListShadows::Internals
{
  penumbra_light_views::CasterBuffers Casters; // CPU lists only, never uploaded
  vtkNew<vtkUnsignedCharArray> State;
  std::vector<double> Depth;        // per sample
  std::vector<vtkIdType> Texel;     // per sample, its texel in its view
  std::vector<vtkIdType> Listed;    // the view's listable samples, ascending
  Lists Grid;
  std::vector<vtkIdType> Near;      // the apex region's triangles
};

//------------------------------------------------------------------------------
vtkPenumbraLinkedListShadows::vtkPenumbraLinkedListShadows()
  : Classifier(vtkPenumbraConservativeShadows::New())
  , Reference(vtkPenumbraReference::New())
  , Impl(new Internals)
{
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
  this->NumberOfPasses = this->NumberOfViews = 0;
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
  if (!this->Hybrid)
  {
    penumbra_light_views::ClassifyFacing(in.Light, n, in.Positions, in.Normals, in.Props,
      in.Shift, anyCaster, vis, state, Pending, Settled);
  }
  for (vtkIdType s = 0; s < n; ++s)
  {
    this->NumberOfValidSamples += vis[s] >= 0.0f;
  }
  std::vector<View> views;
  std::vector<signed char> sampleView;
  penumbra_light_views::FitViews(
    in.Light, n, in.Positions, in.Shift, state, Pending, views, sampleView);
  this->NumberOfViews = static_cast<int>(views.size());
  this->ClassifyTimeMs = ElapsedMs(classifyStart);

  // ---- 2.-4. Per view and pass: lists, irregular rasterization, apex-region triangles.
  impl.Depth.resize(static_cast<size_t>(n));
  impl.Texel.resize(static_cast<size_t>(n));
  const TestContext ctx = { &in, penumbra_rules::SceneDiagonal(geometry),
    this->Reference->GetRelativeEpsilon(), this->Reference->GetTieFactor(), state,
    impl.Depth.data() };
  const int size = this->Resolution;
  vtkIdType rows = 0;
  for (size_t vi = 0; vi < views.size(); ++vi)
  {
    auto listStart = Clock::now();
    impl.Listed.clear();
    ProjectSamples(views[vi], size, static_cast<signed char>(vi), sampleView, ctx, n, impl.Texel,
      impl.Depth, impl.Listed);
    this->ListTimeMs += ElapsedMs(listStart);
    const vtkIdType listed = static_cast<vtkIdType>(impl.Listed.size());
    const vtkIdType capacity = this->ListCapacity > 0 ? this->ListCapacity : std::max<vtkIdType>(listed, 1);
    for (vtkIdType first = 0; first < listed; first += capacity)
    {
      const vtkIdType count = std::min(capacity, listed - first);
      listStart = Clock::now();
      vtkIdType passRows = 0;
      this->MaxListLength = std::max(this->MaxListLength,
        impl.Grid.Build(size, impl.Listed.data() + first, count, impl.Texel, state, passRows));
      rows += passRows;
      this->ListTimeMs += ElapsedMs(listStart);
      const auto rasterStart = Clock::now();
      impl.Near.clear();
      this->NumberOfTests +=
        RasterizeLists(views[vi], size, ctx, impl.Casters.TriangleIds, impl.Grid, impl.Near);
      this->NumberOfTests += TestNearTriangles(ctx, impl.Listed.data() + first, count, impl.Near);
      impl.Grid.Clear();
      this->RasterTimeMs += ElapsedMs(rasterStart);
      ++this->NumberOfPasses;
    }
    this->NumberOfListedSamples += listed;
  }
  this->MeanListLength = rows > 0 ? static_cast<double>(this->NumberOfListedSamples) / rows : 0.0;

  // ---- 5. Settle the lists' answers; the unknown and unlisted samples are traced.
  vtkIdType traced = 0;
  for (vtkIdType s = 0; s < n; ++s)
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
  visibility->Modified();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
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
  os << indent << "ClassifyTimeMs: " << this->ClassifyTimeMs << "\n";
  os << indent << "ListTimeMs: " << this->ListTimeMs << "\n";
  os << indent << "RasterTimeMs: " << this->RasterTimeMs << "\n";
  os << indent << "TraceTimeMs: " << this->TraceTimeMs << "\n";
}
