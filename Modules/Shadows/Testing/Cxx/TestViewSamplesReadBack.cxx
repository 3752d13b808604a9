// vtkPenumbraViewSamplesPass read-back modes on one rendered frame: the positions rebuilt
// from triangle ids and pixel rays (READ_BACK_IDS) lie on their triangles' planes and within
// half a pixel's footprint of the G-buffer's float32 positions (READ_BACK_POSITIONS), with
// the same prop and triangle ids and the same normals, for a perspective and a parallel
// camera. The scene sits at georeferenced coordinates so the rebasing is exercised.
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCameraPass.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraViewSamplesPass.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSphereSource.h"

#include "PenumbraTestMacros.h"

#include <algorithm>
#include <cmath>
#include <iostream>

namespace
{
// A georeferenced offset (metres): large enough that float32 world coordinates would lose
// the scene, small enough that VTK's own float vertex shift keeps the G-buffer accurate.
const double Offset[3] = { 4.5e5, 5.2e6, 120.0 };

struct Frame
{
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkRenderWindow> Window;

  explicit Frame(bool parallel)
  {
    vtkNew<vtkPlaneSource> plane;
    plane->SetOrigin(Offset[0] - 4, Offset[1] - 4, Offset[2]);
    plane->SetPoint1(Offset[0] + 4, Offset[1] - 4, Offset[2]);
    plane->SetPoint2(Offset[0] - 4, Offset[1] + 4, Offset[2]);
    plane->SetResolution(7, 5);
    vtkNew<vtkSphereSource> sphere;
    sphere->SetCenter(Offset[0], Offset[1], Offset[2] + 1.2);
    sphere->SetRadius(1.0);
    sphere->SetThetaResolution(40);
    sphere->SetPhiResolution(30);
    vtkPolyDataAlgorithm* sources[] = { plane, sphere };
    for (vtkPolyDataAlgorithm* source : sources)
    {
      vtkNew<vtkPolyDataMapper> mapper;
      mapper->SetInputConnection(source->GetOutputPort());
      vtkNew<vtkActor> actor;
      actor->SetMapper(mapper);
      this->Renderer->AddActor(actor);
    }
    vtkNew<vtkLight> light;
    light->SetLightTypeToSceneLight();
    light->SetPositional(false);
    light->SetPosition(Offset[0] + 1, Offset[1] + 0.5, Offset[2] + 2);
    light->SetFocalPoint(Offset);
    this->Renderer->AddLight(light);
    vtkCamera* cam = this->Renderer->GetActiveCamera();
    cam->SetParallelProjection(parallel);
    cam->SetPosition(Offset[0] + 5, Offset[1] - 6, Offset[2] + 4);
    cam->SetFocalPoint(Offset[0], Offset[1], Offset[2] + 0.5);
    cam->SetViewUp(0, 0, 1);
    cam->SetViewAngle(40);
    cam->SetParallelScale(3.5);
    this->Renderer->ResetCameraClippingRange();
    this->Window->SetSize(160, 120);
    this->Window->SetMultiSamples(0);
    this->Window->AddRenderer(this->Renderer);
  }
};

// World size of one pixel at a rebased position.
double PixelFootprint(vtkCamera* cam, const double origin[3], const float* p, int height)
{
  if (cam->GetParallelProjection())
  {
    return 2.0 * cam->GetParallelScale() / height;
  }
  double eye[3], dop[3];
  cam->GetPosition(eye);
  cam->GetDirectionOfProjection(dop);
  double depth = 0.0;
  for (int k = 0; k < 3; ++k)
  {
    depth += (p[k] + origin[k] - eye[k]) * dop[k];
  }
  return 2.0 * std::tan(cam->GetViewAngle() * M_PI / 360.0) * depth / height;
}

int CheckReadBackModes(bool parallel)
{
  Frame frame(parallel);
  vtkNew<vtkPenumbraTechniques> techniques;
  CHECK(techniques->Apply(frame.Renderer, "raytraced", ""));
  frame.Window->Render();
  auto* pass = vtkPenumbraShadowPass::GetInstalled(frame.Renderer);
  CHECK(pass != nullptr);
  vtkPenumbraViewSamplesPass* gbuffer = pass->GetViewSamplesPass();
  CHECK(gbuffer->GetReadBackMode() == vtkPenumbraViewSamplesPass::READ_BACK_POSITIONS);
  gbuffer->SetReadBackModeToIds();
  const int w = 160, h = 120;
  vtkNew<vtkPenumbraViewSamples> rebuilt, floats;
  rebuilt->SetSize(w, h);
  floats->SetSize(w, h);
  CHECK(gbuffer->ReadSamples(rebuilt, 0));
  CHECK(gbuffer->GetNumberOfFallbackSamples() == 0);
  gbuffer->SetReadBackModeToPositions();
  CHECK(gbuffer->ReadSamples(floats, 0));
  gbuffer->SetReadBackModeToIds();

  vtkPenumbraSceneGeometry* geometry = pass->GetGeometry();
  double origin[3], bounds[6];
  rebuilt->GetOrigin(origin);
  geometry->GetBounds(bounds);
  const double scale = std::sqrt(std::pow(bounds[1] - bounds[0], 2) +
    std::pow(bounds[3] - bounds[2], 2) + std::pow(bounds[5] - bounds[4], 2));
  vtkCamera* cam = frame.Renderer->GetActiveCamera();
  vtkIdType valid = 0;
  double worstPlane = 0.0, worstShift = 0.0, worstNormal = 1.0;
  for (vtkIdType i = 0; i < rebuilt->GetNumberOfSamples(); ++i)
  {
    CHECK(rebuilt->GetPropIndices()->GetValue(i) == floats->GetPropIndices()->GetValue(i));
    CHECK(rebuilt->GetTriangleIds()->GetValue(i) == floats->GetTriangleIds()->GetValue(i));
    const vtkIdType tri = rebuilt->GetTriangleIds()->GetValue(i);
    if (!rebuilt->IsValid(i) || tri < 0)
    {
      continue;
    }
    ++valid;
    double v[9];
    geometry->GetTriangle(tri, v);
    double n[3] = { (v[4] - v[1]) * (v[8] - v[2]) - (v[5] - v[2]) * (v[7] - v[1]),
      (v[5] - v[2]) * (v[6] - v[0]) - (v[3] - v[0]) * (v[8] - v[2]),
      (v[3] - v[0]) * (v[7] - v[1]) - (v[4] - v[1]) * (v[6] - v[0]) };
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const float* p = rebuilt->GetPositions()->GetPointer(3 * i);
    const float* q = floats->GetPositions()->GetPointer(3 * i);
    const float* pn = rebuilt->GetNormals()->GetPointer(3 * i);
    const float* qn = floats->GetNormals()->GetPointer(3 * i);
    double plane = 0.0, shift = 0.0, agree = 0.0;
    for (int k = 0; k < 3; ++k)
    {
      plane += (p[k] - v[k]) * n[k] / len;
      shift += (p[k] - q[k]) * (p[k] - q[k]);
      agree += pn[k] * qn[k];
    }
    worstPlane = std::max(worstPlane, std::fabs(plane) / scale);
    worstShift = std::max(worstShift, std::sqrt(shift) / PixelFootprint(cam, origin, q, h));
    worstNormal = std::min(worstNormal, agree);
  }
  std::cout << (parallel ? "parallel" : "perspective") << ": " << valid
            << " samples, plane distance / scene scale " << worstPlane
            << ", distance to the G-buffer position / pixel footprint " << worstShift
            << ", lowest normal agreement " << worstNormal << std::endl;
  CHECK(valid > w * h / 3);
  CHECK(worstPlane < 1e-6);
  CHECK(worstShift < 0.5);
  CHECK(worstNormal > 0.999);
  return EXIT_SUCCESS;
}
}

int TestViewSamplesReadBack(int, char*[])
{
  RUN(CheckReadBackModes(false));
  RUN(CheckReadBackModes(true));
  return EXIT_SUCCESS;
}
