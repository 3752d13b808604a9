// vtkPenumbraShadowPass end to end, headless, with the ray-traced technique: the view samples
// land where geometry says, the visibility of a known occluder matches its exact footprint,
// and the shading applies it to Phong and PBR receivers in square and wide windows while
// translucent props stay drawn. Lights that are off or black and props that do not receive
// get no shadow; unchanged geometry is not extracted or indexed again.
#include "vtkActor.h"
#include "vtkCallbackCommand.h"
#include "vtkCamera.h"
#include "vtkCameraPass.h"
#include "vtkCommand.h"
#include "vtkCompositeDataDisplayAttributes.h"
#include "vtkCompositePolyDataMapper2.h"
#include "vtkCubeSource.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowMapPass.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPlaneSource.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderPassCollection.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSequencePass.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkUnsignedCharArray.h"

#include "PenumbraTestMacros.h"

#include <cmath>
#include <string>

namespace
{
struct Scene
{
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkActor> Plane;
  vtkNew<vtkActor> Occluder;
  vtkNew<vtkLight> Light;
  vtkSmartPointer<vtkRenderWindow> Window;

  // Plane z = 0 over [-4, 4] x [-2, 2]; thin square occluder [-0.5, 0.5]^2 at z = 1; light
  // travelling along (-1, 0, -1). Seen from straight above (parallel, scale 2) the visible
  // shadow is exactly x in [-1.5, -0.5], y in [-0.5, 0.5]: the box's own thickness shifts
  // part of it under the occluder, where the camera cannot see.
  Scene(int width, int height)
  {
    vtkNew<vtkPlaneSource> plane;
    plane->SetOrigin(-4, -2, 0);
    plane->SetPoint1(4, -2, 0);
    plane->SetPoint2(-4, 2, 0);
    plane->SetResolution(8, 4);
    vtkNew<vtkCubeSource> box;
    box->SetBounds(-0.5, 0.5, -0.5, 0.5, 0.98, 1.0);
    vtkActor* actors[] = { this->Plane, this->Occluder };
    vtkPolyDataAlgorithm* sources[] = { plane, box };
    for (int i = 0; i < 2; ++i)
    {
      vtkNew<vtkPolyDataMapper> mapper;
      mapper->SetInputConnection(sources[i]->GetOutputPort());
      actors[i]->SetMapper(mapper);
      actors[i]->GetProperty()->SetAmbient(0.1);
      actors[i]->GetProperty()->SetDiffuse(0.9);
      actors[i]->GetProperty()->SetSpecular(0.0);
      this->Renderer->AddActor(actors[i]);
    }
    this->Light->SetLightTypeToSceneLight();
    this->Light->SetPositional(false);
    this->Light->SetPosition(1, 0, 1);
    this->Light->SetFocalPoint(0, 0, 0);
    this->Renderer->AddLight(this->Light);
    this->Renderer->SetBackground(0, 0, 0);
    vtkCamera* cam = this->Renderer->GetActiveCamera();
    cam->ParallelProjectionOn();
    cam->SetPosition(0, 0, 10);
    cam->SetFocalPoint(0, 0, 0);
    cam->SetViewUp(0, 1, 0);
    cam->SetParallelScale(2.0);
    this->Renderer->ResetCameraClippingRange();
    this->Window = vtkSmartPointer<vtkRenderWindow>::Take(vtkRenderWindow::New());
    this->Window->SetSize(width, height);
    this->Window->SetMultiSamples(0);
    this->Window->AddRenderer(this->Renderer);
  }

  vtkPenumbraShadowPass* Pass() { return vtkPenumbraShadowPass::GetInstalled(this->Renderer); }

