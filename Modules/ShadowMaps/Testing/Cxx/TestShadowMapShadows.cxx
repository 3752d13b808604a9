// vtkPenumbraShadowMapShadows (Brabec, "Shadow Techniques for Interactive and Real-Time
// Applications", PhD thesis, 2003, ch. 4-6) against the exact reference on the same view
// samples: the mismatch rate falls as the map resolution rises and is small at 4096^2; a
// point light inside a closed room shadows every visible face with cube and dual-paraboloid
// maps; a wide window agrees with a square one; a PBR receiver is darkened; the paraboloid
// mapping round-trips; lights that are off get no map; unchanged frames render no map; the
// minimum-area rectangle fit shrinks a rotated receiver's map.
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCameraPass.h"
#include "vtkCubeSource.h"
#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraFrame.h"
#include "vtkPenumbraMetrics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPlaneSource.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkUnsignedCharArray.h"

#include "PenumbraTechniqueTests.h"
#include "PenumbraTestMacros.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace
{
vtkPenumbraShadowPass* ShadowPassOf(vtkRenderer* renderer)
{
  return vtkPenumbraShadowPass::GetInstalled(renderer);
}

vtkPenumbraShadowMapShadows* TechniqueOf(vtkRenderer* renderer)
{
  vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
  return pass ? vtkPenumbraShadowMapShadows::SafeDownCast(pass->GetTechnique()) : nullptr;
}

// A plane (z = 0, 8 x 6 m) with a box (1 x 1 x 0.5 m, 1 m above it) lit by a directional
// light from (1.5, 0.7, 3), seen obliquely.
vtkSmartPointer<vtkRenderer> PlaneAndBox(vtkActor** planeActor = nullptr)
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-4, -3, 0);
  plane->SetPoint1(4, -3, 0);
  plane->SetPoint2(-4, 3, 0);
  vtkNew<vtkCubeSource> box;
  box->SetBounds(-0.5, 0.5, -0.5, 0.5, 1.0, 1.5);
  vtkPolyDataAlgorithm* sources[] = { plane, box };
  for (int i = 0; i < 2; ++i)
  {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(sources[i]->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetAmbient(0.1);
    actor->GetProperty()->SetDiffuse(0.9);
    actor->GetProperty()->SetSpecular(0.0);
    renderer->AddActor(actor);
    if (i == 0 && planeActor)
    {
      *planeActor = actor;
    }
  }
  vtkNew<vtkLight> light;
  light->SetLightTypeToSceneLight();
  light->SetPositional(false);
  light->SetPosition(1.5, 0.7, 3.0);
  light->SetFocalPoint(0, 0, 0);
  renderer->AddLight(light);
  renderer->SetBackground(0, 0, 0);
  vtkCamera* cam = renderer->GetActiveCamera();
  cam->SetPosition(0.5, -6, 8);
  cam->SetFocalPoint(0, 0, 0);
  cam->SetViewUp(0, 0, 1);
  renderer->ResetCamera();
  cam->Dolly(1.8); // the plane and the shadow fill the view
  renderer->ResetCameraClippingRange();
  return renderer;
}

vtkSmartPointer<vtkRenderWindow> WindowFor(vtkRenderer* renderer, int width, int height)
{
  auto window = vtkSmartPointer<vtkRenderWindow>::Take(vtkRenderWindow::New());
  window->SetSize(width, height);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  return window;
}

struct Comparison
{
  double MismatchRate = 1.0;
  vtkIdType Mismatches = 0;
  vtkIdType Valid = 0;
};

// Mismatch of light `index`'s visibility against the exact reference on the same samples
// (reference ties excluded).
int Compare(vtkRenderer* renderer, int index, Comparison& out, vtkFloatArray* refOut = nullptr)
{
  vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
  CHECK(pass != nullptr);
  CHECK(pass->GetNumberOfLights() > index);
  vtkFloatArray* test = pass->GetVisibility(index);
  CHECK(test != nullptr);
  vtkNew<vtkPenumbraReference> reference;
  reference->SetGeometry(pass->GetGeometry());
  vtkNew<vtkFloatArray> ref;
  CHECK(reference->ComputeVisibility(pass->GetViewSamples(), pass->GetLight(index), ref));
  vtkNew<vtkPenumbraMetrics> metrics;
  CHECK(metrics->CompareHard(test, ref, reference->GetTies()));
  out.MismatchRate = metrics->GetMismatchRate();
  out.Mismatches = metrics->GetFalseLit() + metrics->GetFalseShadow();
  out.Valid = pass->GetViewSamples()->GetNumberOfValidSamples();
  if (refOut)
  {
    refOut->DeepCopy(ref);
  }
  return EXIT_SUCCESS;
}

int RenderAndCompare(vtkRenderer* renderer, const std::string& options, int width, int height,
  Comparison& out, const char* label, const char* name = "shadowmap")
{
  auto window = WindowFor(renderer, width, height);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, name, options.c_str()));
  window->Render();
  RUN(Compare(renderer, 0, out));
  vtkPenumbraShadowMapShadows* technique = TechniqueOf(renderer);
  CHECK(technique != nullptr);
  std::printf("%-40s %-44s valid %7lld mismatches %6lld rate %.5f views %d map %.1f ms lookup "
              "%.1f ms\n",
    label, options.c_str(), static_cast<long long>(out.Valid),
    static_cast<long long>(out.Mismatches), out.MismatchRate, technique->GetNumberOfViews(),
    technique->GetMapTimeMs(), technique->GetLookupTimeMs());
  window->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// The GPU lookup (hardware depth compare) and the CPU lookup (double precision) answer the
