/**
 * @class   vtkPenumbraHeadlessFactory
 * @brief   Object factory that makes vtkRenderWindow::New() return a headless window.
 *
 * Installed automatically when this module is initialised (C++ `vtk_module_autoinit`, or
 * `import penumbra` in Python) if headless rendering is wanted:
 *
 *  - `PENUMBRA_HEADLESS=1` (or `on`, `egl`): always use vtkPenumbraEGLRenderWindow;
 *  - `PENUMBRA_HEADLESS=osmesa`: always use vtkPenumbraOSMesaRenderWindow (Mesa's off-screen
 *    library instead of EGL);
 *  - `PENUMBRA_HEADLESS=0` (or `off`, `x`): never; VTK's X window is used as usual;
 *  - unset: use the EGL window exactly when `DISPLAY` is unset or empty, i.e. when VTK's X window
 * could only fail with "bad X server connection".
 *
 * When installed, vtkRenderWindowInteractor::New() also returns a
 * vtkGenericRenderWindowInteractor, because VTK's X interactor opens the missing X display
 * as soon as a window initialises it (vtkContextView does). The overrides of every other
 * factory for both classes (VTK's X classes) are disabled, so the choice does not depend on
 * load order.
 */

#ifndef vtkPenumbraHeadlessFactory_h
#define vtkPenumbraHeadlessFactory_h

#include "vtkObjectFactory.h"
#include "vtkPenumbraHeadlessModule.h" // For export macro

class VTKPENUMBRAHEADLESS_EXPORT vtkPenumbraHeadlessFactory : public vtkObjectFactory
{
public:
  static vtkPenumbraHeadlessFactory* New();
  vtkTypeMacro(vtkPenumbraHeadlessFactory, vtkObjectFactory);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  const char* GetVTKSourceVersion() override;
  const char* GetDescription() override { return "Penumbra headless render window"; }

  /**
   * Whether the environment asks for headless rendering (see the class description).
   */
  static bool HeadlessRequested();

  /**
   * Whether the environment asks for the OSMesa window (`PENUMBRA_HEADLESS=osmesa`) rather
   * than the EGL one.
   */
  static bool OSMesaRequested();

  /**
   * Make vtkRenderWindow::New() return the headless window from now on: the OSMesa one if
   * OSMesaRequested(), else the EGL one. Idempotent.
   */
  static void Install();

  /**
   * Undo Install(): VTK's own render window factory is enabled again. Idempotent.
   */
  static void Uninstall();

  /**
   * Whether Install() is in effect.
   */
  static bool IsInstalled();

protected:
  vtkPenumbraHeadlessFactory();
  ~vtkPenumbraHeadlessFactory() override = default;

private:
  vtkPenumbraHeadlessFactory(const vtkPenumbraHeadlessFactory&) = delete;
  void operator=(const vtkPenumbraHeadlessFactory&) = delete;
};

#endif
