// vtkPenumbraLinkedListShadows: the per-texel lists of the view samples (Johnson et al. 2005;
// Ferko 2014), built on the CPU or with the GPU's compute path.

#include "vtkPenumbraLinkedListInternals.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"

#include <algorithm>

using namespace penumbra_llsm;

namespace penumbra_llsm
{
// Projects the view's pending samples into its grid: `texel` and `depth` per listable sample
// (appended to `listed`, ascending); a sample outside the grid or behind the apex, or on a
// positional light, is left to the tracer (Pending). Only the view's samples of `pending`
// (the call's pending samples, ascending; the hybrid's few) are projected.
void ProjectSamples(const View& view, int size, signed char viewIndex,
  const std::vector<signed char>& sampleView, const TestContext& ctx,
  const std::vector<vtkIdType>& pending, std::vector<vtkIdType>& texel, std::vector<double>& depth,
  std::vector<float>& point, std::vector<vtkIdType>& listed)
{
  std::vector<vtkIdType> candidates;
  for (vtkIdType s : pending)
  {
    if (sampleView[static_cast<size_t>(s)] == viewIndex)
    {
      candidates.push_back(s);
    }
  }
  vtkSMPTools::For(0, static_cast<vtkIdType>(candidates.size()),
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        const vtkIdType s = candidates[static_cast<size_t>(i)];
        texel[static_cast<size_t>(s)] = -1;
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
        point[2 * static_cast<size_t>(s)] = static_cast<float>((ms * 0.5 + 0.5) * size);
        point[2 * static_cast<size_t>(s) + 1] = static_cast<float>((mt * 0.5 + 0.5) * size);
      }
    });
  for (vtkIdType s : candidates)
  {
    if (texel[static_cast<size_t>(s)] >= 0)
    {
      listed.push_back(s);
    }
  }
}

void Lists::Reserve(int size)
{
  const size_t texels = static_cast<size_t>(size) * size;
  if (this->Head.size() != texels)
  {
    this->Head.assign(texels, NoNode);
    this->Active.assign(texels, 0);
  }
}

// CPU: lists the `count` samples from `first` (texel per sample in `texel`).
void Lists::BuildOnCPU(
  int size, const vtkIdType* first, vtkIdType count, const std::vector<vtkIdType>& texel)
{
  const size_t texels = static_cast<size_t>(size) * size;
  this->Reserve(size);
  this->Nodes.resize(2 * static_cast<size_t>(count));
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
      const size_t j = static_cast<size_t>(this->Counts[static_cast<size_t>(texelOf(i))]++);
      this->Nodes[2 * j] = static_cast<std::uint32_t>(first[i]);
      this->NodeTexel[j] = static_cast<std::uint32_t>(texelOf(i));
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
      this->NodeTexel[j] = static_cast<std::uint32_t>(pairs[j].first);
      this->Nodes[2 * j] = static_cast<std::uint32_t>(pairs[j].second);
    }
  }
  // Link each node to the next of its texel; the first of a run is the texel's head.
  for (size_t j = 0; j < this->NodeTexel.size(); ++j)
  {
    const std::uint32_t t = this->NodeTexel[j];
    const bool last = j + 1 == this->NodeTexel.size() || this->NodeTexel[j + 1] != t;
    this->Nodes[2 * j + 1] = last ? NoNode : static_cast<std::uint32_t>(j + 1);
    if (j == 0 || this->NodeTexel[j - 1] != t)
    {
      this->Head[t] = static_cast<std::uint32_t>(j);
    }
  }
}

// GPU: links the view's samples of `listed` still Pending, at most `capacity` (the node
// pool) of them; the others stay Pending for a further pass. `overflow`: the pool was too
// small (the counter went beyond it).
bool Lists::BuildOnGPU(ListCompute& compute, int size, const std::vector<vtkIdType>& listed,
  vtkIdType capacity, const std::vector<vtkIdType>& texel, const unsigned char* state,
  bool& overflow, std::string& why)
{
  this->Reserve(size);
  this->Items.clear();
  for (vtkIdType s : listed)
  {
    if (state[s] == Pending)
    {
      this->Items.push_back(static_cast<std::uint32_t>(s));
      this->Items.push_back(static_cast<std::uint32_t>(texel[static_cast<size_t>(s)]));
    }
  }
  std::uint32_t requested = 0;
  if (!compute.Link(this->Items.data(), this->Items.size() / 2, this->Head.size(),
        static_cast<size_t>(capacity), this->Nodes, requested, why))
  {
    return false;
  }
  overflow = requested > capacity;
  const size_t count = this->Nodes.size() / 2;
  this->NodeTexel.resize(count);
  for (size_t j = 0; j < count; ++j)
  {
    this->NodeTexel[j] = static_cast<std::uint32_t>(texel[this->Nodes[2 * j]]);
  }
  if (!compute.Heads(this->NodeTexel, this->TexelHeads, why))
  {
    return false;
  }
  for (size_t j = 0; j < count; ++j)
  {
    this->Head[this->NodeTexel[j]] = this->TexelHeads[j];
  }
  return true;
}

