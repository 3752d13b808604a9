// Helpers shared by the technique tests of this module: light types, the pass a registry
// technique installs, a light aimed at a target, the plane-and-box scene, and the scene files.
#ifndef PenumbraTechniqueTests_h
#define PenumbraTechniqueTests_h

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCameraPass.h"
#include "vtkCubeSource.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowTechnique.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"

#include <initializer_list>
#include <iostream>
#include <string>

namespace penumbra_technique_tests
{
enum class LightType
{
  Directional,
  Spot,
  Point,
  AsInScene
};

inline const char* Name(LightType type)
{
  switch (type)
  {
    case LightType::Directional:
      return "directional";
    case LightType::Spot:
      return "spot";
    case LightType::Point:
      return "point";
    default:
      return "scene light";
  }
}

// The shadow pass a registry technique installed (camera pass -> shadow pass).
inline vtkPenumbraShadowPass* ShadowPass(vtkRenderer* renderer)
{
  return vtkPenumbraShadowPass::GetInstalled(renderer);
}

// Replaces the renderer's lights by one of `type` aimed at `target` from `from`; a spot
// light gets `spotCone` degrees (VTK's half angle).
inline void SetLight(vtkRenderer* renderer, LightType type, const double from[3],
  const double target[3], double spotCone)
{
  if (type == LightType::AsInScene)
  {
    return;
  }
  renderer->RemoveAllLights();
  vtkNew<vtkLight> light;
  light->SetLightTypeToSceneLight();
  light->SetPosition(from[0], from[1], from[2]);
  light->SetFocalPoint(target[0], target[1], target[2]);
  light->SetPositional(type != LightType::Directional);
  light->SetConeAngle(type == LightType::Spot ? spotCone : 180.0);
  renderer->AddLight(light);
}

// One actor per source, with default properties, added to `renderer`.
inline void AddSources(vtkRenderer* renderer, std::initializer_list<vtkPolyDataAlgorithm*> sources)
{
  for (auto* source : sources)
  {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(source->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    renderer->AddActor(actor);
  }
}

// Plane z = 0 (8 x 6 m) under a box occluder at z = 1 - thickness .. 1, lit from (1.5, 0.7, 3)
// towards the origin (spot lights: 35 degrees). With `zoom` a parallel camera looks straight
// down at the shadow of (0, 0, 1) through a window `zoom` metres high.
inline vtkSmartPointer<vtkRenderer> PlaneScene(
  LightType type, double thickness, double halfWidth, double zoom = 0.0)
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-4, -3, 0);
  plane->SetPoint1(4, -3, 0);
  plane->SetPoint2(-4, 3, 0);
  plane->SetResolution(8, 6);
  vtkNew<vtkCubeSource> box;
  box->SetBounds(-halfWidth, halfWidth, -0.5, 0.5, 1.0 - thickness, 1.0);
  AddSources(renderer, { plane, box });
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.5, -6, 8);
  camera->SetFocalPoint(0, 0, 0);
  camera->SetViewUp(0, 0, 1);
  renderer->ResetCamera();
  const double from[3] = { 1.5, 0.7, 3.0 };
  const double target[3] = { 0, 0, 0 };
  SetLight(renderer, type, from, target, 35.0);
  if (zoom > 0.0)
  {
    double shadow[2]; // where the shadow of (0, 0, 1) falls on z = 0
    for (int c = 0; c < 2; ++c)
    {
      shadow[c] = type == LightType::Directional ? -from[c] / from[2]
                                                 : from[c] - from[c] * from[2] / (from[2] - 1.0);
    }
    camera->ParallelProjectionOn();
    camera->SetPosition(shadow[0], shadow[1], 5);
    camera->SetFocalPoint(shadow[0], shadow[1], 0);
    camera->SetViewUp(0, 1, 0);
    camera->SetParallelScale(0.5 * zoom);
    renderer->ResetCameraClippingRange();
  }
  return renderer;
}

// Counts the warning events of an observed object (OnWarning as a vtkCallbackCommand's
// callback, the counter as its client data) and keeps the last one's text.
struct WarningCounter
{
  int Warnings = 0;
  std::string Last;
  static void OnWarning(vtkObject*, unsigned long, void* client, void* data)
  {
    auto* self = static_cast<WarningCounter*>(client);
    ++self->Warnings;
    self->Last = data ? static_cast<const char*>(data) : "";
  }
};

// A width x height window without multisampling that renders `renderer`.
inline vtkSmartPointer<vtkRenderWindow> TestWindow(vtkRenderer* renderer, int width, int height)
{
  vtkSmartPointer<vtkRenderWindow> window =
    vtkSmartPointer<vtkRenderWindow>::Take(vtkRenderWindow::New());
  window->SetSize(width, height);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  return window;
}

// True when `technique` refuses null inputs with an error (silenced here: ctest fails on
// error output) instead of crashing.
inline bool RefusesNullInputs(vtkPenumbraShadowTechnique* technique)
{
  vtkNew<vtkFloatArray> out;
  vtkNew<vtkLight> light;
  const int display = vtkObject::GetGlobalWarningDisplay();
  vtkObject::GlobalWarningDisplayOff();
  const int refused = technique->ComputeVisibility(nullptr, nullptr, nullptr, light, out);
  vtkObject::SetGlobalWarningDisplay(display);
  return refused == 0;
}

// Reads Data/Scenes/`file` (PENUMBRA_SCENES_DIR); null with a message on failure.
inline vtkSmartPointer<vtkRenderer> ReadScene(
  const std::string& file, vtkPenumbraSceneReader* reader)
{
  reader->SetFileName((std::string(PENUMBRA_SCENES_DIR) + "/" + file).c_str());
  if (!reader->Read())
  {
    std::cerr << "cannot read " << file << ": " << reader->GetErrorMessage() << std::endl;
    return nullptr;
  }
  return reader->GetRenderer();
}

// The default city scene (default.json) with its own sun (AsInScene), or with a light of
// `type` above and off the centre of the block, aimed at the centre.
inline vtkSmartPointer<vtkRenderer> DefaultSceneWith(
  LightType type, vtkPenumbraSceneReader* reader, double spotCone)
{
  vtkSmartPointer<vtkRenderer> renderer = ReadScene("default.json", reader);
  if (renderer)
  {
    double b[6];
    renderer->ComputeVisiblePropBounds(b);
    const double centre[3] = { 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]) };
    const double above[3] = { centre[0] + 0.2 * (b[1] - b[0]), centre[1] - 0.1 * (b[3] - b[2]),
      b[5] + 0.3 * (b[5] - b[4]) };
    SetLight(renderer, type, above, centre, spotCone);
  }
  return renderer;
}
}

#endif