  double Luminance(double x, double y)
  {
    int* size = this->Window->GetSize();
    const double pixel = 4.0 / size[1]; // world units per pixel
    const int col = static_cast<int>((x + 0.5 * size[0] * pixel) / pixel);
    const int row = static_cast<int>((y + 2.0) / pixel);
    vtkNew<vtkUnsignedCharArray> px;
    this->Window->GetPixelData(col, row, col, row, 0, px);
    const unsigned char* p = px->GetPointer(0);
    return (p[0] + p[1] + p[2]) / 3.0;
  }
};

// Samples on the plane (prop 0 in the geometry) that the light does not reach.
vtkIdType ShadowedPlaneSamples(vtkPenumbraShadowPass* pass)
{
  vtkPenumbraViewSamples* samples = pass->GetViewSamples();
  vtkFloatArray* vis = pass->GetVisibility(0);
  if (!vis)
  {
    return -1;
  }
  int planeIndex = -1;
  for (int i = 0; i < pass->GetGeometry()->GetNumberOfProps(); ++i)
  {
    if (pass->GetGeometry()->GetProp(i)->GetBounds()[5] < 0.5)
    {
      planeIndex = i;
    }
  }
  vtkIdType count = 0;
  for (vtkIdType i = 0; i < samples->GetNumberOfSamples(); ++i)
  {
    if (samples->GetPropIndices()->GetValue(i) == planeIndex && vis->GetValue(i) == 0.0f)
    {
      ++count;
    }
  }
  return count;
}

int CheckFootprint(int width, int height)
{
  Scene scene(width, height);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, "raytraced", ""));
  scene.Window->Render();
  vtkPenumbraShadowPass* pass = scene.Pass();
  CHECK(pass != nullptr);
  CHECK(pass->GetNumberOfLights() == 1);

  // Samples: positions on the plane are the pixel centres, normals face up.
  vtkPenumbraViewSamples* samples = pass->GetViewSamples();
  CHECK(samples->GetWidth() == width && samples->GetHeight() == height);
  const double pixel = 4.0 / height;
  double origin[3];
  samples->GetOrigin(origin);
  const vtkIdType center = (height / 2 + 3) * width + width / 4 + 5;
  CHECK(samples->IsValid(center));
  float* p = samples->GetPositions()->GetPointer(3 * center);
  const double wantX = -0.5 * width * pixel + (width / 4 + 5 + 0.5) * pixel;
  const double wantY = -2.0 + (height / 2 + 3 + 0.5) * pixel;
  CHECK(std::fabs(p[0] + origin[0] - wantX) < 1e-4 && std::fabs(p[1] + origin[1] - wantY) < 1e-4);
  CHECK(std::fabs(p[2] + origin[2]) < 1e-4);
  CHECK(samples->GetNormals()->GetPointer(3 * center)[2] > 0.999f);
  CHECK(samples->GetTriangleIds()->GetValue(center) >= 0);

  // Exact footprint: 1 x 1 world units = (1/pixel)^2 samples, every one shadowed, no other.
  const vtkIdType expected =
    static_cast<vtkIdType>(std::lround(1.0 / pixel) * std::lround(1.0 / pixel));
  const vtkIdType shadowed = ShadowedPlaneSamples(pass);
  std::cout << width << "x" << height << ": shadowed plane samples " << shadowed << " expected "
            << expected << std::endl;
  CHECK(shadowed == expected);

  // The image shows it: dark in the footprint, lit beside it.
  CHECK(scene.Luminance(-1.0, 0.0) < 40.0);
  CHECK(scene.Luminance(1.2, 0.0) > 150.0);
  CHECK(scene.Luminance(-1.0, 1.2) > 150.0);

  // Nothing changed: no re-extraction, no rebuild of the ray tracer's structure.
  auto* tracer = vtkPenumbraRayTracedShadows::SafeDownCast(pass->GetTechnique());
  const int builds = tracer->GetReference()->GetNumberOfBuilds();
  scene.Window->Render();
  CHECK(pass->GetGeometry()->GetNumberOfPropsExtractedLastUpdate() == 0);
  CHECK(tracer->GetReference()->GetNumberOfBuilds() == builds);
  CHECK(ShadowedPlaneSamples(pass) == expected);
  return EXIT_SUCCESS;
}

