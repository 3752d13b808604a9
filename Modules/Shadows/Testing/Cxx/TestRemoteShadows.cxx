// The pass's hook for shadows cast by geometry this process does not hold
// (vtkPenumbraRemoteShadows, used by the ParaView view's distributed ray queries), with a fake
// "other process" that blocks the light on the strip 1 <= x <= 2 of the ground:
// - it is asked once per computed frame, after the technique, with the frame's samples, and
//   its answer is what is shaded (the strip dark, the local occluder's shadow still there);
// - a frame is reused, and the hook not asked, only when the hook agrees;
// - a process whose own props cast nothing still computes its frame when a hook is set, for
//   every exact hard-light technique;
// - an area light is not resolved, and that is said once.
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkCubeSource.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraRemoteShadows.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"

#include "PenumbraReferenceScenes.h"
#include "PenumbraTestMacros.h"

#include <string>

namespace
{
// Blocks light 0 for the samples on 1 <= x <= 2.
class OtherProcess : public vtkPenumbraRemoteShadows
{
public:
  static OtherProcess* New();
  vtkTypeMacro(OtherProcess, vtkPenumbraRemoteShadows);

  bool Resolve(vtkPenumbraSceneGeometry*, vtkPenumbraViewSamples* samples,
    const std::vector<vtkLight*>& lights, const std::vector<vtkFloatArray*>& visibilities,
    std::string&) override
  {
    ++this->Resolves;
    this->Lights = lights.size();
    this->WithValues = !visibilities.empty() && visibilities[0] != nullptr;
    if (!samples || !this->WithValues)
    {
      return true;
    }
    for (vtkIdType s = 0; s < samples->GetNumberOfSamples(); ++s)
    {
      double w[3];
      if (samples->GetWorldPosition(s, w) && w[0] >= 1.0 && w[0] <= 2.0 && w[2] < 0.5)
      {
        visibilities[0]->SetValue(s, 0.0f);
      }
    }
    return true;
  }
  bool AgreeToReuse(bool mine) override { return mine && !this->Changed; }

  int Resolves = 0;
  size_t Lights = 0;
  bool WithValues = false;
  bool Changed = true;
};
vtkStandardNewMacro(OtherProcess);

// Ground z = 0 over [-4, 4] x [-2, 2], a thin occluder over [-0.5, 0.5]^2 at z = 1, a sun
// along (-1, 0, -1), seen from above (parallel projection, 128 x 64 pixels).
struct Scene
{
  vtkNew<vtkRenderer> Renderer;
  vtkSmartPointer<vtkActor> Ground;
  vtkNew<vtkLight> Sun;
  vtkNew<vtkRenderWindow> Window;

  explicit Scene(bool occluder)
  {
    this->Ground = penumbra_test::AddRectangle(this->Renderer, -4, 4, -2, 2, 0);
    if (occluder)
    {
      vtkNew<vtkCubeSource> box;
      box->SetBounds(-0.5, 0.5, -0.5, 0.5, 0.98, 1.0);
      const double zero[3] = { 0, 0, 0 };
      penumbra_test::AddActor(this->Renderer, box, zero);
    }
    this->Sun->SetLightTypeToSceneLight();
    this->Sun->SetPositional(false);
    this->Sun->SetPosition(1, 0, 1);
    this->Sun->SetFocalPoint(0, 0, 0);
    this->Renderer->AddLight(this->Sun);
    penumbra_test::LookFromAbove(this->Renderer, 2.0);
    this->Renderer->ResetCameraClippingRange();
    this->Window->SetSize(128, 64);
    this->Window->SetMultiSamples(0);
    this->Window->AddRenderer(this->Renderer);
  }