// same question on the same maps: they may differ only where float rounding moves a sample
// across a texel edge or its depth across the threshold.
int CheckLookupsAgree()
{
  struct Case
  {
    const char* Scene; // nullptr: plane + box
    const char* Options;
    float Tolerance; // per sample; Fast PCF's weights come from float vs double positions
  };
  const Case cases[] = { { nullptr, "", 1e-6f },
    { nullptr, "\"filter\": \"pcf\", \"pcf_kernel\": 5", 1e-6f },
    { nullptr, "\"filter\": \"bilinear\", \"resolution\": 512", 2e-3f },
    { nullptr, "\"depth\": \"midpoint\"", 1e-6f },
    { nullptr, "\"fit_rectangle\": \"minimum\"", 1e-6f },
    { "torture/point_light_in_room.json", "\"point\": \"cube\"", 1e-6f },
    { "torture/point_light_in_room.json", "\"point\": \"paraboloid\"", 1e-6f },
    { "torture/point_light_in_room.json", "\"filter\": \"bilinear\"", 2e-3f } };
  for (const Case& c : cases)
  {
    vtkNew<vtkFloatArray> answers[2];
    vtkIdType valid = 0;
    for (int l = 0; l < 2; ++l)
    {
      vtkNew<vtkPenumbraSceneReader> reader;
      vtkSmartPointer<vtkRenderer> renderer;
      if (c.Scene)
      {
        reader->SetFileName((std::string(PENUMBRA_SCENES_DIR) + "/" + c.Scene).c_str());
        CHECK(reader->Read());
        renderer = reader->GetRenderer();
      }
      else
      {
        renderer = PlaneAndBox();
      }
      auto window = WindowFor(renderer, 200, 150);
      vtkNew<vtkPenumbraTechniques> techniques;
      const std::string options = std::string("{\"lookup\": \"") + (l ? "cpu" : "gpu") + "\"" +
        (*c.Options ? ", " : "") + c.Options + "}";
      CHECK(techniques->Apply(renderer, "shadowmap", options.c_str()));
      window->Render();
      vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
      CHECK(pass && pass->GetVisibility(0));
      answers[l]->DeepCopy(pass->GetVisibility(0));
      valid = pass->GetViewSamples()->GetNumberOfValidSamples();
      CHECK(TechniqueOf(renderer)->GetLookup() ==
        (l ? vtkPenumbraShadowMapShadows::LOOKUP_CPU : vtkPenumbraShadowMapShadows::LOOKUP_GPU));
      window->RemoveRenderer(renderer);
      window->Finalize();
    }
    CHECK(answers[0]->GetNumberOfTuples() == answers[1]->GetNumberOfTuples());
    vtkIdType differ = 0, shadowed = 0;
    for (vtkIdType i = 0; i < answers[0]->GetNumberOfTuples(); ++i)
    {
      differ += std::fabs(answers[0]->GetValue(i) - answers[1]->GetValue(i)) > c.Tolerance;
      shadowed += answers[1]->GetValue(i) == 0.0f;
    }
    std::printf("lookup gpu vs cpu %-34s %-40s valid %lld shadowed %lld differ %lld\n",
      c.Scene ? c.Scene : "plane+box", c.Options, static_cast<long long>(valid),
      static_cast<long long>(shadowed), static_cast<long long>(differ));
    CHECK(shadowed > 0);
    CHECK(differ <= valid / 1000);
  }
  return EXIT_SUCCESS;
}

// The GPU lookup made in the receivers' own shaders (lookup "gpu": no visibility texture,
// vtkPenumbraFrame::ShaderLookup) shades exactly what the full-screen G-buffer lookup
// (lookup "gbuffer") writes: the same image, pixel for pixel, and the same visibility read
// back; a spot light too, and the filters that take several taps; and a repeated frame, which
// reads them from a texture, the same image again.
// Whether the shader lookup's run (index 0) and the full-screen lookup's (1) agree: the
// same image bytes and read-back visibilities, with some shadow (over 100 samples at 0).
bool SameLookups(const std::string& label, vtkSmartPointer<vtkUnsignedCharArray> images[2],
  vtkFloatArray* answers[2])
{
  vtkIdType pixels = 0, values = 0, shadowed = 0;
  for (vtkIdType i = 0; i < images[0]->GetNumberOfValues(); ++i)
  {
    pixels += images[0]->GetValue(i) != images[1]->GetValue(i);
  }
  values += std::abs(answers[0]->GetNumberOfTuples() - answers[1]->GetNumberOfTuples());
  const vtkIdType n = std::min(answers[0]->GetNumberOfTuples(), answers[1]->GetNumberOfTuples());
  for (vtkIdType i = 0; i < n; ++i)
  {
    values += answers[0]->GetValue(i) != answers[1]->GetValue(i);
    shadowed += answers[0]->GetValue(i) == 0.0f;
  }
  std::printf("%s: %lld channel values and %lld visibilities differ (%lld shadowed)\n",
    label.c_str(), static_cast<long long>(pixels), static_cast<long long>(values),
    static_cast<long long>(shadowed));
  return shadowed > 100 && pixels == 0 && values == 0;
}

int CheckShaderLookup()
{
  const char* filters[] = { "none", "pcf", "bilinear" };
  // 0 directional, 1 spot, 2 directional and a point light (whose cube maps are read from
  // a texture while the directional light is looked up: both kinds in one shader).
  for (int lights = 0; lights < 3; ++lights)
  {
    for (const char* filter : filters)
    {
      vtkSmartPointer<vtkUnsignedCharArray> images[2];
      vtkNew<vtkFloatArray> answers[2];
      for (int g = 0; g < 2; ++g)
      {
        vtkSmartPointer<vtkRenderer> renderer = PlaneAndBox();
        if (lights == 2)
        {
          vtkNew<vtkLight> point;
          point->SetLightTypeToSceneLight();
          point->SetPositional(true);
          point->SetConeAngle(180.0);
          point->SetPosition(-1.0, -0.5, 2.5);
          point->SetIntensity(0.5);
          renderer->AddLight(point);
        }
        if (lights == 1)
        {
          auto* light = vtkLight::SafeDownCast(renderer->GetLights()->GetItemAsObject(0));
          CHECK(light != nullptr);
          light->SetPositional(true);
          light->SetPosition(1.5, 0.7, 3.0);
          light->SetFocalPoint(0.0, 0.0, 0.0);
          light->SetConeAngle(60.0);
        }
        auto window = WindowFor(renderer, 160, 120);
        vtkNew<vtkPenumbraTechniques> techniques;
        const std::string options = std::string("{\"filter\": \"") + filter + "\", \"lookup\": \"" +
          (g ? "gbuffer" : "gpu") + "\"}";
        CHECK(techniques->Apply(renderer, "shadowmap", options.c_str()));
        window->Render();
        vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
        CHECK(pass && pass->GetFrame());
        // Only the "gpu" lookup is made while shading; reading the visibility resolves it.
        CHECK((pass->GetFrame()->GetShaderLookup(0) != nullptr) == (g == 0));
        images[g] = vtkSmartPointer<vtkUnsignedCharArray>::New();
        CHECK(window->GetRGBACharPixelData(0, 0, 159, 119, 0, images[g]) == VTK_OK);
        // A frame where nothing changed reads the lookup's values from a texture (written
        // once): the same image again.
        window->Render();
        CHECK(pass->GetLastFrameReused());
        vtkNew<vtkUnsignedCharArray> again;
        CHECK(window->GetRGBACharPixelData(0, 0, 159, 119, 0, again) == VTK_OK);
        for (vtkIdType i = 0; i < again->GetNumberOfValues(); ++i)
        {
          CHECK(again->GetValue(i) == images[g]->GetValue(i));
        }
        CHECK(pass->GetVisibility(0) != nullptr);
        answers[g]->DeepCopy(pass->GetVisibility(0));
        window->RemoveRenderer(renderer);
        window->Finalize();
      }
      vtkFloatArray* read[2] = { answers[0], answers[1] };
      const std::string kind =
        lights == 1 ? "spot" : (lights == 2 ? "directional+point" : "directional");
      CHECK(SameLookups(
        "shader lookup vs G-buffer lookup, " + kind + " light, filter " + filter, images, read));
    }
  }
  return EXIT_SUCCESS;
}

