#include "vtkPenumbraOSMesaRenderWindow.h"

#include "vtkObjectFactory.h"

#include <EGL/egl.h>
#include <GL/osmesa.h>

#include <mutex>
#include <string>
#include <vector>

// glvnd's libGLdispatch vendor interface (libglvnd src/GLdispatch/GLdispatch.h, ABI version 1;
// libEGL and libGLX call it the same way). The header is not installed, so the few entry
// points used are declared here with the layouts of glvnd 1.x.
extern "C"
{
  struct PenumbraGLdispatchThreadState
  {
    int tag; // which window-system library owns the state (0 GLX, 1 EGL)
    void (*threadDestroyedCallback)(PenumbraGLdispatchThreadState*);
    void* priv; // managed by libGLdispatch
  };
  using PenumbraGetProcCallback = void* (*)(const char*, void*);
  int __glDispatchGetABIVersion(void);
  void __glDispatchInit(void);
  int __glDispatchNewVendorID(void);
  void* __glDispatchCreateTable(PenumbraGetProcCallback getProcAddress, void* param);
  unsigned char __glDispatchMakeCurrent(
    PenumbraGLdispatchThreadState* state, void* table, int vendorID, const void* patchCallbacks);
  void __glDispatchLoseCurrent(void);
  PenumbraGLdispatchThreadState* __glDispatchGetCurrentThreadState(void);
}

namespace
{
// The GLdispatch ABI this file is written against.
constexpr int GLdispatchABIVersion = 1;

// Neither GLX (0) nor EGL (1): libEGL refuses to replace a state it does not own, which is
// why the EGL window releases this one first.
constexpr int OSMesaStateTag = 0x4f534d;

// One dispatch table serves every OSMesa context: OSMesaGetProcAddress returns Mesa's glapi
// entry points, which dispatch to whichever OSMesa context is current.
struct Dispatch
{
  void* Table = nullptr;
  int Vendor = 0;
  std::string Error;
};

const Dispatch& OSMesaDispatch()
{
  static Dispatch dispatch;
  static std::once_flag once;
  std::call_once(once,
    []
    {
      if (__glDispatchGetABIVersion() != GLdispatchABIVersion)
      {
        dispatch.Error = "glvnd's libGLdispatch has ABI version " +
          std::to_string(__glDispatchGetABIVersion()) + ", this window supports version " +
          std::to_string(GLdispatchABIVersion);
        return;
      }
      __glDispatchInit();
      dispatch.Vendor = __glDispatchNewVendorID();
      dispatch.Table = __glDispatchCreateTable([](const char* name, void*)
        { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); },
        nullptr);
      if (!dispatch.Table)
      {
        dispatch.Error = "glvnd could not create a dispatch table for OSMesa";
      }
    });
  return dispatch;
}

void NoThreadCleanup(PenumbraGLdispatchThreadState*) {}

thread_local PenumbraGLdispatchThreadState ThreadState = { OSMesaStateTag, NoThreadCleanup,
  nullptr };

bool OSMesaIsDispatched()
{
  return __glDispatchGetCurrentThreadState() == &ThreadState;
}

