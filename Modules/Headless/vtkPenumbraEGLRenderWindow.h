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
 * Rendering always goes to VTK's own offscreen framebuffers, so window sizes are unlimited by
 * any screen and `vtkWindowToImageFilter` / `GetPixelData` read the finished frame. Several
 * windows may live in one process; each owns its context and they share the EGL display.
 *
 * Debian's GLEW is built for GLX: `glewInit()` loads every GL entry point and then fails with
 * GLEW_ERROR_NO_GLX_DISPLAY because no X display exists. That code is treated as success.
 *
 * A failure to create a context (no EGL, no usable device, GL older than 3.2) is reported once
 * with vtkErrorMacro and leaves the window unusable, never crashing: `IsUsable()` says which.
 */

#ifndef vtkPenumbraEGLRenderWindow_h
#define vtkPenumbraEGLRenderWindow_h

#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraHeadlessModule.h" // For export macro

#include <memory> // For std::unique_ptr

class VTKPENUMBRAHEADLESS_EXPORT vtkPenumbraEGLRenderWindow : public vtkOpenGLRenderWindow
{
public:
  static vtkPenumbraEGLRenderWindow* New();
  vtkTypeMacro(vtkPenumbraEGLRenderWindow, vtkOpenGLRenderWindow);
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

  /**
   * True once a context exists and OpenGL 3.2 or newer was initialised on it.
   */
  bool IsUsable() const { return this->Usable; }

  /**
   * Human-readable description of the EGL platform, device and GL renderer in use
   * (empty before the first render).
   */
  const char* GetContextDescription();

  /**
   * Renders if a context could be created; otherwise reports the reason (once) and draws
   * nothing, leaving the window unusable rather than crashing.
   */
  void Render() override;
  void Start() override;
  void Frame() override;
  void Initialize() override;
  void Finalize() override;
  void MakeCurrent() override;
  void ReleaseCurrent() override;
  bool IsCurrent() override;
  void SetSize(int width, int height) override;
  void SetSize(int a[2]) override { this->SetSize(a[0], a[1]); }
  int* GetScreenSize() VTK_SIZEHINT(2) override;
  void SetShowWindow(bool) override;
  const char* ReportCapabilities() override;
  vtkTypeBool IsDirect() override { return this->Usable ? 1 : 0; }
  vtkTypeBool GetEventPending() override { return 0; }
  void* GetGenericContext() override;
  void* GetGenericDisplayId() override;
  void SetWindowName(const char*) override {}
  void SetWindowId(void*) override {}
  void SetParentId(void*) override {}
  void SetDisplayId(void*) override {}
  void SetNextWindowId(void*) override {}
  void SetWindowInfo(const char*) override {}
  void SetNextWindowInfo(const char*) override {}
  void SetParentInfo(const char*) override {}
  void* GetGenericWindowId() override { return nullptr; }
  void* GetGenericParentId() override { return nullptr; }
  void* GetGenericDrawable() override { return nullptr; }
  void HideCursor() override {}
  void ShowCursor() override {}
  void SetFullScreen(vtkTypeBool) override {}
  void WindowRemap() override {}
  bool GetPlatformSupportsRenderWindowSharing() override { return false; }

  /**
   * There is no on-screen framebuffer: the frame stays in VTK's display framebuffer.
   */
  void BlitDisplayFramebuffersToHardware() override {}

protected:
  vtkPenumbraEGLRenderWindow();
  ~vtkPenumbraEGLRenderWindow() override;

  void CreateAWindow() override;
  void DestroyWindow() override;
  void OpenGLInitContext() override;
  int ReadPixels(
    const vtkRecti& rect, int front, int glFormat, int glType, void* data, int right) override;

  int DeviceIndex;
  bool Usable;

private:
  vtkPenumbraEGLRenderWindow(const vtkPenumbraEGLRenderWindow&) = delete;
  void operator=(const vtkPenumbraEGLRenderWindow&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