// fit: "scene" (SetFitTo(FIT_TO_SCENE)): after a camera move the directional light's map
// is the same (its footprint unchanged; the view fit's is smaller), the frame looked up
// in the receivers' shaders renders no view samples, and its image and read-back visibility
// (samples rendered on demand) equal those of the full-screen lookup, which renders them.
int CheckSceneFit()
{
  vtkSmartPointer<vtkUnsignedCharArray> images[2];
  vtkNew<vtkFloatArray> answers[2];
  double moved[2][2] = { { 0, 0 }, { 0, 0 } };
  for (int g = 0; g < 2; ++g)
  {
    vtkSmartPointer<vtkRenderer> renderer = PlaneAndBox();
    auto window = WindowFor(renderer, 160, 120);
    vtkNew<vtkPenumbraTechniques> techniques;
    const std::string options =
      std::string("{\"fit\": \"scene\", \"lookup\": \"") + (g ? "gbuffer" : "gpu") + "\"}";
    CHECK(techniques->Apply(renderer, "shadowmap", options.c_str()));
    window->Render();
    vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
    double before[2], after[2];
    CHECK(TechniqueOf(renderer)->GetMapFootprint(pass->GetLight(0), before));
    renderer->GetActiveCamera()->Azimuth(25.0);
    renderer->GetActiveCamera()->Zoom(1.4);
    window->Render();
    CHECK(!pass->GetLastFrameReused());
    CHECK(pass->GetLastFrameRenderedSamples() == (g == 1));
    CHECK(TechniqueOf(renderer)->GetMapFootprint(pass->GetLight(0), after));
    CHECK(before[0] == after[0] && before[1] == after[1]);
    images[g] = vtkSmartPointer<vtkUnsignedCharArray>::New();
    CHECK(window->GetRGBACharPixelData(0, 0, 159, 119, 0, images[g]) == VTK_OK);
    CHECK(pass->GetVisibility(0) != nullptr);
    answers[g]->DeepCopy(pass->GetVisibility(0));
    // The view fit of the same scene refits the map to the moved view.
    CHECK(techniques->Apply(renderer, "shadowmap", "{\"fit\": \"view\"}"));
    window->Render();
    CHECK(TechniqueOf(renderer)->GetMapFootprint(ShadowPassOf(renderer)->GetLight(0), moved[g]));
    // The view fit covers only the receivers seen after the zoom: less than the scene.
    CHECK(moved[g][0] * moved[g][1] < 0.95 * after[0] * after[1]);
    window->RemoveRenderer(renderer);
    window->Finalize();
  }
  vtkFloatArray* read[2] = { answers[0], answers[1] };
  std::printf("view fit footprint after the move: %.3f x %.3f\n", moved[0][0], moved[0][1]);
  CHECK(SameLookups("scene fit after a camera move, shader vs G-buffer lookup", images, read));
  return EXIT_SUCCESS;
}

// The scene fit reads only the runs of vertices whose box could move the extent; the result
// must be that of every vertex. A sphere of 7,686 triangles (91 runs of 256 vertices) under a
// tilted sun: the map's footprint equals the extent of every vertex along the map's axes (the
// light-space basis of vtkPenumbraLightViews' Basis()), padded as the fit pads it, before and
// after the sun moves (the runs' boxes are kept, the extent is redone).
int CheckSceneFitReadsWhatMatters()
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(63);
  sphere->SetPhiResolution(63);
  sphere->SetRadius(1.3);
  sphere->SetCenter(0.2, -0.1, 1.5);
  sphere->Update();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  renderer->AddActor(actor);
  vtkNew<vtkLight> sun;
  sun->SetLightTypeToSceneLight();
  sun->SetPositional(false);
  sun->SetFocalPoint(0, 0, 0);
  renderer->AddLight(sun);
  renderer->GetActiveCamera()->SetPosition(3, -5, 4);
  renderer->GetActiveCamera()->SetFocalPoint(0, 0, 1);
  renderer->ResetCamera();
  auto window = WindowFor(renderer, 96, 72);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"fit\": \"scene\"}"));
  vtkPoints* points = sphere->GetOutput()->GetPoints();
  const double positions[2][3] = { { 1.0, 2.0, 3.0 }, { -2.0, 0.7, 1.1 } };
  for (const double* position : positions)
  {
    sun->SetPosition(position[0], position[1], position[2]);
    window->Render();
    double sides[2];
    CHECK(TechniqueOf(renderer)->GetMapFootprint(sun, sides));
    // The map's axes: travel direction f, r = f x helper, u = r x f (Basis()).
    double f[3] = { -position[0], -position[1], -position[2] };
    vtkMath::Normalize(f);
    const double helper[3] = { std::fabs(f[0]) < 0.9 ? 1.0 : 0.0, std::fabs(f[0]) < 0.9 ? 0.0 : 1.0,
      0.0 };
    double axes[3][3];
    vtkMath::Cross(f, helper, axes[0]);
    vtkMath::Normalize(axes[0]);
    vtkMath::Cross(axes[0], f, axes[1]);
    vtkMath::Normalize(axes[1]);
    std::copy(f, f + 3, axes[2]);
    double lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
    for (vtkIdType i = 0; i < points->GetNumberOfPoints(); ++i)
    {
      double p[3];
      points->GetPoint(i, p);
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], vtkMath::Dot(p, axes[a]));
        hi[a] = std::max(hi[a], vtkMath::Dot(p, axes[a]));
      }
    }
    // FitViews() pads by 1e-3 of the widest extent and by 1e-9 of the scene's size, which the
    // tolerance below covers (7e-9 here). Reading only the runs whose boxes reach farthest
    // made a side 4.8e-7 short (tried on purpose).
    const double pad = 1e-3 * std::max({ hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] });
    for (int a = 0; a < 2; ++a)
    {
      const double expected = hi[a] - lo[a] + 2.0 * pad;
      std::printf("sun (%g, %g, %g): side %d %.12f, every vertex's extent %.12f\n", position[0],
        position[1], position[2], a, sides[a], expected);
      CHECK(std::fabs(sides[a] - expected) < 1e-8 * expected);
    }
  }
  return EXIT_SUCCESS;
}

