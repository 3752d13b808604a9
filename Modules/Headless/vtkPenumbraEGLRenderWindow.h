/**
 * @class   vtkPenumbraEGLRenderWindow
 * @brief   OpenGL render window on an EGL context without any window system.
 *
 * Debian 12's VTK 9.1 is built for X only: its render window needs an X server even for
 * offscreen images. This window creates an OpenGL 4.5..3.2 core context through EGL instead,
 * with no surface at all (EGL_KHR_surfaceless_context). It picks, in this order:
 *
 *  1. the EGL device given by `DeviceIndex` (or the `PENUMBRA_EGL_DEVICE` environment
 *     variable) through EGL_EXT_platform_device, for example an NVIDIA GPU;
 *  2. the first hardware EGL device, if the EGL implementation exposes any;
 *  3. Mesa's surfaceless platform (EGL_MESA_platform_surfaceless), i.e. llvmpipe on a machine
 *     without a GPU.
 *
 * Several windows may live in one process; each owns its context and they share the EGL
 * display. Offscreen rendering, sizes, read-back and failure reporting are those of
 * vtkPenumbraHeadlessRenderWindow: a failure to create a context (no EGL, no usable device, GL
 * older than 3.2) is reported once and leaves the window unusable, never crashing.
 */

#ifndef vtkPenumbraEGLRenderWindow_h
#define vtkPenumbraEGLRenderWindow_h

#include "vtkPenumbraHeadlessModule.h" // For export macro
#include "vtkPenumbraHeadlessRenderWindow.h"

#include <memory> // For std::unique_ptr

class VTKPENUMBRAHEADLESS_EXPORT vtkPenumbraEGLRenderWindow : public vtkPenumbraHeadlessRenderWindow
{
public:
  static vtkPenumbraEGLRenderWindow* New();
  vtkTypeMacro(vtkPenumbraEGLRenderWindow, vtkPenumbraHeadlessRenderWindow);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * EGL device to render on, as an index into eglQueryDevicesEXT's list; -1 (default) picks a
   * hardware device if there is one and Mesa's surfaceless platform otherwise. Must be set
   * before the first render. The `PENUMBRA_EGL_DEVICE` environment variable gives the default.
   */
  vtkSetMacro(DeviceIndex, int);
  vtkGetMacro(DeviceIndex, int);
  ///@}

  void MakeCurrent() override;
  void ReleaseCurrent() override;
  bool IsCurrent() override;
  void* GetGenericContext() override;
  void* GetGenericDisplayId() override;

  /**
   * The colour bits of the bound draw framebuffer. A surfaceless context has no default
   * framebuffer, yet VTK 9.2 (ParaView 5.11's) queries its attachments during initialisation
   * and logs an error for each; VTK 9.1 stayed silent. While the default framebuffer is bound
   * this reports RGBA 8/8/8/8, the format of VTK's offscreen framebuffers that every frame of
   * this window is drawn into; otherwise VTK's own query answers.
   */
  int GetColorBufferSizes(int* rgba) override;

protected:
  vtkPenumbraEGLRenderWindow();
  ~vtkPenumbraEGLRenderWindow() override;

  bool CreateContext(std::string& why) override;
  bool HasContext() override;
  void DestroyContext() override;

  int DeviceIndex;

private:
  vtkPenumbraEGLRenderWindow(const vtkPenumbraEGLRenderWindow&) = delete;
  void operator=(const vtkPenumbraEGLRenderWindow&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
