// penumbra-bench --mismatch-lists: where a hard-shadow technique disagrees with the exact
// reference, sample by sample, and what is around each such sample, so that the cause of a
// mismatch rate can be read off instead of guessed (shadow boundaries, creases and
// contacts, the level rmsm looked the sample up at).

#include "PenumbraBench.h"

#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace penumbra_bench
{
namespace
{
constexpr double LitThreshold = 0.5;   // vtkPenumbraMetrics' default
constexpr int BoundaryReach = 3;       // pixels searched for a reference shadow boundary
constexpr double CreaseCosine = 0.985; // neighbours' normals more than ~10 degrees apart

struct SampleView
{
  vtkPenumbraViewSamples* Samples;
  vtkFloatArray* Reference;
  vtkUnsignedCharArray* Ties;
  int W, H;

  vtkIdType Index(int x, int y) const
  {
    return x < 0 || y < 0 || x >= this->W || y >= this->H ? -1 : static_cast<vtkIdType>(y) * W + x;
  }
  bool Measured(vtkIdType i) const
  {
    return i >= 0 && this->Reference->GetValue(i) >= 0.0f &&
      !(this->Ties && this->Ties->GetValue(i));
  }
  bool RefLit(vtkIdType i) const { return this->Reference->GetValue(i) >= LitThreshold; }

  // Chebyshev distance in pixels to the nearest measured sample whose reference answer
  // differs (a shadow boundary of the exact answer), BoundaryReach + 1 when none is that near.
  int BoundaryDistance(int x, int y) const
  {
    const bool lit = this->RefLit(this->Index(x, y));
    for (int r = 1; r <= BoundaryReach; ++r)
    {
      for (int dy = -r; dy <= r; ++dy)
      {
        for (int dx = -r; dx <= r; ++dx)
        {
          const vtkIdType j = this->Index(x + dx, y + dy);
          if (std::max(std::abs(dx), std::abs(dy)) == r && this->Measured(j) &&
            this->RefLit(j) != lit)
          {
            return r;
          }
        }
      }
    }
    return BoundaryReach + 1;
  }

  // Whether an 8-neighbour is background, another prop or a surface turned away by more than
  // ~10 degrees: a silhouette, a crease or a contact.
  bool AtCrease(int x, int y) const
  {
    const vtkIdType i = this->Index(x, y);
    const float* n = this->Samples->GetNormals()->GetPointer(3 * i);
    const int prop = this->Samples->GetPropIndices()->GetValue(i);
    for (int dy = -1; dy <= 1; ++dy)
    {
      for (int dx = -1; dx <= 1; ++dx)
      {
        const vtkIdType j = this->Index(x + dx, y + dy);
        if (j < 0 || j == i)
        {
          continue;
        }
        if (this->Reference->GetValue(j) < 0.0f ||
          this->Samples->GetPropIndices()->GetValue(j) != prop)
        {
          return true;
        }
        const float* m = this->Samples->GetNormals()->GetPointer(3 * j);
        if (n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < CreaseCosine)
        {
          return true;
        }
      }
    }
    return false;
  }
};

// Cosine between the sample's normal and the direction to the light.
double FacingCosine(vtkPenumbraViewSamples* samples, vtkIdType i, vtkLight* light)
{
  double p[3], l[3], f[3], d[3];
  samples->GetWorldPosition(i, p);
  light->GetTransformedPosition(l);
  light->GetTransformedFocalPoint(f);
  for (int c = 0; c < 3; ++c)
  {
    d[c] = light->GetPositional() ? l[c] - p[c] : l[c] - f[c];
  }
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const float* n = samples->GetNormals()->GetPointer(3 * i);
  return len > 0.0 ? (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / len : 0.0;
}
}

std::string WriteMismatchList(const std::string& path, vtkPenumbraViewSamples* samples,
  vtkFloatArray* estimate, vtkFloatArray* reference, vtkUnsignedCharArray* ties, vtkLight* light,
  vtkIntArray* levels)
{
  const SampleView view{ samples, reference, ties, samples->GetWidth(), samples->GetHeight() };
  if (!estimate || estimate->GetNumberOfTuples() != samples->GetNumberOfSamples())
  {
    return "no per-sample visibility to list";
  }
  const bool haveLevels = levels && levels->GetNumberOfTuples() == samples->GetNumberOfSamples();
  std::ofstream csv(path);
  csv << "x,y,estimate,reference,kind,boundary_px,crease,cos_light,level\n";
  // Per category (kind, boundary distance, crease): count; per level: mismatches.
  std::map<std::string, int> categories;
  std::map<int, int> perLevel;
  int total = 0;
  for (int y = 0; y < view.H; ++y)
  {
    for (int x = 0; x < view.W; ++x)
    {
      const vtkIdType i = view.Index(x, y);
      const float e = estimate->GetValue(i);
      if (!view.Measured(i) || e < 0.0f || (e >= LitThreshold) == view.RefLit(i))
      {
        continue;
      }
      const bool falseLit = e >= LitThreshold;
      const int boundary = view.BoundaryDistance(x, y);
      const bool crease = view.AtCrease(x, y);
      const int level = haveLevels ? levels->GetValue(i) : 0;
      csv << x << "," << y << "," << e << "," << reference->GetValue(i) << ","
          << (falseLit ? "false_lit" : "false_shadow") << "," << boundary << "," << crease << ","
          << FacingCosine(samples, i, light) << "," << level << "\n";
      std::ostringstream key;
      key << (falseLit ? "lit" : "shadow") << " "
          << (boundary == 1                  ? "edge1"
                 : boundary <= BoundaryReach ? "edge2-3"
                                             : "far")
          << (crease ? " crease" : " smooth");
      ++categories[key.str()];
      ++perLevel[level];
      ++total;
    }
  }
  std::ostringstream summary;
  summary << total << " mismatches:";
  for (const auto& c : categories)
  {
    summary << " [" << c.first << " " << c.second << "]";
  }
  if (haveLevels)
  {
    summary << "; by level:";
    for (const auto& l : perLevel)
    {
      summary << " " << l.first << ":" << l.second;
    }
  }
  return summary.str();
}
}