// Fast PCF (Brabec 2003, ch. 5.2) softens only edges: on a coarse map every sample with a
// fractional value lies within a texel's footprint (a few pixels here) of a change of the
// exact hard shadow or of a silhouette in the map (a change of prop: the taps of a box side
// next to its top see the top), and samples away from them are exactly 0 or 1.
int CheckBilinearEdges()
{
  const int width = 200, height = 150, reach = 4;
  vtkNew<vtkFloatArray> answers[2], exact;
  vtkNew<vtkIntArray> props;
  const char* options[2] = { "{\"filter\": \"none\", \"resolution\": 256}",
    "{\"filter\": \"bilinear\", \"resolution\": 256}" };
  Comparison c[2];
  for (int f = 0; f < 2; ++f)
  {
    auto renderer = PlaneAndBox();
    auto window = WindowFor(renderer, width, height);
    vtkNew<vtkPenumbraTechniques> techniques;
    CHECK(techniques->Apply(renderer, "shadowmap", options[f]));
    window->Render();
    RUN(Compare(renderer, 0, c[f], exact));
    answers[f]->DeepCopy(ShadowPassOf(renderer)->GetVisibility(0));
    props->DeepCopy(ShadowPassOf(renderer)->GetViewSamples()->GetPropIndices());
    window->RemoveRenderer(renderer);
    window->Finalize();
  }
  vtkIdType fractional = 0, awayFromEdges = 0;
  for (int y = 0; y < height; ++y)
  {
    for (int x = 0; x < width; ++x)
    {
      const float v = answers[1]->GetValue(y * width + x);
      if (!(v > 0.0f && v < 1.0f))
      {
        continue;
      }
      ++fractional;
      bool edge = false;
      const float centre = exact->GetValue(y * width + x);
      const int prop = props->GetValue(y * width + x);
      for (int dy = -reach; dy <= reach && !edge; ++dy)
      {
        for (int dx = -reach; dx <= reach && !edge; ++dx)
        {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < width && yy < height)
          {
            const float other = exact->GetValue(yy * width + xx);
            edge = (other >= 0.0f && other != centre) || props->GetValue(yy * width + xx) != prop;
          }
        }
      }
      awayFromEdges += edge ? 0 : 1;
    }
  }
  std::printf("bilinear at 256^2: %lld fractional samples, %lld away from exact edges; "
              "mismatch against the exact shadow: none %lld, bilinear %lld\n",
    static_cast<long long>(fractional), static_cast<long long>(awayFromEdges),
    static_cast<long long>(c[0].Mismatches), static_cast<long long>(c[1].Mismatches));
  CHECK(fractional > 0);
  CHECK(awayFromEdges == 0);
  return EXIT_SUCCESS;
}

