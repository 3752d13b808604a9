#include "vtkPenumbraRayTracedShadows.h"

#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkSMPTools.h"
#include "vtkTimerLog.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace
{
// The lattice of one image axis: every `block`-th pixel and the last one, so that every
// pixel lies in a block between two lattice pixels.
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

// The blocks of an image: the cells between adjacent lattice pixels, with each pixel's block
// on both axes (a pixel on a block edge belongs to the block after it, the last lattice
// pixel to the block before it).
struct Blocks
{
  std::vector<int> X, Y; // lattice pixels per axis
  std::vector<int> BlockOfX, BlockOfY;
  int Width = 0;

  Blocks(int width, int height, int block)
    : X(Lattice(width, block))
    , Y(Lattice(height, block))
    , Width(width)
  {
    BlockOfX = Owners(X, width);
    BlockOfY = Owners(Y, height);
  }
  int CountX() const { return static_cast<int>(this->X.size()) - 1; }
  int CountY() const { return static_cast<int>(this->Y.size()) - 1; }
  vtkIdType Sample(int x, int y) const { return static_cast<vtkIdType>(y) * this->Width + x; }

  static std::vector<int> Owners(const std::vector<int>& at, int size)
  {
    std::vector<int> owner(static_cast<size_t>(size), 0);
    for (size_t b = 0; b + 1 < at.size(); ++b)
    {
      for (int i = at[b]; i <= at[b + 1]; ++i)
      {
        owner[static_cast<size_t>(i)] = static_cast<int>(b);
      }
    }
    return owner;
  }
};

// 1. The samples traced first: every lattice pixel and every block's centre.
void SeedLattice(const Blocks& blocks, unsigned char* trace)
{
  for (int y : blocks.Y)
  {
    for (int x : blocks.X)
    {
      trace[blocks.Sample(x, y)] = 1;
    }
  }
  for (int by = 0; by < blocks.CountY(); ++by)
  {
    for (int bx = 0; bx < blocks.CountX(); ++bx)
    {
      trace[blocks.Sample(
        (blocks.X[bx] + blocks.X[bx + 1]) / 2, (blocks.Y[by] + blocks.Y[by + 1]) / 2)] = 1;
    }
  }
}

// The bilinear value at (x, y) from the corners of block (bx, by).
float Bilinear(const Blocks& blocks, const float* vis, int bx, int by, int x, int y)
{
  const int x0 = blocks.X[bx], x1 = blocks.X[bx + 1];
  const int y0 = blocks.Y[by], y1 = blocks.Y[by + 1];
  const float u = x1 > x0 ? static_cast<float>(x - x0) / static_cast<float>(x1 - x0) : 0.0f;
  const float v = y1 > y0 ? static_cast<float>(y - y0) / static_cast<float>(y1 - y0) : 0.0f;
  return (1 - v) * ((1 - u) * vis[blocks.Sample(x0, y0)] + u * vis[blocks.Sample(x1, y0)]) +
    v * ((1 - u) * vis[blocks.Sample(x0, y1)] + u * vis[blocks.Sample(x1, y1)]);
}

// 2. Per block: refine (1) unless every sample of the block, edges included, lies on the
// centre's prop (a surface, not the background) and the corners predict the centre within
// the tolerance.
std::vector<unsigned char> DecideBlocks(
  const Blocks& blocks, const float* vis, const int* props, float tolerance)
{
  std::vector<unsigned char> refine(static_cast<size_t>(blocks.CountX()) * blocks.CountY(), 0);
  vtkSMPTools::For(0, blocks.CountY(),
    [&](vtkIdType first, vtkIdType last)
    {
      for (int by = static_cast<int>(first); by < static_cast<int>(last); ++by)
      {
        const int y0 = blocks.Y[by], y1 = blocks.Y[by + 1];
        for (int bx = 0; bx < blocks.CountX(); ++bx)
        {
          const int x0 = blocks.X[bx], x1 = blocks.X[bx + 1];
          const int cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
          const int prop = props[blocks.Sample(cx, cy)];
          bool same = prop >= 0;
          for (int y = y0; same && y <= y1; ++y)
          {
            for (int x = x0; same && x <= x1; ++x)
            {
              same = props[blocks.Sample(x, y)] == prop;
            }
          }
          refine[static_cast<size_t>(by) * blocks.CountX() + bx] = !same ||
            std::fabs(vis[blocks.Sample(cx, cy)] - Bilinear(blocks, vis, bx, by, cx, cy)) >
              tolerance;
        }
      }
    });
  return refine;
}

// Whether any block that holds pixel (x, y) is refined: its own block, and the block before
// it on an axis where the pixel lies on its own block's first lattice line (the edge the two
// blocks share).
bool InRefinedBlock(const Blocks& blocks, const std::vector<unsigned char>& refine, int x, int y)
{
  const int bx = blocks.BlockOfX[static_cast<size_t>(x)];
  const int by = blocks.BlockOfY[static_cast<size_t>(y)];
  const int fromX = bx > 0 && x == blocks.X[static_cast<size_t>(bx)] ? bx - 1 : bx;
  const int fromY = by > 0 && y == blocks.Y[static_cast<size_t>(by)] ? by - 1 : by;
  for (int oy = fromY; oy <= by; ++oy)
  {
    for (int ox = fromX; ox <= bx; ++ox)
    {
      if (refine[static_cast<size_t>(oy) * blocks.CountX() + ox])
      {
        return true;
      }
    }
  }
  return false;
}

// 3. The samples to trace now (mask 1): those of refined blocks not traced yet. Returns how
// many samples with a surface are traced in all.
vtkIdType MarkRefined(const Blocks& blocks, int height, const std::vector<unsigned char>& refine,
  const int* props, unsigned char* trace)
{
  vtkIdType traced = 0;
  for (int y = 0; y < height; ++y)
  {
    for (int x = 0; x < blocks.Width; ++x)
    {
      const vtkIdType s = blocks.Sample(x, y);
      const bool first = trace[s] != 0;
      trace[s] = !first && InRefinedBlock(blocks, refine, x, y) ? 1 : 0;
      traced += props[s] >= 0 && (first || trace[s]) ? 1 : 0;
    }
  }
  return traced;
}

// 4. Every sample neither traced in step 1 nor in a refined block, from its block's corners.
// `trace` still marks step 3's samples; step 1's are the lattice and the block centres.
void Interpolate(const Blocks& blocks, int height, const std::vector<unsigned char>& refine,
  const unsigned char* trace, float* vis)
{
  vtkSMPTools::For(0, height,
    [&](vtkIdType first, vtkIdType last)
    {
      for (int y = static_cast<int>(first); y < static_cast<int>(last); ++y)
      {
        const int by = blocks.BlockOfY[static_cast<size_t>(y)];
        const bool latticeY =
          y == blocks.Y[static_cast<size_t>(by)] || y == blocks.Y[static_cast<size_t>(by) + 1];
        for (int x = 0; x < blocks.Width; ++x)
        {
          const int bx = blocks.BlockOfX[static_cast<size_t>(x)];
          const bool latticeX =
            x == blocks.X[static_cast<size_t>(bx)] || x == blocks.X[static_cast<size_t>(bx) + 1];
          const bool centre =
            x == (blocks.X[static_cast<size_t>(bx)] + blocks.X[static_cast<size_t>(bx) + 1]) / 2 &&
            y == (blocks.Y[static_cast<size_t>(by)] + blocks.Y[static_cast<size_t>(by) + 1]) / 2;
          if (trace[blocks.Sample(x, y)] || (latticeX && latticeY) || centre ||
            refine[static_cast<size_t>(by) * blocks.CountX() + bx])
          {
            continue;
          }
          vis[blocks.Sample(x, y)] = Bilinear(blocks, vis, bx, by, x, y);
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
  const double start = vtkTimerLog::GetUniversalTime();
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
  this->LastTimeMs = 1000.0 * (vtkTimerLog::GetUniversalTime() - start);
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

// Brabec 2003, ch. 11.3 (see the class description): 1. the exact visibility at the lattice
// and the block centres; 2. per block, interpolate or refine; 3. the exact visibility at
// every other sample of a refined block; 4. the rest bilinearly from its block's corners.
int vtkPenumbraRayTracedShadows::ComputeAdaptive(
  vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility)
{
  const int width = samples->GetWidth(), height = samples->GetHeight();
  const vtkIdType n = samples->GetNumberOfSamples();
  if (width < 2 || height < 2 || n != static_cast<vtkIdType>(width) * height)
  {
    return this->Reference->ComputeVisibility(samples, light, visibility);
  }
  const Blocks blocks(width, height, this->AdaptiveBlock);
  vtkNew<vtkUnsignedCharArray> mask;
  mask->SetNumberOfTuples(n);
  unsigned char* trace = mask->GetPointer(0);
  std::fill(trace, trace + n, 0);
  SeedLattice(blocks, trace);
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  if (!this->Reference->ComputeVisibility(samples, light, visibility, mask)) // 1.
  {
    return 0;
  }
  const int* props = samples->GetPropIndices()->GetPointer(0);
  const std::vector<unsigned char> refine = DecideBlocks(blocks, visibility->GetPointer(0), props,
    static_cast<float>(this->AdaptiveTolerance)); // 2.
  const vtkIdType traced = MarkRefined(blocks, height, refine, props, trace);
  if (!this->Reference->ComputeVisibility(samples, light, visibility, mask)) // 3.
  {
    return 0;
  }
  Interpolate(blocks, height, refine, trace, visibility->GetPointer(0)); // 4.
  vtkIdType valid = 0;
  for (vtkIdType s = 0; s < n; ++s)
  {
    valid += props[s] >= 0;
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