// After either build: marks the listed samples open and their texels active, collects the
// pass's samples; returns the longest list, and the non-empty texels in `rows`.
vtkIdType Lists::Finish(unsigned char* state, vtkIdType& rows)
{
  const size_t count = this->NodeTexel.size();
  this->Samples.resize(count);
  vtkIdType longest = 0;
  rows = 0;
  for (size_t j = 0; j < count; ++j)
  {
    const std::uint32_t t = this->NodeTexel[j];
    this->Samples[j] = static_cast<vtkIdType>(this->Nodes[2 * j]);
    state[this->Samples[j]] = Open;
    this->Active[t] = 1;
    if (this->Head[t] == j)
    {
      vtkIdType length = 0;
      for (std::uint32_t k = this->Head[t]; k != NoNode; k = this->Nodes[2 * k + 1])
      {
        ++length;
      }
      longest = std::max(longest, length);
      ++rows;
    }
  }
  return longest;
}

// Empties the texels of the last build.
void Lists::Clear()
{
  for (std::uint32_t t : this->NodeTexel)
  {
    this->Head[t] = NoNode;
    this->Active[t] = 0;
  }
}
}

//------------------------------------------------------------------------------
// The list path of this call: the GPU when asked for and its context runs compute shaders
// (sample ids must fit its 32-bit nodes), else the CPU.
void vtkPenumbraLinkedListShadows::Internals::ChooseListPath(
  vtkPenumbraLinkedListShadows* self, vtkRenderer* renderer, vtkIdType n)
{
  this->UseGpu = false;
  if (self->ListBuilder != LISTS_GPU)
  {
    return;
  }
  std::string why;
  auto* window =
    renderer ? vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow()) : nullptr;
  if (n >= static_cast<vtkIdType>(NoNode))
  {
    why = "more view samples than 32-bit node links can name";
  }
  else if (self->Resolution > 4096)
  {
    why = "a grid beyond 4096^2 texels";
  }
  else
  {
    this->UseGpu = this->Compute.Prepare(window, why);
  }
  if (!this->UseGpu)
  {
    this->ReportListPath(self, why);
  }
}

//------------------------------------------------------------------------------
void vtkPenumbraLinkedListShadows::Internals::ReportListPath(
  vtkPenumbraLinkedListShadows* self, const std::string& why)
{
  // Said once per reason: the CPU lists give the same answer, so rendering goes on.
  if (why != this->ReportedProblem)
  {
    this->ReportedProblem = why;
    vtkErrorWithObjectMacro(self,
      "GPU list construction (lists \"gpu\") cannot run: " << why << "; the CPU builds the lists");
  }
  this->UseGpu = false;
}

//------------------------------------------------------------------------------
// One pass's lists of the view's samples still pending: on the GPU (a pool of `capacity`
// nodes; the samples beyond it stay pending), or on the CPU (the first `capacity` pending).
// Returns false when nothing was pending.
bool vtkPenumbraLinkedListShadows::Internals::BuildPass(vtkPenumbraLinkedListShadows* self,
  int view, vtkIdType capacity, unsigned char* state, vtkIdType& rows)
{
  bool built = false;
  if (this->UseGpu)
  {
    std::string why;
    bool overflow = false;
    built = this->Grid.BuildOnGPU(
      this->Compute, self->Resolution, this->Listed, capacity, this->Texel, state, overflow, why);
    if (!built)
    {
      this->ReportListPath(self, why);
    }
    self->NumberOfOverflows += overflow ? 1 : 0;
  }
  if (!built)
  {
    this->Pick.clear();
    for (size_t i = 0;
         i < this->Listed.size() && static_cast<vtkIdType>(this->Pick.size()) < capacity; ++i)
    {
      if (state[this->Listed[i]] == Pending)
      {
        this->Pick.push_back(this->Listed[i]);
      }
    }
    this->Grid.BuildOnCPU(
      self->Resolution, this->Pick.data(), static_cast<vtkIdType>(this->Pick.size()), this->Texel);
  }
  vtkIdType passRows = 0;
  self->MaxListLength = std::max(self->MaxListLength, this->Grid.Finish(state, passRows));
  rows += passRows;
  if (self->RecordLists)
  {
    for (size_t j = 0; j < this->Grid.Samples.size(); ++j)
    {
      const vtkIdType entry[3] = { view, this->Grid.NodeTexel[j], this->Grid.Samples[j] };
      this->Recorded->InsertNextTypedTuple(entry);
    }
  }
  return !this->Grid.Samples.empty();
}