// PCSS (Fernando 2005) and single-sample soft shadows (Brabec 2003, ch. 11) at their limits,
// on the plane and box under an area light where the
// directional light was: a tiny light converges to the exact hard shadow (small MAE, like
// the hard shadow map), a huge one stays finite with every value in [0, 1].
int CheckSoftLimits(const char* technique)
{
  const double sizes[2] = { 1e-3, 50.0 };
  for (double size : sizes)
  {
    auto renderer = PlaneAndBox();
    renderer->RemoveAllLights();
    vtkNew<vtkPenumbraAreaLight> light;
    light->SetPosition(1.5, 0.7, 3.0);
    light->SetFocalPoint(0, 0, 0);
    light->SetWidth(size);
    light->SetHeight(size);
    light->SetSamplesPerAxis(4);
    renderer->AddLight(light);
    auto window = WindowFor(renderer, 200, 150);
    vtkNew<vtkPenumbraTechniques> techniques;
    CHECK(techniques->Apply(renderer, technique, "{}"));
    window->Render();
    vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
    CHECK(pass && pass->GetVisibility(0));
    CHECK(pass->GetTechnique()->HandlesAreaLights());
    vtkFloatArray* vis = pass->GetVisibility(0);
    vtkNew<vtkPenumbraReference> reference;
    reference->SetGeometry(pass->GetGeometry());
    vtkNew<vtkFloatArray> exact;
    CHECK(reference->ComputeConvergedVisibility(pass->GetViewSamples(), light, 16, exact));
    vtkNew<vtkPenumbraMetrics> metrics;
    CHECK(metrics->CompareSoft(vis, exact));
    float lo = 1.0f, hi = 0.0f;
    vtkIdType bad = 0, valid = 0;
    for (vtkIdType i = 0; i < vis->GetNumberOfTuples(); ++i)
    {
      const float v = vis->GetValue(i);
      if (exact->GetValue(i) < 0.0f)
      {
        continue;
      }
      ++valid;
      bad += std::isfinite(v) && v >= 0.0f && v <= 1.0f ? 0 : 1;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    std::printf("%s, light %g x %g: MAE %.4f against the converged reference, values in "
                "[%g, %g], %lld of %lld outside [0, 1]\n",
      technique, size, size, metrics->GetMAE(), lo, hi, static_cast<long long>(bad),
      static_cast<long long>(valid));
    CHECK(valid > 0 && bad == 0);
    if (size < 1.0)
    {
      CHECK(metrics->GetMAE() < 0.01); // the hard shadow, up to aliasing at its edges
      CHECK(lo == 0.0f && hi == 1.0f);
    }
    window->RemoveRenderer(renderer);
    window->Finalize();
  }
  return EXIT_SUCCESS;
}

// The mismatch rate falls as the resolution rises (Brabec 2003: aliasing shrinks with the texel).
int CheckResolutionSeries()
{
  const int resolutions[] = { 256, 1024, 4096 };
  double rates[3];
  for (int i = 0; i < 3; ++i)
  {
    auto renderer = PlaneAndBox();
    Comparison c;
    RUN(RenderAndCompare(renderer, "{\"resolution\": " + std::to_string(resolutions[i]) + "}", 320,
      240, c, "plane+box directional"));
    CHECK(c.Valid > 50000);
    rates[i] = c.MismatchRate;
  }
  CHECK(rates[0] >= rates[1] && rates[1] >= rates[2]);
  CHECK(rates[0] > rates[2]);
  // At 4096^2 a texel is about 2 mm here, far below a view sample's footprint.
  CHECK(rates[2] < 0.0005); // measured 7e-5
  // Filtered, midpoint and slope-bias-free variants stay usable on the same scene.
  for (const char* options : { "{\"filter\": \"pcf\", \"pcf_kernel\": 5}",
         "{\"depth\": \"midpoint\"}", "{\"depth\": \"midpoint\", \"bias\": 0, \"slope_bias\": 0}" })
  {
    auto renderer = PlaneAndBox();
    Comparison c;
    RUN(RenderAndCompare(renderer, options, 320, 240, c, "plane+box directional"));
    CHECK(c.MismatchRate < 0.02);
  }
  // A spot light (35-degree half-angle) over the same scene: one perspective map fitted to
  // the receivers in the cone; samples outside the cone are shadowed as in the reference.
  {
    auto renderer = PlaneAndBox();
    renderer->RemoveAllLights();
    vtkNew<vtkLight> spot;
    spot->SetLightTypeToSceneLight();
    spot->SetPositional(true);
    spot->SetPosition(1.5, 0.7, 3.0);
    spot->SetFocalPoint(0, 0, 0);
    spot->SetConeAngle(35.0);
    renderer->AddLight(spot);
    Comparison c;
    RUN(RenderAndCompare(renderer, "{\"resolution\": 2048}", 320, 240, c, "plane+box spot"));
    CHECK(c.MismatchRate < 0.001);
  }
  return EXIT_SUCCESS;
}

// A sun 0.2 degrees above the horizon (slope-scaled bias, ch. 4.1.2): the plane is a grazing
// receiver whose depth changes by ~290 texels per texel. Its samples must not shadow
// themselves, and the error must fall with resolution (a tangent cap of 20 left 42 % of
// the lit samples shadowed at 1024² and at 4096²).
int CheckGrazingLight()
{
  const int resolutions[] = { 1024, 4096 };
  double rates[2];
  for (int i = 0; i < 2; ++i)
  {
    auto renderer = PlaneAndBox();
    vtkLight* sun = vtkLight::SafeDownCast(renderer->GetLights()->GetItemAsObject(0));
    CHECK(sun != nullptr);
    const double elevation = vtkMath::RadiansFromDegrees(0.2);
    sun->SetPosition(-std::cos(elevation), 0.3 * std::cos(elevation), std::sin(elevation));
    Comparison c;
    RUN(RenderAndCompare(renderer, "{\"resolution\": " + std::to_string(resolutions[i]) + "}", 320,
      240, c, "plane+box grazing sun"));
    CHECK(c.Valid > 50000);
    rates[i] = c.MismatchRate;
  }
  CHECK(rates[0] < 0.02);
  CHECK(rates[1] <= rates[0]);
  return EXIT_SUCCESS;
}

// The same scene in an 800 x 400 window (a wide one) and a 400 x 400 one: the
// rates agree, so the wide aspect neither stretches the map nor shifts the lookup (VTK's
// pass distorts non-square windows).
int CheckNonSquare()
{
  double rates[2];
  const int widths[2] = { 800, 400 };
  for (int i = 0; i < 2; ++i)
  {
    auto renderer = PlaneAndBox();
    Comparison c;
    RUN(RenderAndCompare(renderer, "{\"resolution\": 2048}", widths[i], 400, c,
      widths[i] == 800 ? "plane+box 800x400" : "plane+box 400x400"));
    CHECK(ShadowPassOf(renderer)->GetViewSamples()->GetNumberOfSamples() == widths[i] * 400);
    CHECK(c.Valid > widths[i] * 400 / 4);
    rates[i] = c.MismatchRate;
  }
  CHECK(rates[0] < 0.002 && rates[1] < 0.002);
  CHECK(std::fabs(rates[0] - rates[1]) < 0.001);
  return EXIT_SUCCESS;
}

// torture/point_light_in_room.json: a point light in a closed room. Seen from four corners
// of the room, every one of the six room faces (floor, ceiling, four walls) gets shadow
// samples from the furniture with cube maps (all six directions) and with dual-paraboloid
// maps (both hemispheres), as in the reference.
int CheckPointLightInRoom()
{
  struct View
  {
    double Position[3], FocalPoint[3];
  };
  const View views[] = { { { 4.5, -4.5, 3.5 }, { 0, 0, 1.5 } },
    { { -4.5, 4.5, 0.4 }, { 0.5, -0.5, 3.0 } }, { { 4.5, 4.5, 3.6 }, { -1, -1, 1.0 } },
    { { -4.5, -4.5, 3.6 }, { 1, 1, 1.0 } } };
  for (const char* point : { "cube", "paraboloid" })
  {
    vtkIdType seen[6] = { 0 }, shadowed[6] = { 0 }, refShadowed[6] = { 0 };
    for (const View& view : views)
    {
      vtkNew<vtkPenumbraSceneReader> reader;
      reader->SetFileName(
        (std::string(PENUMBRA_SCENES_DIR) + "/torture/point_light_in_room.json").c_str());
      CHECK(reader->Read());
      vtkRenderer* renderer = reader->GetRenderer();
      vtkCamera* camera = renderer->GetActiveCamera();
      camera->SetPosition(view.Position);
      camera->SetFocalPoint(view.FocalPoint);
      camera->SetViewUp(0, 0, 1);
      camera->SetViewAngle(90);
      renderer->ResetCameraClippingRange();
      auto window = WindowFor(renderer, 200, 150);
      vtkNew<vtkPenumbraTechniques> techniques;
      const std::string options = std::string("{\"point\": \"") + point + "\"}";
      CHECK(techniques->Apply(renderer, "shadowmap", options.c_str()));
      window->Render();
      Comparison c;
      vtkNew<vtkFloatArray> ref;
      RUN(Compare(renderer, 0, c, ref));
      vtkPenumbraShadowMapShadows* technique = TechniqueOf(renderer);
      CHECK(technique != nullptr);
      std::printf("point_light_in_room %-10s camera (%4.1f %4.1f %3.1f) valid %lld mismatches "
                  "%lld rate %.5f views %d\n",
        point, view.Position[0], view.Position[1], view.Position[2],
        static_cast<long long>(c.Valid), static_cast<long long>(c.Mismatches), c.MismatchRate,
        technique->GetNumberOfViews());
      CHECK(technique->GetNumberOfViews() >= 2);
      CHECK(c.MismatchRate < 0.003); // measured 1e-4 (cube), 4e-4 (paraboloid) from the corner
      // Per room face (dominant normal axis and sign): samples seen, shadowed by technique
      // and reference. Only the room's faces (the prop with the largest bounds) count.
      vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
      vtkPenumbraViewSamples* samples = pass->GetViewSamples();
      vtkFloatArray* vis = pass->GetVisibility(0);
      int roomProp = -1;
      double roomSize = -1.0;
      for (int i = 0; i < pass->GetGeometry()->GetNumberOfProps(); ++i)
      {
        const double* b = pass->GetGeometry()->GetProp(i)->GetBounds();
        const double size = (b[1] - b[0]) + (b[3] - b[2]) + (b[5] - b[4]);
        if (size > roomSize)
        {
          roomSize = size;
          roomProp = i;
        }
      }
      for (vtkIdType s = 0; s < samples->GetNumberOfSamples(); ++s)
      {
        if (samples->GetPropIndices()->GetValue(s) != roomProp)
        {
          continue;
        }
        double nrm[3];
        samples->GetNormals()->GetTuple(s, nrm);
        int axis = 0;
        for (int a = 1; a < 3; ++a)
        {
          axis = std::fabs(nrm[a]) > std::fabs(nrm[axis]) ? a : axis;
        }
        const int face = 2 * axis + (nrm[axis] < 0.0);
        ++seen[face];
        shadowed[face] += vis->GetValue(s) == 0.0f;
        refShadowed[face] += ref->GetValue(s) == 0.0f;
      }
      window->RemoveRenderer(renderer);
      window->Finalize();
    }
    const char* names[6] = { "-x wall", "+x wall", "-y wall", "+y wall", "floor", "ceiling" };
    for (int face = 0; face < 6; ++face)
    {
      // Inward normals: the face with normal +x is the -x wall.
      std::printf("  %-10s %-8s seen %6lld, shadowed %6lld (reference %6lld)\n", point, names[face],
        static_cast<long long>(seen[face]), static_cast<long long>(shadowed[face]),
        static_cast<long long>(refShadowed[face]));
      CHECK(seen[face] >= 500);
      CHECK(refShadowed[face] >= 50);
      CHECK(shadowed[face] >= 50);
      // The technique's shadow on each face matches the reference's in size.
      CHECK(std::llabs(static_cast<long long>(shadowed[face] - refShadowed[face])) <=
        std::max<long long>(10, refShadowed[face] / 20));
    }
  }
  return EXIT_SUCCESS;
}

// A PBR receiver is darkened in the shadow (pixel statistics through the shadow pass): the
// plane's shadowed samples are much darker than its lit ones on screen.
int CheckPBRReceiver()
{
  vtkActor* plane = nullptr;
  auto renderer = PlaneAndBox(&plane);
  plane->GetProperty()->SetInterpolationToPBR();
  plane->GetProperty()->SetRoughness(0.6);
  plane->GetProperty()->SetMetallic(0.0);
  vtkCamera* cam = renderer->GetActiveCamera();
  cam->ParallelProjectionOn();
  cam->SetPosition(0, 0, 10);
  cam->SetFocalPoint(0, 0, 0);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(3.0);
  renderer->ResetCameraClippingRange();
  const int w = 160, h = 160;
  auto window = WindowFor(renderer, w, h);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"resolution\": 1024}"));
  window->Render();
  vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
  vtkFloatArray* vis = pass->GetVisibility(0);
  CHECK(vis != nullptr);
  vtkNew<vtkUnsignedCharArray> pixels;
  window->GetPixelData(0, 0, w - 1, h - 1, 0, pixels);
  // Samples are stored row by row from the bottom, like the pixels.
  vtkPenumbraViewSamples* samples = pass->GetViewSamples();
  CHECK(samples->GetNumberOfSamples() == w * h);
  double sum[2] = { 0, 0 };
  vtkIdType count[2] = { 0, 0 };
  int planeProp = -1;
  for (int i = 0; i < pass->GetGeometry()->GetNumberOfProps(); ++i)
  {
    if (pass->GetGeometry()->GetProp(i) == plane)
    {
      planeProp = i;
    }
  }
  CHECK(planeProp >= 0);
  for (vtkIdType s = 0; s < w * h; ++s)
  {
    if (samples->GetPropIndices()->GetValue(s) != planeProp)
    {
      continue;
    }
    const float v = vis->GetValue(s);
    if (v != 0.0f && v != 1.0f)
    {
      continue;
    }
    const unsigned char* p = pixels->GetPointer(3 * s);
    const int lit = v == 1.0f;
    sum[lit] += (p[0] + p[1] + p[2]) / 3.0;
    ++count[lit];
  }
  CHECK(count[0] > 100 && count[1] > 100);
  const double shadowMean = sum[0] / count[0], litMean = sum[1] / count[1];
  std::printf("PBR plane: shadowed %lld px mean %.1f, lit %lld px mean %.1f\n",
    static_cast<long long>(count[0]), shadowMean, static_cast<long long>(count[1]), litMean);
  CHECK(litMean > 2.0 * shadowMean + 20.0);
  window->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// Maps are rendered again only when the light, the casters or the camera change; lights