// Makes `context` current for OSMesa and for glvnd's entry points; false with `why` if another
// window system's context cannot be released or OSMesa refuses.
bool Activate(OSMesaContext context, std::vector<unsigned char>& buffer, std::string& why)
{
  const Dispatch& dispatch = OSMesaDispatch();
  if (!dispatch.Table)
  {
    why = dispatch.Error;
    return false;
  }
  if (__glDispatchGetCurrentThreadState() && !OSMesaIsDispatched() &&
    eglGetCurrentContext() != EGL_NO_CONTEXT)
  {
    eglMakeCurrent(eglGetCurrentDisplay(), EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
  if (__glDispatchGetCurrentThreadState() && !OSMesaIsDispatched())
  {
    why = "another window system (GLX) has a current OpenGL context on this thread";
    return false;
  }
  // VTK renders into its own framebuffer objects: OSMesa's buffer only has to exist.
  if (!OSMesaMakeCurrent(context, buffer.data(), GL_UNSIGNED_BYTE, 4, 4))
  {
    why = "OSMesaMakeCurrent failed";
    return false;
  }
  if (!OSMesaIsDispatched() &&
    !__glDispatchMakeCurrent(&ThreadState, dispatch.Table, dispatch.Vendor, nullptr))
  {
    why = "glvnd refused to dispatch OpenGL to OSMesa";
    return false;
  }
  return true;
}
}

struct vtkPenumbraOSMesaRenderWindow::Internals
{
  OSMesaContext Context = nullptr;
  std::vector<unsigned char> Buffer = std::vector<unsigned char>(4 * 4 * 4, 0);
};

vtkStandardNewMacro(vtkPenumbraOSMesaRenderWindow);

vtkPenumbraOSMesaRenderWindow::vtkPenumbraOSMesaRenderWindow()
  : Impl(new Internals)
{
}

vtkPenumbraOSMesaRenderWindow::~vtkPenumbraOSMesaRenderWindow()
{
  this->Finalize();
}

bool vtkPenumbraOSMesaRenderWindow::HasContext()
{
  return this->Impl->Context != nullptr;
}

bool vtkPenumbraOSMesaRenderWindow::CreateContext(std::string& why)
{
  Internals& impl = *this->Impl;
  // Newest core profile first; VTK needs 3.2, the shadow techniques use 4.3 features and
  // check for them at run time. Depth and stencil belong to VTK's framebuffers.
  const int versions[][2] = { { 4, 5 }, { 4, 3 }, { 4, 1 }, { 3, 3 }, { 3, 2 } };
  for (const auto& v : versions)
  {
    const int attribs[] = { OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS,
      8, OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, v[0],
      OSMESA_CONTEXT_MINOR_VERSION, v[1], 0 };
    impl.Context = OSMesaCreateContextAttribs(attribs, nullptr);
    if (impl.Context)
    {
      break;
    }
  }
  if (!impl.Context)
  {
    why = "OSMesa could not create an OpenGL 3.2+ core context";
    return false;
  }
  if (!Activate(impl.Context, impl.Buffer, why))
  {
    OSMesaDestroyContext(impl.Context);
    impl.Context = nullptr;
    return false;
  }
  this->ContextDescription = "OSMesa (Mesa off-screen, dispatched through glvnd)";
  return true;
}

void vtkPenumbraOSMesaRenderWindow::DestroyContext()
{
  Internals& impl = *this->Impl;
  if (!impl.Context)
  {
    return;
  }
  if (OSMesaGetCurrentContext() == impl.Context)
  {
    ReleaseCurrentOSMesa();
  }
  OSMesaDestroyContext(impl.Context);
  impl.Context = nullptr;
}

void vtkPenumbraOSMesaRenderWindow::MakeCurrent()
{
  Internals& impl = *this->Impl;
  if (impl.Context && !this->IsCurrent())
  {
    std::string why;
    if (!Activate(impl.Context, impl.Buffer, why))
    {
      vtkErrorMacro("Cannot make the OSMesa context current: " << why);
    }
  }
}

void vtkPenumbraOSMesaRenderWindow::ReleaseCurrent()
{
  if (this->Impl->Context && this->IsCurrent())
  {
    ReleaseCurrentOSMesa();
  }
}

bool vtkPenumbraOSMesaRenderWindow::IsCurrent()
{
  return this->Impl->Context && OSMesaGetCurrentContext() == this->Impl->Context &&
    OSMesaIsDispatched();
}

void vtkPenumbraOSMesaRenderWindow::ReleaseCurrentOSMesa()
{
  if (OSMesaIsDispatched())
  {
    __glDispatchLoseCurrent();
  }
  if (OSMesaGetCurrentContext())
  {
    OSMesaMakeCurrent(nullptr, nullptr, GL_UNSIGNED_BYTE, 0, 0);
  }
}

void* vtkPenumbraOSMesaRenderWindow::GetGenericContext()
{
  return this->Impl->Context;
}

void vtkPenumbraOSMesaRenderWindow::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
