// The OSMesa headless window (PENUMBRA_HEADLESS=osmesa): the same checks as the EGL window's,
// then an EGL and an OSMesa window taking turns on one thread (glvnd's one current context).
#include "vtkPenumbraEGLRenderWindow.h"
#include "vtkPenumbraOSMesaRenderWindow.h"

#include "HeadlessWindowTests.h"

int TestOSMesaRenderWindow(int, char*[])
{
  using headless_window_tests::RedFraction;
  RUN(headless_window_tests::CheckHeadlessWindow<vtkPenumbraOSMesaRenderWindow>());
  vtkNew<vtkPenumbraOSMesaRenderWindow> osmesa;
  vtkNew<vtkPenumbraEGLRenderWindow> egl;
  const double a = RedFraction(osmesa, 64, 64);
  const double b = RedFraction(egl, 64, 64);
  const double c = RedFraction(osmesa, 64, 64);
  std::cout << "OSMesa " << a << " EGL " << b << " OSMesa again " << c << std::endl;
  CHECK(a > 0.2 && a == b && b == c);
  return EXIT_SUCCESS;
}