// that are off get none.
int CheckMapCache()
{
  auto renderer = PlaneAndBox();
  auto window = WindowFor(renderer, 128, 96);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"resolution\": 512}"));
  window->Render();
  vtkPenumbraShadowMapShadows* technique = TechniqueOf(renderer);
  CHECK(technique != nullptr);
  const int first = technique->GetNumberOfMapRenders();
  CHECK(first == 1);
  window->Render(); // nothing changed
  CHECK(technique->GetNumberOfMapRenders() == first);
  auto* light = vtkLight::SafeDownCast(renderer->GetLights()->GetItemAsObject(0));
  CHECK(light != nullptr);
  light->SetPosition(1.4, 0.8, 3.0); // the light moved
  window->Render();
  CHECK(technique->GetNumberOfMapRenders() == first + 1);
  renderer->GetActiveCamera()->Azimuth(10.0); // the view (and the fit) changed
  renderer->ResetCameraClippingRange();
  window->Render();
  CHECK(technique->GetNumberOfMapRenders() == first + 2);
  window->Render();
  CHECK(technique->GetNumberOfMapRenders() == first + 2);

  // Off: lit everywhere and no map, whether or not the pass asks the technique at all (VTK
  // would light the scene with a new headlight instead: not here).
  renderer->AutomaticLightCreationOff();
  light->SwitchOff();
  window->Render();
  CHECK(technique->GetNumberOfMapRenders() == first + 2);
  vtkPenumbraShadowPass* pass = ShadowPassOf(renderer);
  vtkNew<vtkFloatArray> vis;
  CHECK(technique->ComputeVisibility(
    renderer, pass->GetGeometry(), pass->GetViewSamples(), light, vis));
  CHECK(technique->GetNumberOfMapRenders() == first + 2);
  CHECK(technique->GetNumberOfViews() == 0);
  CHECK(vis->GetNumberOfTuples() == pass->GetViewSamples()->GetNumberOfSamples());
  for (vtkIdType s = 0; s < vis->GetNumberOfTuples(); ++s)
  {
    CHECK(vis->GetValue(s) == -1.0f || vis->GetValue(s) == 1.0f);
  }
  window->RemoveRenderer(renderer);
  window->Finalize();
  return EXIT_SUCCESS;
}

