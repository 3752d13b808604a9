#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraStatistics.h"

#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkSMPTools.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace
{
// The lattice of one image axis: every `block`-th pixel and the last one, so that every
// pixel lies between two lattice pixels.
std::vector<int> Lattice(int size, int block)
{
  std::vector<int> at;
  for (int i = 0; i < size; i += block)
  {
    at.push_back(i);
  }
  if (at.back() != size - 1)
  {
    at.push_back(size - 1);
  }
  return at;
}

// A block of the image between lattice pixels (corners included). Its samples are the closed
// rectangle; it owns the half-open one [X0, X1) x [Y0, Y1), closed on the image's last column
// and row, so that the blocks of a refinement own every sample once.
struct Block
{
  int X0, Y0, X1, Y1;
  int CentreX() const { return (this->X0 + this->X1) / 2; }
  int CentreY() const { return (this->Y0 + this->Y1) / 2; }
};

struct Image
{
  int Width, Height;
  vtkIdType Sample(int x, int y) const { return static_cast<vtkIdType>(y) * this->Width + x; }
  int OwnedX1(const Block& b) const { return b.X1 == this->Width - 1 ? b.X1 : b.X1 - 1; }
  int OwnedY1(const Block& b) const { return b.Y1 == this->Height - 1 ? b.Y1 : b.Y1 - 1; }
};

std::vector<Block> TopBlocks(const Image& image, int block)
{
  const std::vector<int> xs = Lattice(image.Width, block), ys = Lattice(image.Height, block);
  std::vector<Block> blocks;
  for (size_t j = 0; j + 1 < ys.size(); ++j)
  {
    for (size_t i = 0; i + 1 < xs.size(); ++i)
    {
      blocks.push_back({ xs[i], ys[j], xs[i + 1], ys[j + 1] });
    }
  }
  return blocks;
}

// Marks the blocks' corners and centres that are not traced yet.
void Seed(const Image& image, const std::vector<Block>& blocks, const unsigned char* done,
  unsigned char* trace)
{
  for (const Block& b : blocks)
  {
    for (const vtkIdType s :
      { image.Sample(b.X0, b.Y0), image.Sample(b.X1, b.Y0), image.Sample(b.X0, b.Y1),
        image.Sample(b.X1, b.Y1), image.Sample(b.CentreX(), b.CentreY()) })
    {
      trace[s] = done[s] ? 0 : 1;
    }
  }
}

// The bilinear value at (x, y) from the block's corners.
float Bilinear(const Image& image, const Block& b, const float* vis, int x, int y)
{
  const float u =
    b.X1 > b.X0 ? static_cast<float>(x - b.X0) / static_cast<float>(b.X1 - b.X0) : 0.0f;
  const float v =
    b.Y1 > b.Y0 ? static_cast<float>(y - b.Y0) / static_cast<float>(b.Y1 - b.Y0) : 0.0f;
  return (1 - v) * ((1 - u) * vis[image.Sample(b.X0, b.Y0)] + u * vis[image.Sample(b.X1, b.Y0)]) +
    v * ((1 - u) * vis[image.Sample(b.X0, b.Y1)] + u * vis[image.Sample(b.X1, b.Y1)]);
}

// Per block: 1 (refine) unless every sample of the block, edges included, lies on the
// centre's prop (a surface, not the background) and the corners predict the traced centre
// within the tolerance.
std::vector<unsigned char> Decide(const Image& image, const std::vector<Block>& blocks,
  const float* vis, const int* props, float tolerance)
{
  std::vector<unsigned char> refine(blocks.size(), 0);
  vtkSMPTools::For(0, static_cast<vtkIdType>(blocks.size()),
    [&](vtkIdType first, vtkIdType last)
    {
      for (vtkIdType i = first; i < last; ++i)
      {
        const Block& b = blocks[static_cast<size_t>(i)];
        const vtkIdType centre = image.Sample(b.CentreX(), b.CentreY());
        const int prop = props[centre];
        bool same = prop >= 0;
        for (int y = b.Y0; same && y <= b.Y1; ++y)
        {
          for (int x = b.X0; same && x <= b.X1; ++x)
          {
            same = props[image.Sample(x, y)] == prop;
          }
        }
        refine[static_cast<size_t>(i)] = !same ||
          std::fabs(vis[centre] - Bilinear(image, b, vis, b.CentreX(), b.CentreY())) > tolerance;
      }
    });
  return refine;
}

// The four (or two) halves of a block, along the axes at least 4 pixels long; none when
// neither is (the block is then traced whole).
std::vector<Block> Split(const Block& b)
{
  const bool splitX = b.X1 - b.X0 >= 4, splitY = b.Y1 - b.Y0 >= 4;
  const int xs[3] = { b.X0, splitX ? b.CentreX() : b.X1, b.X1 };
  const int ys[3] = { b.Y0, splitY ? b.CentreY() : b.Y1, b.Y1 };
  std::vector<Block> halves;
  if (!splitX && !splitY)
  {
    return halves;
  }
  for (int j = 0; j < (splitY ? 2 : 1); ++j)
  {
    for (int i = 0; i < (splitX ? 2 : 1); ++i)
    {
      halves.push_back({ xs[i], ys[j], xs[i + 1], ys[j + 1] });
    }
  }
  return halves;
}

// Every sample a block owns that is not traced, from the block's corners.
void Interpolate(
  const Image& image, const std::vector<Block>& leaves, const unsigned char* done, float* vis)
{
  vtkSMPTools::For(0, static_cast<vtkIdType>(leaves.size()),
    [&](vtkIdType first, vtkIdType last)
    {
      for (vtkIdType i = first; i < last; ++i)
      {
        const Block& b = leaves[static_cast<size_t>(i)];
        for (int y = b.Y0; y <= image.OwnedY1(b); ++y)
        {
          for (int x = b.X0; x <= image.OwnedX1(b); ++x)
          {
            const vtkIdType s = image.Sample(x, y);
            if (!done[s])
            {
              vis[s] = Bilinear(image, b, vis, x, y);
            }
          }
        }
      }
    });
}
}