int CheckReceiversAndLights()
{
  Scene scene(128, 128);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, "raytraced", ""));

  // PBR receiver: the shadow darkens it too.
  scene.Plane->GetProperty()->SetInterpolationToPBR();
  scene.Plane->GetProperty()->SetRoughness(0.6);
  scene.Plane->GetProperty()->SetMetallic(0.0);
  // A translucent sphere beside the footprint must still be drawn.
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(1.2, -1.2, 0.5);
  sphere->SetRadius(0.4);
  vtkNew<vtkPolyDataMapper> sphereMapper;
  sphereMapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> glass;
  glass->SetMapper(sphereMapper);
  glass->GetProperty()->SetColor(1, 0, 0);
  glass->GetProperty()->SetOpacity(0.5);
  scene.Renderer->AddActor(glass);
  scene.Window->Render();
  const double pbrShadow = scene.Luminance(-1.0, 0.0);
  const double pbrLit = scene.Luminance(1.5, 0.5);
  std::cout << "PBR shadowed " << pbrShadow << " lit " << pbrLit << std::endl;
  CHECK(pbrLit > 2.5 * pbrShadow + 20.0);
  {
    int* size = scene.Window->GetSize();
    const int col = static_cast<int>((1.2 + 2.0) / 4.0 * size[0]);
    const int row = static_cast<int>((-1.2 + 2.0) / 4.0 * size[1]);
    vtkNew<vtkUnsignedCharArray> px;
    scene.Window->GetPixelData(col, row, col, row, 0, px);
    const unsigned char* c = px->GetPointer(0);
    std::cout << "translucent sphere pixel " << int(c[0]) << " " << int(c[1]) << " " << int(c[2])
              << std::endl;
    CHECK(c[0] > c[1] + 30 && c[0] > c[2] + 30);
  }

  // A non-receiver is lit as if nothing blocked.
  vtkPenumbraShadowKeys::SetReceivesShadows(scene.Plane, false);
  scene.Window->Render();
  CHECK(scene.Luminance(-1.0, 0.0) > 0.8 * scene.Luminance(1.5, 0.5));
  // ... and its samples cost no shadow work: only the occluder's top remains to be traced.
  vtkPenumbraViewSamples* samples = scene.Pass()->GetViewSamples();
  CHECK(samples->GetNumberOfValidSamples() < samples->GetNumberOfSamples() / 10);
  vtkPenumbraShadowKeys::SetReceivesShadows(scene.Plane, true);

  // A black light costs nothing: no visibility computed.
  scene.Light->SetIntensity(0.0);
  scene.Window->Render();
  CHECK(scene.Pass()->GetNumberOfLights() == 1);
  CHECK(scene.Pass()->GetVisibility(0) == nullptr);
  // A light that is off is not even listed (with every light off VTK would create a
  // headlight: not here).
  scene.Renderer->AutomaticLightCreationOff();
  scene.Light->SetIntensity(1.0);
  scene.Light->SwitchOff();
  scene.Window->Render();
  CHECK(scene.Pass()->GetNumberOfLights() == 0);
  return EXIT_SUCCESS;
}
}