// Direction -> paraboloid coordinates -> direction, including the z -> -1 pole of the front
// paraboloid and the equator seam between the hemispheres.
int CheckParaboloidRoundTrip()
{
  std::vector<std::array<double, 3>> directions;
  const int count = 20000;
  for (int i = 0; i < count; ++i)
  {
    // Fibonacci sphere.
    const double z = 1.0 - 2.0 * (i + 0.5) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = i * 2.399963229728653;
    directions.push_back({ r * std::cos(phi), r * std::sin(phi), z });
  }
  for (double e : { 0.0, 1e-12, 1e-9, 1e-6, 1e-3, 1e-2 })
  {
    for (int k = 0; k < 16; ++k)
    {
      const double phi = k * 0.3926990816987241;
      const double r = std::sin(e);
      // Near the pole z -> -1 (and +1) and near the seam z -> 0 from both sides.
      directions.push_back({ r * std::cos(phi), r * std::sin(phi), -std::cos(e) });
      directions.push_back({ r * std::cos(phi), r * std::sin(phi), std::cos(e) });
      directions.push_back({ std::cos(e) * std::cos(phi), std::cos(e) * std::sin(phi), -r });
      directions.push_back({ std::cos(e) * std::cos(phi), std::cos(e) * std::sin(phi), r });
    }
  }
  double worst = 0.0;
  for (const auto& d : directions)
  {
    double xy[2], back[3];
    const int hemisphere = vtkPenumbraShadowMapShadows::ParaboloidFromDirection(d.data(), xy);
    CHECK(hemisphere == (d[2] >= 0.0 ? 0 : 1));
    CHECK(xy[0] * xy[0] + xy[1] * xy[1] <= 1.0 + 1e-12);
    vtkPenumbraShadowMapShadows::DirectionFromParaboloid(xy, hemisphere, back);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(d.data(), back)));
  }
  std::printf(
    "paraboloid round trip: %zu directions, worst error %.3g\n", directions.size(), worst);
  CHECK(worst < 1e-5);
  return EXIT_SUCCESS;
}

int CheckBadInput()
{
  vtkNew<vtkPenumbraShadowMapShadows> technique;
  vtkNew<vtkFloatArray> out;
  vtkNew<vtkLight> light;
  const int display = vtkObject::GetGlobalWarningDisplay();
  vtkObject::GlobalWarningDisplayOff();
  const int refused = technique->ComputeVisibility(nullptr, nullptr, nullptr, light, out);
  vtkObject::SetGlobalWarningDisplay(display);
  CHECK(refused == 0);
  CHECK(technique->GetNumberOfMapRenders() == 0);
  vtkNew<vtkPenumbraTechniques> techniques;
  vtkNew<vtkRenderer> renderer;
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"resolution\": 32}") == 0);
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"filter\": \"box\"}") == 0);
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"pcf_kernel\": 4}") == 0);
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"bias\": -1}") == 0);
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"point\": \"sphere\"}") == 0);
  CHECK(techniques->Apply(renderer, "shadowmap", "{\"resolutoin\": 512}") == 0);
  CHECK(techniques->Apply(renderer, "shadowmap",
          "{\"resolution\": 512, \"filter\": \"pcf\", \"pcf_kernel\": 7, \"bias\": 0.001, "
          "\"slope_bias\": 2, \"depth\": \"midpoint\", \"point\": \"paraboloid\"}") == 1);
  vtkPenumbraShadowMapShadows* applied = TechniqueOf(renderer);
  CHECK(applied != nullptr);
  CHECK(applied->GetResolution() == 512 && applied->GetPCFKernel() == 7);
  CHECK(applied->GetFilter() == vtkPenumbraShadowMapShadows::FILTER_PCF);
  CHECK(applied->GetDepthMode() == vtkPenumbraShadowMapShadows::DEPTH_MIDPOINT);
  CHECK(applied->GetPointMode() == vtkPenumbraShadowMapShadows::POINT_PARABOLOID);
  return EXIT_SUCCESS;
}
}

// RESM (Ferko 2013): a 6 x 6 m plane seen straight down by a parallel camera, lit straight
// down: a sample's map step per pixel is the pixel size over the fitted extent, so the
// need along each axis is the plane's width in pixels (closed form: 6 m / (8 m / 512 px) =
// 384, less one pixel for the sample centres, plus the fit's 1e-3 padding), on the GPU and
// the CPU path alike. The map side is rounded up to 64 texels and follows the view with
// hysteresis: a need 14 % lower keeps it, a much lower one shrinks it, a higher one grows it.
vtkSmartPointer<vtkRenderer> PlaneFromAbove(double parallelScale)
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  vtkNew<vtkPlaneSource> plane;
  plane->SetOrigin(-3, -3, 0);
  plane->SetPoint1(3, -3, 0);
  plane->SetPoint2(-3, 3, 0);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(plane->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  renderer->AddActor(actor);
  vtkNew<vtkLight> light;
  light->SetLightTypeToSceneLight();
  light->SetPositional(false);
  light->SetPosition(0, 0, 1);
  light->SetFocalPoint(0, 0, 0);
  renderer->AddLight(light);
  vtkCamera* cam = renderer->GetActiveCamera();
  cam->SetParallelProjection(true);
  cam->SetPosition(0, 0, 10);
  cam->SetFocalPoint(0, 0, 0);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(parallelScale);
  renderer->ResetCameraClippingRange();
  return renderer;
}

int CheckRESMClosedForm()
{
  for (const char* options : { "{}", "{\"lookup\": \"cpu\"}" })
  {
    auto renderer = PlaneFromAbove(4.0);
    auto window = WindowFor(renderer, 512, 512);
    vtkNew<vtkPenumbraTechniques> techniques;
    CHECK(techniques->Apply(renderer, "resm", options));
    vtkPenumbraShadowMapShadows* technique = TechniqueOf(renderer);
    CHECK(technique != nullptr);
    // Nothing casts onto the plane: the maps are fitted and sized all the same.
    auto sizeAt = [&](double scale, int size[2], double need[2])
    {
      renderer->GetActiveCamera()->SetParallelScale(scale);
      window->Render();
      technique->GetLastMapSize(size);
      technique->GetLastEstimate(need);
      std::printf("resm %-20s scale %.1f need %.1f x %.1f map %d x %d\n", options, scale, need[0],
        need[1], size[0], size[1]);
    };
    int size[2];
    double need[2];
    sizeAt(4.0, size, need);
    const double expected = 383.0 * (1.0 + 2e-3);
    CHECK(std::abs(need[0] - expected) < 0.01 * expected);
    CHECK(std::abs(need[1] - expected) < 0.01 * expected);
    CHECK(size[0] == 384 && size[1] == 384);
    sizeAt(3.6, size, need); // need about 426: rounded up to 448
    CHECK(size[0] == 448 && size[1] == 448);
    sizeAt(4.0, size, need); // 384 again, within 15 % of 448: kept
    CHECK(size[0] == 448 && size[1] == 448);
    sizeAt(6.0, size, need); // need about 256: shrinks
    CHECK(size[0] == 256 && size[1] == 256);
    sizeAt(3.6, size, need); // grows back at once
    CHECK(size[0] == 448 && size[1] == 448);
    window->RemoveRenderer(renderer);
    window->Finalize();
  }
  return EXIT_SUCCESS;
}

