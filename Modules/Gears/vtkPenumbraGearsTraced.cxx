// GEARS' ray-traced share: the long-list switch that sends dense cells to the reference,
// their samples' routing, and the tracing of undecided light samples (Wang et al. 2014, §5.1).
#include "vtkPenumbraGearsShadowsInternals.h"

namespace
{
// Triangles per grid cell from the casters' cell ranges, without visiting a single (caster,
// cell) pair: a 2-D difference array (+1 at a range's first corner, -1 past its edges) whose
// prefix sums are the list lengths. O(casters + cells), so a cell's cost is known before its
// list is built.
std::vector<std::int64_t> CellListLengths(
  int g, const std::vector<int>& range, const std::vector<std::int64_t>& touched)
{
  const size_t side = static_cast<size_t>(g) + 1;
  std::vector<std::int64_t> diff(side * side, 0);
  for (size_t t = 0; t < touched.size(); ++t)
  {
    if (touched[t] <= 0)
    {
      continue;
    }
    const int* rg = &range[4 * t];
    diff[static_cast<size_t>(rg[2]) * side + rg[0]] += 1;
    diff[static_cast<size_t>(rg[2]) * side + rg[1] + 1] -= 1;
    diff[static_cast<size_t>(rg[3] + 1) * side + rg[0]] -= 1;
    diff[static_cast<size_t>(rg[3] + 1) * side + rg[1] + 1] += 1;
  }
  std::vector<std::int64_t> length(static_cast<size_t>(g) * g, 0);
  for (int iy = 0; iy < g; ++iy)
  {
    std::int64_t row = 0;
    for (int ix = 0; ix < g; ++ix)
    {
      row += diff[static_cast<size_t>(iy) * side + ix];
      length[static_cast<size_t>(iy) * g + ix] =
        row + (iy > 0 ? length[static_cast<size_t>(iy - 1) * g + ix] : 0);
    }
  }
  return length;
}
}
//------------------------------------------------------------------------------
// The long-list switch: cells whose list costs more than tracing their light samples. On a
// dense mesh under a large light a cell meets hundreds of tiny triangles each covering less
// than one light sample, and Embree's log N per ray wins. Their samples go to the reference
// whole (exact by construction) and their lists are never built (Scratch.Traced).
void vtkPenumbraGearsShadows::Internals::MarkTracedCells(const CallState& call, SideState& S)
{
  const int g = S.G;
  std::vector<unsigned char>& traced = this->Scratch.Traced;
  traced.assign(static_cast<size_t>(g) * g, 0);
  if (call.TraceLimit > 0.0 && g > 1)
  {
    const std::vector<std::int64_t> lengths = CellListLengths(g, S.Range, S.Touched);
    const double limit = call.TraceLimit - static_cast<double>(this->Scratch.GlobalList.size());
    for (const std::int32_t c : this->Scratch.Occupied)
    {
      if (static_cast<double>(lengths[static_cast<size_t>(c)]) > limit)
      {
        traced[static_cast<size_t>(c)] = 1;
        S.Total -= lengths[static_cast<size_t>(c)];
      }
    }
  }
}

//------------------------------------------------------------------------------
// Step 4's bookkeeping: the samples of ray-traced cells are flagged uncertain (the reference
// takes them whole); every other sample will consider its cell list and the global list.
void vtkPenumbraGearsShadows::Internals::RouteTracedCells(CallState& call)
{
  const ScratchArrays& sc = this->Scratch;
  for (const std::int32_t cell : sc.Occupied)
  {
    if (sc.Traced[static_cast<size_t>(cell)] && call.DenseTree)
    {
      call.TreeSamples += sc.SampleStart[cell + 1] - sc.SampleStart[cell];
      continue; // the tree walk counts its own assignments
    }
    if (sc.Traced[static_cast<size_t>(cell)])
    {
      for (std::uint32_t o = sc.SampleStart[cell]; o < sc.SampleStart[cell + 1]; ++o)
      {
        call.Uncertain[sc.Ids[sc.SampleOrder[o]]] = 1;
      }
      call.TracedCellSamples += sc.SampleStart[cell + 1] - sc.SampleStart[cell];
      continue;
    }
    call.Assignments += static_cast<vtkIdType>(sc.SampleStart[cell + 1] - sc.SampleStart[cell]) *
      static_cast<vtkIdType>(sc.CellStart[cell + 1] - sc.CellStart[cell] + sc.GlobalList.size());
  }
}

//------------------------------------------------------------------------------
// Samples on the light plane and in ray-traced cells go to the reference whole; undecided
// light samples one by one, with its exact rules (Wang et al. 2014, §5.1: "identical to ray
// tracing").
int vtkPenumbraGearsShadows::Internals::TraceUndecided(vtkPenumbraGearsShadows* self,
  vtkPenumbraViewSamples* samples, vtkFloatArray* visibility, CallState& call)
{
  const auto traceStart = Clock::now();
  const vtkIdType n = call.N;
  const LightSamples& ls = call.Light;
  const std::vector<signed char>& side = this->Scratch.Side;
  unsigned char* uncertain = call.Uncertain;
  float* vis = call.Vis;
  vtkIdType nWhole = 0;
  for (vtkIdType s = 0; s < n; ++s)
  {
    if (side[static_cast<size_t>(s)] == 2)
    {
      uncertain[s] = 1;
    }
    nWhole += uncertain[s];
  }
  call.UncertainSamples = nWhole - call.TracedCellSamples;
  if (nWhole > 0)
  {
    if (!self->Reference->ComputeVisibility(samples, call.Used, visibility, this->Uncertain))
    {
      PENUMBRA_FAIL_FOR(
        self, "tracing the uncertain samples failed: " << self->Reference->GetErrorMessage());
    }
  }
  const vtkIdType nTrace = static_cast<vtkIdType>(call.TraceSamples.size());
  vtkIdType withTracedRays = 0;
  if (nTrace > 0)
  {
    std::vector<unsigned char> lit(static_cast<size_t>(nTrace));
    if (!self->Reference->TraceAreaRays(samples, call.Used, nTrace, call.TraceSamples.data(),
          call.TraceLights.data(), lit.data()))
    {
      PENUMBRA_FAIL_FOR(
        self, "tracing the undecided light samples failed: " << self->Reference->GetErrorMessage());
    }
    vtkIdType previous = -1;
    for (vtkIdType i = 0; i < nTrace; ++i)
    {
      const vtkIdType s = call.TraceSamples[static_cast<size_t>(i)];
      withTracedRays += s != previous;
      previous = s;
      if (!lit[static_cast<size_t>(i)])
      {
        continue;
      }
      // vis[s] = float(lit) / float(n) with lit recovered exactly from the known part.
      const int known = static_cast<int>(std::lround(vis[s] * ls.Count));
      vis[s] = static_cast<float>(known + 1) / static_cast<float>(ls.Count);
      if (call.Masks)
      {
        const int j = call.TraceLights[static_cast<size_t>(i)];
        call.Masks[static_cast<size_t>(s) * call.Words + j / 32] |= 1u << (j % 32);
      }
    }
  }
  call.TracedRays = nTrace;
  call.SamplesWithTracedRays = withTracedRays;
  call.TraceMs = nWhole > 0 || nTrace > 0 ? ElapsedMs(traceStart) : 0.0;
  return 1;
}
