// VTK's own shadow-map pass through the headless window: a square occluder over a plane under
// a slanted directional light leaves a dark footprint exactly where geometry says, and the
// rest of the plane stays lit.
#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCameraPass.h"
#include "vtkCubeSource.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkPenumbraHeadlessRenderWindow.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderPassCollection.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSequencePass.h"
#include "vtkShadowMapBakerPass.h"
#include "vtkShadowMapPass.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <cstdlib>
#include <iostream>

int TestHeadlessShadowPass(int, char*[])
{
  const int size = 128;
  vtkSmartPointer<vtkRenderWindow> win =
    vtkSmartPointer<vtkRenderWindow>::Take(vtkRenderWindow::New());
  if (!vtkPenumbraHeadlessRenderWindow::SafeDownCast(win))
  {
    std::cerr << "vtkRenderWindow::New() did not give the headless window" << std::endl;
    return EXIT_FAILURE;
  }
  win->SetSize(size, size);

  vtkNew<vtkPlaneSource> plane; // z = 0, [-2, 2]^2
  plane->SetOrigin(-2, -2, 0);
  plane->SetPoint1(2, -2, 0);
  plane->SetPoint2(-2, 2, 0);
  plane->SetResolution(8, 8);
  vtkNew<vtkCubeSource> occluder; // thin square [-0.5, 0.5]^2 at z = 1
  occluder->SetBounds(-0.5, 0.5, -0.5, 0.5, 0.98, 1.0);

  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0, 0, 0);
  for (vtkPolyDataAlgorithm* src :
    { static_cast<vtkPolyDataAlgorithm*>(plane), static_cast<vtkPolyDataAlgorithm*>(occluder) })
  {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(src->GetOutputPort());
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(1, 1, 1);
    actor->GetProperty()->SetAmbient(0.1);
    actor->GetProperty()->SetDiffuse(0.9);
    actor->GetProperty()->SetSpecular(0.0);
    ren->AddActor(actor);
  }
  // Light travels along (-1, 0, -1): the occluder's shadow is the square shifted by -1 in x.
  vtkNew<vtkLight> light;
  light->SetLightTypeToSceneLight();
  light->SetPositional(false);
  light->SetPosition(1, 0, 1);
  light->SetFocalPoint(0, 0, 0);
  ren->AddLight(light);

  vtkCamera* cam = ren->GetActiveCamera();
  cam->ParallelProjectionOn();
  cam->SetPosition(0, 0, 10);
  cam->SetFocalPoint(0, 0, 0);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(2.0);
  ren->ResetCameraClippingRange();

  vtkNew<vtkShadowMapPass> shadows;
  vtkNew<vtkRenderPassCollection> passes;
  passes->AddItem(shadows->GetShadowMapBakerPass());
  passes->AddItem(shadows);
  vtkNew<vtkSequencePass> seq;
  seq->SetPasses(passes);
  vtkNew<vtkCameraPass> cameraPass;
  cameraPass->SetDelegatePass(seq);
  ren->SetPass(cameraPass);
  win->AddRenderer(ren);
  win->Render();

  vtkNew<vtkUnsignedCharArray> px;
  win->GetPixelData(0, 0, size - 1, size - 1, 0, px);
  auto lum = [&](double x, double y)
  {
    const int col = static_cast<int>((x + 2.0) / 4.0 * size);
    const int row = static_cast<int>((y + 2.0) / 4.0 * size);
    const unsigned char* p = px->GetPointer(3 * (row * size + col));
    return (p[0] + p[1] + p[2]) / 3.0;
  };
  const double shadowed = lum(-1.0, 0.0);
  const double lit = lum(1.2, 0.0);
  const double litAside = lum(-1.0, 1.2);
  std::cout << "shadowed " << shadowed << " lit " << lit << " lit aside " << litAside << std::endl;

  // Count dark plane pixels: the footprint is 1x1 of the 4x4 view, i.e. 1/16 of the image,
  // minus nothing (the occluder does not hide it from straight above).
  long dark = 0;
  for (int row = 0; row < size; ++row)
  {
    for (int col = 0; col < size; ++col)
    {
      const unsigned char* p = px->GetPointer(3 * (row * size + col));
      dark += ((p[0] + p[1] + p[2]) / 3.0 < 60.0) ? 1 : 0;
    }
  }
  const double expected = size * size / 16.0;
  std::cout << "dark pixels " << dark << " expected about " << expected << std::endl;

  bool ok = true;
  ok &= lit > 150.0;
  ok &= litAside > 150.0;
  ok &= shadowed < 60.0;
  ok &= dark > 0.8 * expected && dark < 1.2 * expected;
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