// RESM's mismatch falls as the largest allowed map rises; at the estimate (no cap) it is as
// small as a square map of the estimate's larger side, within a stated margin.
int CheckRESMSeries()
{
  const int caps[] = { 128, 512, 8192 };
  double rates[3];
  int largest[3];
  for (int i = 0; i < 3; ++i)
  {
    auto renderer = PlaneAndBox();
    Comparison c;
    RUN(RenderAndCompare(renderer, "{\"max_resolution\": " + std::to_string(caps[i]) + "}", 320,
      240, c, "plane+box directional", "resm"));
    rates[i] = c.MismatchRate;
    int size[2];
    TechniqueOf(renderer)->GetLastMapSize(size);
    largest[i] = std::max(size[0], size[1]);
    CHECK(largest[i] <= caps[i]);
  }
  CHECK(rates[0] >= rates[1] && rates[1] >= rates[2] && rates[0] > rates[2]);
  auto renderer = PlaneAndBox();
  Comparison square;
  RUN(RenderAndCompare(renderer, "{\"resolution\": " + std::to_string(largest[2]) + "}", 320, 240,
    square, "plane+box directional"));
  CHECK(rates[2] <= 1.5 * square.MismatchRate + 1e-4);
  return EXIT_SUCCESS;
}

// Brabec 2003, ch. 4.2.2: a long thin strip (8 x 1 m) at 45 degrees to the light's in-plane
// basis (world x and y for a light from overhead), three boxes above it, on a 64^2 map. The
// axis-aligned fit covers the strip's 6 x 6 m bounding square; the minimum-area rectangle
// lies along the strip (7.8 x 1.2 m with the 4 x 4-sample tile boxes' reach), more than 3.5
// times smaller, and the mismatch is no worse (the texels are smaller across the strip but
// longer along it: a square map of a long rectangle). "square" has the shortest longer side
// (6.14 against 6.23 m; its mismatch, 1.3e-2 against 1.1e-2, follows how the coarse texels
// meet the shadow edges, not asserted). For every fit the GPU frame path and the CPU path
// fit the same rectangle and their lookups agree.
vtkSmartPointer<vtkRenderer> DiagonalStrip()
{
  auto renderer = vtkSmartPointer<vtkRenderer>::New();
  const double d = 4.0 / std::sqrt(2.0), w = 0.5 / std::sqrt(2.0);
  vtkNew<vtkPlaneSource> strip;
  strip->SetOrigin(-d + w, -d - w, 0);
  strip->SetPoint1(d + w, d - w, 0);
  strip->SetPoint2(-d - w, -d + w, 0);
  vtkNew<vtkCubeSource> boxes[3];
  for (int i = 0; i < 3; ++i)
  {
    const double c = 1.8 * (i - 1); // along the strip
    boxes[i]->SetBounds(c - 0.25, c + 0.25, c - 0.25, c + 0.25, 0.5, 0.8);
  }
  penumbra_technique_tests::AddSources(renderer, { strip, boxes[0], boxes[1], boxes[2] });
  const double from[3] = { 0.2, 0.1, 1.0 }, target[3] = { 0, 0, 0 };
  penumbra_technique_tests::SetLight(
    renderer, penumbra_technique_tests::LightType::Directional, from, target, 0.0);
  vtkCamera* cam = renderer->GetActiveCamera();
  cam->SetPosition(0.5, -0.5, 8); // the strip runs across the window
  cam->SetFocalPoint(0, 0, 0);
  cam->SetViewUp(-1, 1, 0);
  renderer->ResetCamera();
  cam->Dolly(2.5);
  renderer->ResetCameraClippingRange();
  return renderer;
}

int CheckMinimumRectangle()
{
  const char* fits[3] = { "axis", "minimum", "square" };
  const char* lookups[2] = { "gpu", "cpu" };
  double area[3][2], longer[3][2], rate[3][2];
  vtkIdType valid = 0;
  for (int f = 0; f < 3; ++f)
  {
    vtkNew<vtkFloatArray> answers[2];
    for (int l = 0; l < 2; ++l)
    {
      auto renderer = DiagonalStrip();
      auto window = WindowFor(renderer, 256, 128);
      vtkNew<vtkPenumbraTechniques> techniques;
      const std::string options = std::string("{\"resolution\": 64, \"fit_rectangle\": \"") +
        fits[f] + "\", \"lookup\": \"" + lookups[l] + "\"}";
      CHECK(techniques->Apply(renderer, "shadowmap", options.c_str()));
      window->Render();
      Comparison c;
      RUN(Compare(renderer, 0, c));
      double sides[2];
      CHECK(TechniqueOf(renderer)->GetMapFootprint(ShadowPassOf(renderer)->GetLight(0), sides));
      area[f][l] = sides[0] * sides[1];
      longer[f][l] = std::max(sides[0], sides[1]);
      rate[f][l] = c.MismatchRate;
      valid = c.Valid;
      answers[l]->DeepCopy(ShadowPassOf(renderer)->GetVisibility(0));
      std::printf("diagonal strip %-60s valid %lld footprint %.3f x %.3f m rate %.5f\n",
        options.c_str(), static_cast<long long>(c.Valid), sides[0], sides[1], c.MismatchRate);
      window->RemoveRenderer(renderer);
      window->Finalize();
    }
    // Both paths fit the same rectangle; their lookups agree.
    CHECK(std::fabs(area[f][1] - area[f][0]) <= 1e-3 * area[f][0]);
    vtkIdType differ = 0, shadowed = 0;
    for (vtkIdType i = 0; i < answers[0]->GetNumberOfTuples(); ++i)
    {
      differ += answers[0]->GetValue(i) != answers[1]->GetValue(i);
      shadowed += answers[1]->GetValue(i) == 0.0f;
    }
    std::printf("diagonal strip %s: shadowed %lld, gpu vs cpu differ %lld\n", fits[f],
      static_cast<long long>(shadowed), static_cast<long long>(differ));
    CHECK(shadowed > 100);
    CHECK(differ <= valid / 1000);
  }
  CHECK(valid > 4000);
  CHECK(area[1][0] * 3.5 < area[0][0]);
  CHECK(longer[2][0] <= longer[0][0] + 1e-9 && longer[2][0] < longer[1][0]);
  CHECK(rate[1][0] <= rate[0][0] + 1e-4 && rate[1][1] <= rate[0][1] + 1e-4);
  return EXIT_SUCCESS;
}

int TestShadowMapShadows(int, char*[])
{
  RUN(CheckMinimumRectangle());
  RUN(CheckRESMClosedForm());
  RUN(CheckRESMSeries());
  RUN(CheckBadInput());
  RUN(CheckParaboloidRoundTrip());
  RUN(CheckMapCache());
  RUN(CheckLookupsAgree());
  RUN(CheckShaderLookup());
  RUN(CheckSceneFit());
  RUN(CheckSceneFitReadsWhatMatters());
  RUN(CheckBilinearEdges());
  RUN(CheckSoftLimits("pcss"));
  RUN(CheckSoftLimits("single-sample-soft"));
  RUN(CheckResolutionSeries());
  RUN(CheckGrazingLight());
  RUN(CheckNonSquare());
  RUN(CheckPBRReceiver());
  RUN(CheckPointLightInRoom());
  return EXIT_SUCCESS;
}