// A translucent slab between the occluder and the ground receives the occluder's shadow (VTK's
// pass drops translucent props; lighting them unshadowed would be wrong too). Its samples are
// the pass's second layer, checked against the exact reference, for each technique family.
int CheckTranslucentReceiver(const char* technique)
{
  Scene scene(128, 128);
  vtkNew<vtkPlaneSource> slabSource;
  slabSource->SetOrigin(-3.5, -1.8, 0.5);
  slabSource->SetPoint1(3.5, -1.8, 0.5);
  slabSource->SetPoint2(-3.5, 1.8, 0.5);
  vtkNew<vtkPolyDataMapper> slabMapper;
  slabMapper->SetInputConnection(slabSource->GetOutputPort());
  vtkNew<vtkActor> slab;
  slab->SetMapper(slabMapper);
  slab->GetProperty()->SetColor(0.2, 1.0, 0.2);
  slab->GetProperty()->SetOpacity(0.5);
  slab->GetProperty()->SetAmbient(0.0);
  slab->GetProperty()->SetDiffuse(1.0);
  slab->GetProperty()->SetSpecular(0.0);
  scene.Renderer->AddActor(slab);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, technique, ""));
  scene.Window->Render();

  vtkPenumbraShadowPass* pass = scene.Pass();
  CHECK(pass->GetTranslucentViewSamples() != nullptr);
  vtkPenumbraViewSamples* samples = pass->GetTranslucentViewSamples();
  vtkFloatArray* vis = pass->GetTranslucentVisibility(0);
  CHECK(vis != nullptr);
  CHECK(vis->GetNumberOfTuples() == samples->GetNumberOfSamples());
  // The slab covers y in [-1.8, 1.8] of the view's [-2, 2]: 90 % of the pixels.
  const double covered =
    static_cast<double>(samples->GetNumberOfValidSamples()) / samples->GetNumberOfSamples();
  CHECK(std::fabs(covered - 0.9) < 0.01);
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(pass->GetGeometry());
  vtkNew<vtkFloatArray> ref;
  CHECK(reference->ComputeVisibility(samples, pass->GetLight(0), ref));
  vtkIdType shadowed = 0, mismatches = 0;
  for (vtkIdType i = 0; i < samples->GetNumberOfSamples(); ++i)
  {
    shadowed += ref->GetValue(i) == 0.0f;
    mismatches += ref->GetValue(i) != vis->GetValue(i) && !reference->GetTies()->GetValue(i);
  }
  const bool exact = std::string(technique) != "shadowmap";
  std::cout << technique << ": translucent samples shadowed " << shadowed << ", mismatches "
            << mismatches << std::endl;
  // The occluder's shadow on the slab: about 1 x 1 of 4 x 4 units.
  CHECK(shadowed > 500 && shadowed < 1500);
  CHECK(exact ? mismatches == 0 : mismatches < shadowed / 50);

  // And the image shows it: the slab in the occluder's shadow (x in [-1, 0]) is dark, beside
  // it lit. The ground behind is shadowed by the slab everywhere, so only the slab differs.
  const double inShadow = scene.Luminance(-0.6, 0.0);
  const double lit = scene.Luminance(1.5, 0.0);
  std::cout << "  slab in shadow " << inShadow << ", lit " << lit << std::endl;
  CHECK(lit > inShadow + 40.0);

  // The opaque layer is unchanged: the ground's samples are all shadowed by the slab.
  CHECK(ShadowedPlaneSamples(pass) > 0);
  scene.Renderer->ReleaseGraphicsResources(scene.Window);
  return EXIT_SUCCESS;
}

// Code written for VTK's vtkShadowMapPass keeps its composition:
// CameraPass -> Sequence[shadows->GetShadowMapBakerPass(), shadows], with the generic pass
// and a technique, or with vtkPenumbraShadowMapPass in place of vtkShadowMapPass.
int CheckVTKComposition(bool shadowMapPass)
{
  Scene scene(128, 64);
  vtkSmartPointer<vtkPenumbraShadowPass> shadows;
  if (shadowMapPass)
  {
    auto dropIn = vtkSmartPointer<vtkPenumbraShadowMapPass>::New();
    CHECK(dropIn->GetShadowMaps() != nullptr);
    dropIn->GetShadowMaps()->SetResolution(1024);
    shadows = dropIn;
  }
  else
  {
    shadows = vtkSmartPointer<vtkPenumbraShadowPass>::New();
    shadows->SetTechnique(vtkNew<vtkPenumbraRayTracedShadows>());
  }
  vtkNew<vtkRenderPassCollection> passes;
  passes->AddItem(shadows->GetShadowMapBakerPass());
  passes->AddItem(shadows);
  vtkNew<vtkSequencePass> sequence;
  sequence->SetPasses(passes);
  vtkNew<vtkCameraPass> camera;
  camera->SetDelegatePass(sequence);
  scene.Renderer->SetPass(camera);
  scene.Window->Render();
  const vtkIdType shadowed = ShadowedPlaneSamples(shadows);
  std::cout << shadows->GetClassName() << ": shadowed plane samples " << shadowed << std::endl;
  // Exact technique: the footprint to the sample; shadow map: within its texel rounding.
  CHECK(shadowMapPass ? std::abs(shadowed - 256) <= 8 : shadowed == 256);
  CHECK(scene.Luminance(-1.0, 0.0) < 40.0);
  CHECK(scene.Luminance(1.2, 0.0) > 150.0);
  scene.Renderer->ReleaseGraphicsResources(scene.Window);
  return EXIT_SUCCESS;
}