vtkStandardNewMacro(vtkPenumbraRayTracedShadows);

vtkPenumbraRayTracedShadows::vtkPenumbraRayTracedShadows()
  : Reference(vtkPenumbraReference::New())
{
}

vtkPenumbraRayTracedShadows::~vtkPenumbraRayTracedShadows()
{
  this->Reference->Delete();
}

int vtkPenumbraRayTracedShadows::ComputeVisibility(vtkRenderer*, vtkPenumbraSceneGeometry* geometry,
  vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility)
{
  const auto start = penumbra::Clock::now();
  this->TracedFraction = -1.0;
  // SetGeometry rebuilds the acceleration structure only when the geometry changed.
  this->Reference->SetGeometry(geometry);
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  int ok = 0;
  if (area && this->SamplesPerAxis > 0 && this->SamplesPerAxis != area->GetSamplesPerAxis())
  {
    // A copy of the light with the requested k: the positions follow the light's own rule.
    vtkPenumbraAreaLight* copy = vtkPenumbraAreaLight::SafeDownCast(area->ShallowClone());
    copy->SetSamplesPerAxis(this->SamplesPerAxis);
    ok = this->AdaptiveBlock > 1 ? this->ComputeAdaptive(samples, copy, visibility)
                                 : this->Reference->ComputeVisibility(samples, copy, visibility);
    copy->Delete();
  }
  else
  {
    ok = area && this->AdaptiveBlock > 1
      ? this->ComputeAdaptive(samples, light, visibility)
      : this->Reference->ComputeVisibility(samples, light, visibility);
  }
  this->LastTimeMs = penumbra::ElapsedMs(start);
  return ok;
}

void vtkPenumbraRayTracedShadows::SetAdaptiveBlock(int block)
{
  block = block <= 1 ? 0 : std::min(block, 16);
  if (block != this->AdaptiveBlock)
  {
    this->AdaptiveBlock = block;
    this->Modified();
  }
}