  // Visibility of light 0 at the ground sample under world (x, 0).
  float VisibilityAt(double x)
  {
    vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(this->Renderer);
    vtkFloatArray* v = pass ? pass->GetVisibility(0) : nullptr;
    if (!v)
    {
      return -2.0f;
    }
    const int column = static_cast<int>((x + 4.0) / 8.0 * 128);
    return v->GetValue(pass->GetViewSamples()->GetSampleIndex(column, 32));
  }
};

int CheckResolved()
{
  Scene scene(true);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, "raytraced", ""));
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(scene.Renderer);
  vtkNew<OtherProcess> other;
  pass->SetRemoteShadows(other);
  scene.Window->Render();
  CHECK(other->Resolves == 1 && other->Lights == 1 && other->WithValues);
  CHECK(scene.VisibilityAt(1.5) == 0.0f);  // the other process's shadow
  CHECK(scene.VisibilityAt(-1.0) == 0.0f); // the local occluder's
  CHECK(scene.VisibilityAt(3.0) == 1.0f);
  CHECK(scene.VisibilityAt(0.5) == 1.0f);

  // Unchanged, and the hook agrees: reused, not asked. It disagrees: computed and asked.
  other->Changed = false;
  scene.Window->Render();
  CHECK(pass->GetLastFrameReused() && other->Resolves == 1);
  other->Changed = true;
  scene.Window->Render();
  CHECK(!pass->GetLastFrameReused() && other->Resolves == 2);
  CHECK(scene.VisibilityAt(1.5) == 0.0f);

  // Without the hook the strip is lit again.
  pass->SetRemoteShadows(nullptr);
  scene.Window->Render();
  CHECK(scene.VisibilityAt(1.5) == 1.0f && other->Resolves == 2);
  return EXIT_SUCCESS;
}

// A process whose props cast nothing: without a hook it has no shadow work; with one, each
// exact technique computes the frame (all lit here) and the hook's shadow is drawn.
int CheckNoLocalCasters(const char* technique)
{
  Scene scene(false);
  vtkPenumbraShadowKeys::SetCastsShadows(scene.Ground, false);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, technique, ""));
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(scene.Renderer);
  scene.Window->Render();
  CHECK(pass->GetVisibility(0) == nullptr);
  vtkNew<OtherProcess> other;
  pass->SetRemoteShadows(other);
  vtkNew<penumbra_test::ErrorCounter> errors;
  pass->AddObserver(vtkCommand::ErrorEvent, errors);
  scene.Window->Render();
  std::cout << technique << " without local casters: strip " << scene.VisibilityAt(1.5)
            << ", elsewhere " << scene.VisibilityAt(-1.0) << ", " << errors->Count << " errors "
            << errors->Last << std::endl;
  CHECK(errors->Count == 0 && other->Resolves == 1);
  CHECK(scene.VisibilityAt(1.5) == 0.0f && scene.VisibilityAt(-1.0) == 1.0f);
  return EXIT_SUCCESS;
}

int CheckAreaLightSaid()
{
  Scene scene(true);
  scene.Renderer->RemoveAllLights();
  vtkNew<vtkPenumbraAreaLight> area;
  area->SetPosition(2, 0, 3);
  area->SetFocalPoint(2, 0, 0);
  area->SetWidth(1.0);
  area->SetHeight(1.0);
  area->SetSamplesPerAxis(4);
  scene.Renderer->AddLight(area);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, "raytraced", ""));
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(scene.Renderer);
  vtkNew<OtherProcess> other;
  pass->SetRemoteShadows(other);
  vtkNew<penumbra_test::ErrorCounter> warnings;
  pass->AddObserver(vtkCommand::WarningEvent, warnings);
  scene.Window->Render();
  scene.Window->Render();
  CHECK(warnings->Count == 1 && warnings->Last.find("own casters only") != std::string::npos);
  CHECK(other->Resolves == 2 && !other->WithValues); // asked (it answers others), no values
  return EXIT_SUCCESS;
}
}

int TestRemoteShadows(int, char*[])
{
  RUN(CheckResolved());
  for (const char* technique : { "raytraced", "conservative", "llsm", "llsm-hybrid", "volumes" })
  {
    RUN(CheckNoLocalCasters(technique));
  }
  RUN(CheckAreaLightSaid());
  return EXIT_SUCCESS;
}