// A frame in which nothing the shadows depend on changed reuses the last visibility (no view
// samples, no technique), and everything that can change the shadows makes the pass compute
// again: camera, light, an occluder's position, a prop's opacity, the window size, a
// technique setting, and a light switched off.
int CheckFrameReuse()
{
  Scene scene(96, 64);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, "raytraced", ""));
  vtkPenumbraShadowPass* pass = scene.Pass();
  CHECK(pass != nullptr && pass->GetReuseUnchangedFrames());
  vtkNew<vtkFloatArray> first;
  // Renders; true when the pass reused (or not) as expected and the visibility equals
  // (or differs from) the first frame's as expected.
  auto render = [&](const char* what, bool reused, bool sameAsFirst)
  {
    scene.Window->Render();
    vtkFloatArray* vis = pass->GetVisibility(0);
    bool same = vis && first->GetNumberOfTuples() == vis->GetNumberOfTuples();
    for (vtkIdType i = 0; same && i < vis->GetNumberOfTuples(); ++i)
    {
      same = vis->GetValue(i) == first->GetValue(i);
    }
    std::cout << "frame reuse: " << what << ": reused " << pass->GetLastFrameReused()
              << ", same visibility as the first frame " << same << std::endl;
    return pass->GetLastFrameReused() == reused && same == sameAsFirst;
  };
  scene.Window->Render();
  CHECK(!pass->GetLastFrameReused() && pass->GetVisibility(0) != nullptr);
  first->DeepCopy(pass->GetVisibility(0));
  CHECK(ShadowedPlaneSamples(pass) == 256);
  CHECK(render("nothing changed", true, true));
  CHECK(render("nothing changed again", true, true));
  CHECK(pass->GetSamplesTimeMs() == 0.0 && pass->GetTechniqueTimeMs() == 0.0);

  scene.Renderer->GetActiveCamera()->SetParallelScale(2.5);
  CHECK(render("camera zoomed", false, false));
  CHECK(pass->GetLastFrameRenderedSamples());
  CHECK(render("nothing changed", true, false));
  scene.Renderer->GetActiveCamera()->SetParallelScale(2.0);
  CHECK(render("camera back", false, true));

  scene.Light->SetPosition(1.0, 0.0, 2.0); // steeper: a smaller visible shadow
  CHECK(render("light moved", false, false));
  CHECK(!pass->GetLastFrameRenderedSamples()); // same view: the samples are kept
  scene.Light->SetPosition(1, 0, 1);
  CHECK(render("light back", false, true));

  scene.Occluder->SetPosition(0.5, 0.0, 0.0);
  CHECK(render("occluder moved", false, false));
  scene.Occluder->SetPosition(0.0, 0.0, 0.0);
  CHECK(render("occluder back", false, true));

  scene.Occluder->GetProperty()->SetOpacity(0.5); // now a translucent receiver: two layers
  CHECK(render("occluder translucent", false, true));
  CHECK(pass->GetTranslucentViewSamples() != nullptr);
  scene.Occluder->GetProperty()->SetOpacity(1.0);
  CHECK(render("occluder opaque", false, true));
  CHECK(pass->GetTranslucentViewSamples() == nullptr);

  vtkPenumbraShadowKeys::SetReceivesShadows(scene.Plane, false);
  CHECK(render("plane no longer receives", false, false));
  vtkPenumbraShadowKeys::SetReceivesShadows(scene.Plane, true);
  CHECK(render("plane receives again", false, true));

  scene.Window->SetSize(128, 64);
  scene.Window->Render();
  CHECK(!pass->GetLastFrameReused() && pass->GetVisibility(0)->GetNumberOfTuples() == 128 * 64);
  scene.Window->SetSize(96, 64);
  CHECK(render("window back", false, true));

  pass->GetTechnique()->Modified(); // a setting changed (any setter modifies the technique)
  CHECK(render("technique modified", false, true));

  // With every light off VTK lights the scene with a new headlight: not here.
  scene.Renderer->AutomaticLightCreationOff();
  scene.Light->SwitchOff();
  scene.Window->Render();
  CHECK(!pass->GetLastFrameReused() && pass->GetVisibility(0) == nullptr);
  scene.Renderer->AutomaticLightCreationOn();
  scene.Light->SwitchOn();
  CHECK(render("light on", false, true));
  CHECK(render("nothing changed", true, true));

  pass->ReuseUnchangedFramesOff();
  CHECK(render("reuse off", false, true));
  scene.Renderer->ReleaseGraphicsResources(scene.Window);
  return EXIT_SUCCESS;
}

