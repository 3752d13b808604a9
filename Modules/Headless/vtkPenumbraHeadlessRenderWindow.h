/**
 * @class   vtkPenumbraHeadlessRenderWindow
 * @brief   Base of the render windows that need no window system (EGL, OSMesa).
 *
 * Debian 12's VTK 9.1 is built for X only. Its subclasses create an OpenGL 3.2+ core context
 * some other way (vtkPenumbraEGLRenderWindow: EGL without a surface;
 * vtkPenumbraOSMesaRenderWindow: Mesa's off-screen library) and everything else is shared
 * here: rendering always goes to VTK's own offscreen framebuffers, so window sizes are
 * limited by no screen and `vtkWindowToImageFilter` / `GetPixelData` read the finished frame;
 * a failure to create a context is reported once with vtkErrorMacro and leaves the window
 * unusable (`IsUsable()`), never crashing; sizes below 1 pixel are refused.
 *
 * Debian's GLEW is built for GLX: `glewInit()` loads every GL entry point and then fails with
 * GLEW_ERROR_NO_GLX_DISPLAY because no X display exists. That code is treated as success.
 */

#ifndef vtkPenumbraHeadlessRenderWindow_h
#define vtkPenumbraHeadlessRenderWindow_h

#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraHeadlessModule.h" // For export macro

#include <string> // For the context description

class VTKPENUMBRAHEADLESS_EXPORT vtkPenumbraHeadlessRenderWindow : public vtkOpenGLRenderWindow
{
public:
  vtkTypeMacro(vtkPenumbraHeadlessRenderWindow, vtkOpenGLRenderWindow);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * True once a context exists and OpenGL 3.2 or newer was initialised on it.
   */
  bool IsUsable() const { return this->Usable; }

  /**
   * Human-readable description of the context's platform and device (empty before the
   * first render).
   */
  const char* GetContextDescription() { return this->ContextDescription.c_str(); }

  /**
   * Renders if a context could be created; otherwise reports the reason (once) and draws
   * nothing, leaving the window unusable rather than crashing.
   */
  void Render() override;
  void Start() override;
  void Frame() override;
  void Initialize() override;
  void Finalize() override;
  void SetSize(int width, int height) override;
  void SetSize(int a[2]) override { this->SetSize(a[0], a[1]); }
  int* GetScreenSize() VTK_SIZEHINT(2) override;
  void SetShowWindow(bool) override;
  const char* ReportCapabilities() override;
  vtkTypeBool IsDirect() override { return this->Usable ? 1 : 0; }
  vtkTypeBool GetEventPending() override { return 0; }
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
  vtkPenumbraHeadlessRenderWindow();
  ~vtkPenumbraHeadlessRenderWindow() override;

  ///@{
  /**
   * What a subclass provides: create a context and make it current (false and `why` on
   * failure, with nothing left allocated), whether one exists, and destroy it (releasing it
   * first if current). Subclass destructors must call Finalize(): the base destructor cannot
   * reach these.
   */
  virtual bool CreateContext(std::string& why) = 0;
  virtual bool HasContext() = 0;
  virtual void DestroyContext() = 0;
  ///@}

  void CreateAWindow() override;
  void DestroyWindow() override;
  void OpenGLInitContext() override;
  int ReadPixels(
    const vtkRecti& rect, int front, int glFormat, int glType, void* data, int right) override;

  bool Usable;
  bool FailureReported;
  std::string ContextDescription;
  std::string Capabilities;

private:
  vtkPenumbraHeadlessRenderWindow(const vtkPenumbraHeadlessRenderWindow&) = delete;
  void operator=(const vtkPenumbraHeadlessRenderWindow&) = delete;
};

#endif
