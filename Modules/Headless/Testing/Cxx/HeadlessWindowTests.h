// Checks shared by the headless windows' tests (EGL, OSMesa): the factory override with
// DISPLAY unset, any size, window-to-image, several windows in one process, clean release and
// re-creation, refused sizes.
#ifndef HeadlessWindowTests_h
#define HeadlessWindowTests_h

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCommand.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPenumbraHeadlessFactory.h"
#include "vtkPointData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkTestErrorObserver.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWindowToImageFilter.h"

#include <cstdlib>
#include <iostream>

#include "PenumbraTestMacros.h"

namespace headless_window_tests
{
// Renders a red sphere on a blue background and returns the fraction of red pixels.
inline double RedFraction(vtkRenderWindow* win, int w, int h)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(32);
  sphere->SetPhiResolution(32);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(sphere->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(1, 0, 0);
  actor->GetProperty()->SetAmbient(1.0);
  actor->GetProperty()->SetDiffuse(0.0);
  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0, 0, 1);
  ren->AddActor(actor);
  win->AddRenderer(ren);
  win->SetSize(w, h);
  win->Render();

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(win);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  vtkImageData* img = grab->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  if (dims[0] != w || dims[1] != h)
  {
    std::cerr << "image is " << dims[0] << "x" << dims[1] << ", expected " << w << "x" << h
              << std::endl;
    return -1.0;
  }
  auto* px = vtkUnsignedCharArray::SafeDownCast(img->GetPointData()->GetScalars());
  long red = 0, blue = 0;
  for (vtkIdType i = 0; i < px->GetNumberOfTuples(); ++i)
  {
    const unsigned char* p = px->GetPointer(3 * i);
    red += (p[0] > 200 && p[1] < 50 && p[2] < 50) ? 1 : 0;
    blue += (p[0] < 50 && p[1] < 50 && p[2] > 200) ? 1 : 0;
  }
  if (red + blue < 0.95 * w * h)
  {
    std::cerr << "unexpected colours: red " << red << " blue " << blue << std::endl;
    return -1.0;
  }
  win->RemoveRenderer(ren);
  return static_cast<double>(red) / (w * h);
}

// The factory gives `Window` (PENUMBRA_HEADLESS chooses it), and it renders as a window must.
template <class Window>
int CheckHeadlessWindow()
{
  CHECK(std::getenv("DISPLAY") == nullptr || *std::getenv("DISPLAY") == '\0');
  CHECK(vtkPenumbraHeadlessFactory::HeadlessRequested());
  CHECK(vtkPenumbraHeadlessFactory::IsInstalled());

  // The factory override: plain VTK code gets the headless window.
  vtkSmartPointer<vtkRenderWindow> win =
    vtkSmartPointer<vtkRenderWindow>::Take(vtkRenderWindow::New());
  CHECK(Window::SafeDownCast(win) != nullptr);

  // Interactors need no X server either: a window with one initialises and renders.
  vtkSmartPointer<vtkRenderWindowInteractor> iren =
    vtkSmartPointer<vtkRenderWindowInteractor>::Take(vtkRenderWindowInteractor::New());
  CHECK(iren->IsA("vtkGenericRenderWindowInteractor"));
  win->SetInteractor(iren);
  iren->Initialize();

  // Square and very non-square windows, both larger than typical screens in one axis.
  const double square = RedFraction(win, 128, 128);
  CHECK(square > 0.2 && square < 0.8);
  const double wide = RedFraction(win, 400, 100);
  CHECK(wide > 0.05 && wide < 0.8);
  const double tall = RedFraction(win, 64, 2500);
  CHECK(tall > 0.001);
  std::cout << "red fractions: square " << square << " wide " << wide << " tall " << tall
            << std::endl;
  std::cout << win->ReportCapabilities() << std::endl;

  // Several windows alive at once, rendered interleaved.
  vtkNew<Window> a;
  vtkNew<Window> b;
  CHECK(RedFraction(a, 96, 64) > 0.1);
  CHECK(RedFraction(b, 64, 96) > 0.1);
  CHECK(RedFraction(a, 96, 64) > 0.1);
  CHECK(a->IsUsable() && b->IsUsable());

  // Release and render again on a fresh context.
  a->Finalize();
  CHECK(!a->IsUsable());
  CHECK(RedFraction(a, 32, 32) > 0.1);

  // Invalid sizes are refused with an error, not allocated.
  vtkNew<vtkTest::ErrorObserver> errors;
  a->AddObserver(vtkCommand::ErrorEvent, errors);
  a->SetSize(0, 10);
  CHECK(errors->GetError());
  CHECK(a->GetSize()[0] == 32);
  return EXIT_SUCCESS;
}
}

#endif