// A technique that answers on the GPU (shadow maps with the GPU lookup) leaves the view
// samples on the GPU; a CPU technique (ray tracing) reads them back. Either way the
// visibility read back for analysis is the same on the same scene.
int CheckSamplesStayOnGPU()
{
  vtkSmartPointer<vtkFloatArray> answers[2];
  const char* names[2] = { "shadowmap", "raytraced" };
  for (int t = 0; t < 2; ++t)
  {
    Scene scene(128, 64);
    vtkNew<vtkPenumbraTechniques> techniques;
    CHECK(techniques->Apply(scene.Renderer, names[t], ""));
    scene.Window->Render();
    vtkPenumbraShadowPass* pass = scene.Pass();
    CHECK(pass->GetFrame() != nullptr);
    const bool readBack = pass->GetFrame()->GetSamplesReadBack();
    std::cout << names[t] << ": samples read back " << readBack << std::endl;
    CHECK(readBack == (t == 1));
    answers[t] = vtkSmartPointer<vtkFloatArray>::New();
    answers[t]->DeepCopy(pass->GetVisibility(0));
    scene.Renderer->ReleaseGraphicsResources(scene.Window);
  }
  CHECK(answers[0]->GetNumberOfTuples() == answers[1]->GetNumberOfTuples());
  vtkIdType differ = 0, background = 0;
  for (vtkIdType i = 0; i < answers[0]->GetNumberOfTuples(); ++i)
  {
    differ += answers[0]->GetValue(i) != answers[1]->GetValue(i);
    background += answers[0]->GetValue(i) < 0.0f;
  }
  std::cout << "shadowmap vs raytraced: " << differ << " samples differ, background " << background
            << std::endl;
  CHECK(differ <= 16); // texel rounding along the footprint's edges
  return EXIT_SUCCESS;
}

