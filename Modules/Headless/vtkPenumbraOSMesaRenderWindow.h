/**
 * @class   vtkPenumbraOSMesaRenderWindow
 * @brief   OpenGL render window on Mesa's off-screen library (OSMesa), without any X server.
 *
 * The alternative to vtkPenumbraEGLRenderWindow for build machines where EGL is unavailable
 * or unwanted: Debian's `libosmesa6` gives an OpenGL 4.5..3.2 core context on llvmpipe (the
 * same software rasterizer Mesa's EGL uses) with no display connection at all. Chosen by
 * `PENUMBRA_HEADLESS=osmesa` (vtkPenumbraHeadlessFactory); EGL stays the default.
 *
 * Debian's VTK and GLEW call OpenGL through glvnd (libOpenGL, libGLX), whose entry points
 * dispatch to the context that EGL or GLX made current; OSMesa does not register with glvnd.
 * So, when this window makes its context current, it also makes current, through glvnd's
 * libGLdispatch vendor interface (the one libEGL and libGLX use, GLdispatch ABI version 1), a
 * dispatch table whose entries are OSMesaGetProcAddress's. VTK, GLEW and the shadow passes
 * then reach OSMesa unchanged; no pass contains window-system code. glvnd allows one current
 * context per thread, so making an OSMesa window current releases a current EGL context and
 * the EGL window releases this one (ReleaseCurrentOSMesa()).
 *
 * Offscreen rendering, sizes, read-back and failure reporting are those of
 * vtkPenumbraHeadlessRenderWindow.
 */

#ifndef vtkPenumbraOSMesaRenderWindow_h
#define vtkPenumbraOSMesaRenderWindow_h

#include "vtkPenumbraHeadlessModule.h" // For export macro
#include "vtkPenumbraHeadlessRenderWindow.h"

#include <memory> // For std::unique_ptr

class VTKPENUMBRAHEADLESS_EXPORT vtkPenumbraOSMesaRenderWindow
  : public vtkPenumbraHeadlessRenderWindow
{
public:
  static vtkPenumbraOSMesaRenderWindow* New();
  vtkTypeMacro(vtkPenumbraOSMesaRenderWindow, vtkPenumbraHeadlessRenderWindow);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  void MakeCurrent() override;
  void ReleaseCurrent() override;
  bool IsCurrent() override;
  void* GetGenericContext() override;
  void* GetGenericDisplayId() override { return nullptr; }

  /**
   * Releases whichever OSMesa context is current on this thread, if any (glvnd allows one
   * current context per thread; the EGL window calls this before making its own current).
   */
  static void ReleaseCurrentOSMesa();

protected:
  vtkPenumbraOSMesaRenderWindow();
  ~vtkPenumbraOSMesaRenderWindow() override;

  bool CreateContext(std::string& why) override;
  bool HasContext() override;
  void DestroyContext() override;

private:
  vtkPenumbraOSMesaRenderWindow(const vtkPenumbraOSMesaRenderWindow&) = delete;
  void operator=(const vtkPenumbraOSMesaRenderWindow&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
