// Shadow maps composited across processes (vtkPenumbraShadowTechnique::
// CompositesAcrossProcesses(), through the collective operations of
// vtkPenumbraRemoteShadows): a scene split over two "processes" in one program, each a
// renderer holding its piece, whose collective calls meet through recordings. Process A holds
// the ground and a small box, process B the occluder that shadows A's ground. Each round,
// each process renders with the other's recorded inputs of the round before, until neither
// recording changes (the calls' inputs depend on earlier results: the fit on the shared
// extent, the maps on the fit). Then, for the shadow-map family's variants (linear and
// midpoint depth, GPU and CPU lookup, the scene and the view fit, cube maps for a point light,
// RESM, PCSS and single-sample soft shadows on an area light):
// - A's ground shows B's shadow, which it does not without the other process;
// - every sample A sees has the visibility the one-process scene (both pieces in one
//   renderer) gives it, value for value: the composited maps are the maps of the union
//   (with the soft lookups' adaptive blocks, away from pixels where B's occluder is in
//   front: the blocks interpolate between neighbouring pixels, which differ there).
#include "vtkCamera.h"
#include "vtkCubeSource.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraRemoteShadows.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace
{
using Recording = std::vector<std::vector<double>>;

// One process's side of the collective calls: its inputs are recorded in call order, and
// each call combines them with the other process's input of the same call in its last
// recording (none yet: this process's own).
class Peer : public vtkPenumbraRemoteShadows
{
public:
  static Peer* New();
  vtkTypeMacro(Peer, vtkPenumbraRemoteShadows);

  bool Resolve(vtkPenumbraSceneGeometry*, vtkPenumbraViewSamples*, const std::vector<vtkLight*>&,
    const std::vector<vtkFloatArray*>&, std::string&) override
  {
    return true;
  }
  bool AgreeToReuse(bool) override { return false; } // every round computes its frame
  bool AllAgree(bool mine) override
  {
    const std::vector<double>* theirs = this->Step({ mine ? 1.0 : 0.0 });
    return mine && (!theirs || (theirs->size() == 1 && (*theirs)[0] != 0.0));
  }
  void ReduceMinimum(double* values, int count) override
  {
    this->Minimum(values, static_cast<size_t>(count));
  }
  void ReduceMinimum(float* values, size_t count) override { this->Minimum(values, count); }
  void GatherValues(std::vector<double>& values) override
  {
    const std::vector<double>* theirs = this->Step(values);
    if (theirs)
    {
      // Process order: A (rank 0) first.
      values.insert(
        this->Rank == 0 ? values.end() : values.begin(), theirs->begin(), theirs->end());
    }
  }

  void StartRound(const Recording& theirs)
  {
    this->Theirs = theirs;
    this->Mine.clear();
    this->Mismatch = false;
  }

  int Rank = 0;
  Recording Mine, Theirs;
  bool Mismatch = false;

private:
  const std::vector<double>* Step(const std::vector<double>& mine)
  {
    this->Mine.push_back(mine);
    const size_t i = this->Mine.size() - 1;
    return i < this->Theirs.size() ? &this->Theirs[i] : nullptr;
  }
  template <typename T>
  void Minimum(T* values, size_t count)
  {
    const std::vector<double>* theirs = this->Step(std::vector<double>(values, values + count));
    if (!theirs)
    {
      return;
    }
    if (theirs->size() != count)
    {
      this->Mismatch = true; // the processes made different calls: reported by the check
      return;
    }
    for (size_t i = 0; i < count; ++i)
    {
      values[i] = std::min(values[i], static_cast<T>((*theirs)[i]));
    }
  }
};
vtkStandardNewMacro(Peer);

struct Case
{
  const char* Technique;
  const char* Options;
  int Light;     // 0 sun, 1 point light, 2 area light
  int Block = 0; // adaptive soft lookups: their block (pixels)
};

// Ground z = 0 over [-4, 4] x [-2, 2] and a box over [2, 2.6] x [-0.3, 0.3] x [0, 0.6]
// (process A); the occluder [-0.5, 0.5]^2 at z = 1 (process B). Seen from above.
struct Process
{
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkRenderWindow> Window;

  Process(bool a, bool b, int light)
  {
    if (a)
    {
      penumbra_test::AddRectangle(this->Renderer, -4, 4, -2, 2, 0);
      vtkNew<vtkCubeSource> box;
      box->SetBounds(2.0, 2.6, -0.3, 0.3, 0.0, 0.6);
      const double zero[3] = { 0, 0, 0 };
      penumbra_test::AddActor(this->Renderer, box, zero);
    }
    if (b)
    {
      vtkNew<vtkCubeSource> box;
      box->SetBounds(-0.5, 0.5, -0.5, 0.5, 0.98, 1.0);
      const double zero[3] = { 0, 0, 0 };
      penumbra_test::AddActor(this->Renderer, box, zero);
    }
    if (light == 2)
    {
      vtkNew<vtkPenumbraAreaLight> area;
      area->SetPosition(1.5, 0, 3);
      area->SetFocalPoint(0, 0, 0);
      area->SetWidth(0.6);
      area->SetHeight(0.6);
      area->SetSamplesPerAxis(4);
      this->Renderer->AddLight(area);
    }
    else
    {
      vtkNew<vtkLight> sun;
      sun->SetLightTypeToSceneLight();
      sun->SetPositional(light == 1);
      sun->SetConeAngle(light == 1 ? 90.0 : 30.0);
      sun->SetPosition(light == 1 ? 1.0 : 1.0, 0, light == 1 ? 3.0 : 1.0);
      sun->SetFocalPoint(0, 0, 0);
      this->Renderer->AddLight(sun);
    }
    penumbra_test::LookFromAbove(this->Renderer, 2.0);
    this->Renderer->GetActiveCamera()->SetClippingRange(5.0, 15.0);
    this->Renderer->SetAutomaticLightCreation(false);
    this->Window->SetSize(128, 64);
    this->Window->SetMultiSamples(0);
    this->Window->AddRenderer(this->Renderer);
  }

  vtkPenumbraShadowPass* Pass() { return vtkPenumbraShadowPass::GetInstalled(this->Renderer); }

  bool Apply(const Case& c)
  {
    vtkNew<vtkPenumbraTechniques> techniques;
    if (!techniques->Apply(this->Renderer, c.Technique, c.Options))
    {
      return false;
    }
    // The whole scene's bounds: the rebasing origin of one process.
    const double scene[6] = { -4, 4, -2, 2, 0, 1 };
    this->Pass()->GetGeometry()->SetSceneBounds(scene);
    return true;
  }

  // Light 0's visibility and the world position of the sample at pixel (i, j); false where
  // no surface is.
  bool At(int i, int j, double w[3], float& v)
  {
    vtkPenumbraShadowPass* pass = this->Pass();
    vtkFloatArray* visibility = pass ? pass->GetVisibility(0) : nullptr;
    vtkPenumbraViewSamples* samples = pass ? pass->GetViewSamples() : nullptr;
    if (!visibility || !samples)
    {
      return false;
    }
    const vtkIdType s = samples->GetSampleIndex(i, j);
    if (!samples->GetWorldPosition(s, w))
    {
      return false;
    }
    v = visibility->GetValue(s);
    return true;
  }

  // Light 0's visibility on the ground at world (x, 0).
  float GroundAt(double x)
  {
    double w[3];
    float v = -1.0f;
    return this->At(static_cast<int>((x + 4.0) / 8.0 * 128), 32, w, v) ? v : -2.0f;
  }
};

int CheckCase(const Case& c)
{
  std::cout << c.Technique << " " << c.Options << ", light " << c.Light << std::endl;
  Process whole(true, true, c.Light);
  CHECK(whole.Apply(c));
  whole.Window->Render();

  Process a(true, false, c.Light), b(false, true, c.Light);
  CHECK(a.Apply(c) && b.Apply(c));
  CHECK(a.Pass()->GetTechnique()->CompositesAcrossProcesses());
  a.Window->Render();
  const float alone = a.GroundAt(-1.0); // B's shadow, without B
  vtkNew<Peer> pa, pb;
  pb->Rank = 1;
  a.Pass()->SetRemoteShadows(pa);
  b.Pass()->SetRemoteShadows(pb);
  bool converged = false;
  for (int round = 0; round < 8 && !converged; ++round)
  {
    const Recording lastA = pa->Mine, lastB = pb->Mine;
    pb->StartRound(lastA);
    b.Pass()->GetTechnique()->Modified(); // the maps are drawn again, with the new inputs
    b.Window->Render();
    pa->StartRound(pb->Mine);
    a.Pass()->GetTechnique()->Modified();
    a.Window->Render();
    converged = round > 0 && pa->Mine == lastA && pb->Mine == lastB;
  }
  std::cout << "  " << pa->Mine.size() << " collective calls"
            << (converged ? "" : ", not converged")
            << (pa->Mismatch || pb->Mismatch ? ", mismatched" : "") << std::endl;
  CHECK(converged && !pa->Mismatch && !pb->Mismatch);
  CHECK(pa->Mine.size() > 3); // the pass's agreement and the technique's calls

  const float shared = a.GroundAt(-1.0);
  std::cout << "  B's shadow on A's ground: alone " << alone << ", composited " << shared
            << ", one process " << whole.GroundAt(-1.0) << std::endl;
  CHECK(alone > 0.5f && shared < 0.5f);
  // The pixels where A sees what the one-process view sees.
  std::vector<char> same(128 * 64, 0);
  std::vector<float> va(128 * 64, 0.0f), vw(128 * 64, 0.0f);
  for (int j = 0; j < 64; ++j)
  {
    for (int i = 0; i < 128; ++i)
    {
      double wa[3], ww[3];
      const int p = j * 128 + i;
      same[p] = a.At(i, j, wa, va[p]) && whole.At(i, j, ww, vw[p]) &&
        std::abs(wa[2] - ww[2]) <= 1e-6; // not B's occluder in front in the one-process view
    }
  }
  // Adaptive soft lookups interpolate inside blocks of pixels whose corners agree: within a
  // block of a pixel that sees something else, the neighbours differ, not the maps.
  auto nearOther = [&](int i, int j)
  {
    for (int y = std::max(0, j - c.Block); y <= std::min(63, j + c.Block); ++y)
    {
      for (int x = std::max(0, i - c.Block); x <= std::min(127, i + c.Block); ++x)
      {
        if (!same[y * 128 + x])
        {
          return true;
        }
      }
    }
    return false;
  };
  int compared = 0, differ = 0;
  float worst = 0.0f;
  for (int j = 0; j < 64; ++j)
  {
    for (int i = 0; i < 128; ++i)
    {
      const int p = j * 128 + i;
      if (!same[p] || (c.Block > 0 && nearOther(i, j)))
      {
        continue;
      }
      ++compared;
      worst = std::max(worst, std::abs(va[p] - vw[p]));
      differ += va[p] != vw[p] ? 1 : 0;
    }
  }
  std::cout << "  " << compared << " samples compared, " << differ << " differ (largest " << worst
            << ")" << std::endl;
  CHECK(compared > 4000 && differ == 0);
  return EXIT_SUCCESS;
}
}

int TestCompositedMaps(int, char*[])
{
  const Case cases[] = {
    { "shadowmap", "", 0 },
    { "shadowmap", "{\"depth\": \"midpoint\"}", 0 },
    { "shadowmap", "{\"lookup\": \"cpu\"}", 0 },
    { "shadowmap", "{\"fit\": \"view\", \"fit_rectangle\": \"minimum\"}", 0 },
    { "shadowmap", "{\"lookup\": \"cpu\", \"depth\": \"midpoint\"}", 1 },
    { "shadowmap", "", 1 },
    { "resm", "", 0 },
    { "pcss", "{\"block\": 1}", 2 },
    { "single-sample-soft", "{\"block\": 1}", 2 },
    { "pcss", "", 2, 4 },
    { "single-sample-soft", "", 2, 4 },
  };
  for (const Case& c : cases)
  {
    if (CheckCase(c) != EXIT_SUCCESS)
    {
      return EXIT_FAILURE;
    }
  }
  return EXIT_SUCCESS;
}
