// The EGL headless window (PENUMBRA_HEADLESS=egl): factory override, sizes, read-back, several
// windows, re-creation, refused sizes.
#include "vtkPenumbraEGLRenderWindow.h"

#include "HeadlessWindowTests.h"

int TestEGLRenderWindow(int, char*[])
{
  return headless_window_tests::CheckHeadlessWindow<vtkPenumbraEGLRenderWindow>();
}