// Every shadowed light takes a texture unit in the receivers' shaders: with more lights than
// the implementation has units for, the first ones are shadowed, the rest lit unshadowed with
// an error, and the frame still renders.
int CheckManyLights()
{
  Scene scene(64, 32);
  const int extra = 63;
  for (int i = 0; i < extra; ++i)
  {
    vtkNew<vtkLight> light;
    light->SetLightTypeToSceneLight();
    light->SetPositional(false);
    light->SetPosition(1, 0.01 * i, 1);
    light->SetFocalPoint(0, 0, 0);
    light->SetIntensity(0.01);
    scene.Renderer->AddLight(light);
  }
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(scene.Renderer, "shadowmap", ""));
  vtkPenumbraShadowPass* pass = scene.Pass();
  std::string error; // the pass reports the lights it leaves unshadowed
  vtkNew<vtkCallbackCommand> onError;
  onError->SetClientData(&error);
  onError->SetCallback([](vtkObject*, unsigned long, void* client, void* call)
    { *static_cast<std::string*>(client) = static_cast<const char*>(call); });
  pass->AddObserver(vtkCommand::ErrorEvent, onError);
  scene.Window->Render();
  std::cout << "many lights: error \"" << error << "\"" << std::endl;
  CHECK(error.find("lights rendered without shadows") != std::string::npos);
  CHECK(pass->GetNumberOfLights() == extra + 1);
  int shadowed = 0;
  for (int i = 0; i <= extra; ++i)
  {
    shadowed += pass->GetVisibility(i) != nullptr;
  }
  std::cout << "many lights: " << shadowed << " of " << extra + 1 << " shadowed" << std::endl;
  CHECK(shadowed >= 8 && shadowed < extra + 1);
  CHECK(pass->GetVisibility(0) != nullptr && pass->GetVisibility(extra) == nullptr);
  CHECK(scene.Luminance(-1.0, 0.0) < scene.Luminance(1.2, 0.0)); // the first light's shadow
  scene.Renderer->ReleaseGraphicsResources(scene.Window);
  return EXIT_SUCCESS;
}

// Hidden blocks of composite data cast no shadows: vtkCompositePolyDataMapper2 does not draw
// them, so the scene geometry (registered accessor) leaves them out, a block inheriting its
// parent's visibility unless it has its own; showing a block again brings it back.
int CheckHiddenBlocks()
{
  auto block = [](double z)
  {
    vtkNew<vtkPlaneSource> plane;
    plane->SetCenter(0, 0, z);
    plane->Update();
    vtkSmartPointer<vtkPolyData> poly = plane->GetOutput();
    return poly;
  };
  vtkNew<vtkMultiBlockDataSet> root, group;
  root->SetBlock(0, block(0.0));
  root->SetBlock(1, group);
  group->SetBlock(0, block(1.0));
  group->SetBlock(1, block(2.0));
  vtkNew<vtkCompositePolyDataMapper2> mapper;
  mapper->SetInputDataObject(root);
  vtkNew<vtkCompositeDataDisplayAttributes> attributes;
  mapper->SetCompositeDataDisplayAttributes(attributes);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  vtkNew<vtkPenumbraSceneGeometry> geometry;

  // Each plane is 2 triangles; cell ids continue over hidden blocks.
  CHECK(geometry->Update(renderer) == 1 && geometry->GetNumberOfTriangles() == 6);
  attributes->SetBlockVisibility(group, false);
  CHECK(geometry->Update(renderer) == 1 && geometry->GetNumberOfTriangles() == 2);
  attributes->SetBlockVisibility(group->GetBlock(1), true); // its own flag wins
  CHECK(geometry->Update(renderer) == 1 && geometry->GetNumberOfTriangles() == 4);
  CHECK(geometry->GetTriangleCellId(2) == 2); // the second plane's cells are skipped
  double bounds[6];
  geometry->GetBounds(bounds);
  CHECK(bounds[4] == 0.0 && bounds[5] == 2.0);
  attributes->RemoveBlockVisibilities();
  CHECK(geometry->Update(renderer) == 1 && geometry->GetNumberOfTriangles() == 6);
  return EXIT_SUCCESS;
}

int TestShadowPass(int, char*[])
{
  RUN(CheckHiddenBlocks());
  RUN(CheckManyLights());
  RUN(CheckFrameReuse());
  RUN(CheckSamplesStayOnGPU());
  RUN(CheckVTKComposition(false));
  RUN(CheckVTKComposition(true));
  RUN(CheckFootprint(128, 64));
  RUN(CheckFootprint(256, 64)); // wide window: same footprint, no distortion
  RUN(CheckReceiversAndLights());
  for (const char* technique : { "raytraced", "conservative", "shadowmap", "volumes" })
  {
    RUN(CheckTranslucentReceiver(technique));
  }
  return EXIT_SUCCESS;
}