// Brabec 2003, ch. 11.3 (see the class description), as a quadtree: the exact visibility at
// the corners and centres of the top blocks; a block the corners cannot predict is split in
// four and its children's corners and centres are traced, down to blocks of 2 pixels, which
// are traced whole; every other sample is interpolated from the block that owns it.
int vtkPenumbraRayTracedShadows::ComputeAdaptive(
  vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility)
{
  const Image image = { samples->GetWidth(), samples->GetHeight() };
  const vtkIdType n = samples->GetNumberOfSamples();
  // Samples that are not one image of Width x Height (or too small to have blocks) are
  // traced whole: exact, only without the saving.
  if (image.Width < 2 || image.Height < 2 ||
    n != static_cast<vtkIdType>(image.Width) * image.Height)
  {
    return this->Reference->ComputeVisibility(samples, light, visibility);
  }
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  vtkNew<vtkUnsignedCharArray> mask;
  mask->SetNumberOfTuples(n);
  unsigned char* trace = mask->GetPointer(0);
  std::fill(trace, trace + n, 0);
  std::vector<unsigned char> done(static_cast<size_t>(n), 0);
  const int* props = samples->GetPropIndices()->GetPointer(0);
  const float tolerance = static_cast<float>(this->AdaptiveTolerance);
  // Traces the marked samples and moves the marks into `done`.
  auto traceMarked = [&]()
  {
    const bool ok = this->Reference->ComputeVisibility(samples, light, visibility, mask) != 0;
    for (vtkIdType s = 0; s < n; ++s)
    {
      done[static_cast<size_t>(s)] |= trace[s];
      trace[s] = 0;
    }
    return ok;
  };
  std::vector<Block> level = TopBlocks(image, this->AdaptiveBlock), leaves;
  Seed(image, level, done.data(), trace);
  while (!level.empty())
  {
    if (!traceMarked())
    {
      return 0;
    }
    const std::vector<unsigned char> refine =
      Decide(image, level, visibility->GetPointer(0), props, tolerance);
    std::vector<Block> next;
    for (size_t i = 0; i < level.size(); ++i)
    {
      const std::vector<Block> halves = refine[i] ? Split(level[i]) : std::vector<Block>();
      if (!refine[i])
      {
        leaves.push_back(level[i]);
      }
      else if (halves.empty())
      {
        for (int y = level[i].Y0; y <= level[i].Y1; ++y) // too small to split: traced whole
        {
          std::fill(
            trace + image.Sample(level[i].X0, y), trace + image.Sample(level[i].X1, y) + 1, 1);
        }
      }
      next.insert(next.end(), halves.begin(), halves.end());
    }
    Seed(image, next, done.data(), trace);
    level.swap(next);
  }
  if (!traceMarked())
  {
    return 0;
  }
  Interpolate(image, leaves, done.data(), visibility->GetPointer(0));
  vtkIdType valid = 0, traced = 0;
  for (vtkIdType s = 0; s < n; ++s)
  {
    valid += props[s] >= 0;
    traced += props[s] >= 0 && done[static_cast<size_t>(s)];
  }
  this->TracedFraction = valid > 0 ? static_cast<double>(traced) / valid : 0.0;
  visibility->Modified();
  return 1;
}

void vtkPenumbraRayTracedShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SamplesPerAxis: " << this->SamplesPerAxis << "\n";
  os << indent << "AdaptiveBlock: " << this->AdaptiveBlock << "\n";
  os << indent << "AdaptiveTolerance: " << this->AdaptiveTolerance << "\n";
}

//------------------------------------------------------------------------------
const char* vtkPenumbraRayTracedShadows::GetTechniqueNameFor(vtkLight* light)
{
  return vtkPenumbraAreaLight::SafeDownCast(light) ? this->GetTechniqueName() : "raytraced";
}

//------------------------------------------------------------------------------
void vtkPenumbraRayTracedShadows::GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  vtkPenumbraReference* r = this->Reference;
  stats->Set("rays", static_cast<double>(r->GetNumberOfRays()));
  stats->Set("ties", static_cast<double>(r->GetNumberOfTies()));
  stats->Set("scene_builds", r->GetNumberOfBuilds());
  stats->Set("scene_build_ms", r->GetLastBuildTimeMs());
}
