#include "vtkPenumbraEGLRenderWindow.h"

#include "vtkObjectFactory.h"
#include "vtkPenumbraOSMesaRenderWindow.h"
#include "vtk_glew.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

namespace
{
bool HasExtension(const char* list, const char* name)
{
  if (!list)
  {
    return false;
  }
  const size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
  {
    const bool startOk = (p == list || p[-1] == ' ');
    const bool endOk = (p[n] == ' ' || p[n] == '\0');
    if (startOk && endOk)
    {
      return true;
    }
  }
  return false;
}

// eglInitialize may be called repeatedly on one display, but eglTerminate ends it for every
// window sharing it; count users so the last window alone terminates.
// Allocated on first use and never destroyed: a window may be destroyed after this file's
// static objects, e.g. ParaView's process window, which pvpython destroys in its exit-time
// cleanup after a script's sys.exit() has already run the static destructors (locking a
// destroyed mutex and erasing from a destroyed map corrupted the heap).
struct DisplayRegistry
{
  std::mutex Mutex;
  std::map<EGLDisplay, int> Users;
};

DisplayRegistry& Displays()
{
  static DisplayRegistry* registry = new DisplayRegistry;
  return *registry;
}

struct OpenedDisplay
{
  EGLDisplay Display = EGL_NO_DISPLAY;
  std::string Description;
  std::string Error;
};

OpenedDisplay OpenDisplay(int deviceIndex)
{
  OpenedDisplay out;
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto getPlatformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
    eglGetProcAddress("eglGetPlatformDisplayEXT"));
  auto queryDevices =
    reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto queryDeviceString =
    reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));

  EGLDisplay candidate = EGL_NO_DISPLAY;
  if (getPlatformDisplay && queryDevices &&
    HasExtension(clientExtensions, "EGL_EXT_platform_device"))
  {
    EGLint count = 0;
    queryDevices(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(static_cast<size_t>(count > 0 ? count : 0));
    if (count > 0)
    {
      queryDevices(count, devices.data(), &count);
    }
    if (deviceIndex >= 0)
    {
      if (deviceIndex >= count)
      {
        std::ostringstream msg;
        msg << "EGL device " << deviceIndex << " requested but only " << count
            << " device(s) exist";
        out.Error = msg.str();
        return out;
      }
      candidate = getPlatformDisplay(
        EGL_PLATFORM_DEVICE_EXT, devices[static_cast<size_t>(deviceIndex)], nullptr);
      out.Description = "EGL device " + std::to_string(deviceIndex);
    }
    else
    {
      // Prefer real hardware (e.g. an NVIDIA GPU); Mesa's software device is handled below
      // through the surfaceless platform, which is what it is meant for.
      for (EGLint i = 0; i < count && candidate == EGL_NO_DISPLAY; ++i)
      {
        const char* deviceExtensions = queryDeviceString
          ? queryDeviceString(devices[static_cast<size_t>(i)], EGL_EXTENSIONS)
          : nullptr;
        if (HasExtension(deviceExtensions, "EGL_MESA_device_software"))
        {
          continue;
        }
        EGLDisplay d =
          getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[static_cast<size_t>(i)], nullptr);
        EGLint major = 0, minor = 0;
        if (d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor) == EGL_TRUE)
        {
          candidate = d;
          out.Description = "EGL hardware device " + std::to_string(i);
        }
      }
    }
  }
  else if (deviceIndex >= 0)
  {
    out.Error = "an EGL device index was requested but EGL_EXT_platform_device is not available";
    return out;
  }

  if (candidate == EGL_NO_DISPLAY && getPlatformDisplay &&
    HasExtension(clientExtensions, "EGL_MESA_platform_surfaceless"))
  {
    candidate = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    out.Description = "Mesa surfaceless platform";
  }
  if (candidate == EGL_NO_DISPLAY)
  {
    out.Error = "no EGL device and no EGL_MESA_platform_surfaceless: install Mesa's EGL "
                "(libegl-mesa0) or a GPU driver with EGL device support";
    return out;
  }

  EGLint major = 0, minor = 0;
  if (eglInitialize(candidate, &major, &minor) != EGL_TRUE)
  {
    std::ostringstream msg;
    msg << "eglInitialize failed on " << out.Description << " (EGL error 0x" << std::hex
        << eglGetError() << ")";
    out.Error = msg.str();
    return out;
  }
  if (major < 1 || (major == 1 && minor < 4))
  {
    out.Error = "EGL 1.4 or newer is required for desktop OpenGL";
    eglTerminate(candidate);
    return out;
  }
  if (!HasExtension(eglQueryString(candidate, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
  {
    out.Error = out.Description + " lacks EGL_KHR_surfaceless_context";
    eglTerminate(candidate);
    return out;
  }
  {
    std::lock_guard<std::mutex> lock(Displays().Mutex);
    ++Displays().Users[candidate];
  }
  out.Description += std::string(", EGL ") + std::to_string(major) + "." + std::to_string(minor) +
    " (" + eglQueryString(candidate, EGL_VENDOR) + ")";
  out.Display = candidate;
  return out;
}

void CloseDisplay(EGLDisplay display)
{
  DisplayRegistry& displays = Displays();
  std::lock_guard<std::mutex> lock(displays.Mutex);
  auto it = displays.Users.find(display);
  if (it != displays.Users.end() && --it->second == 0)
  {
    displays.Users.erase(it);
    eglTerminate(display);
  }
}

int DefaultDeviceIndex()
{
  const char* env = std::getenv("PENUMBRA_EGL_DEVICE");
  if (env && *env)
  {
    char* end = nullptr;
    long v = std::strtol(env, &end, 10);
    if (end && *end == '\0' && v >= 0 && v < 1024)
    {
      return static_cast<int>(v);
    }
  }
  return -1;
}
}

struct vtkPenumbraEGLRenderWindow::Internals
{
  EGLDisplay Display = EGL_NO_DISPLAY;
  EGLContext Context = EGL_NO_CONTEXT;
};

vtkStandardNewMacro(vtkPenumbraEGLRenderWindow);

vtkPenumbraEGLRenderWindow::vtkPenumbraEGLRenderWindow()
  : DeviceIndex(DefaultDeviceIndex())
  , Impl(new Internals)
{
}

vtkPenumbraEGLRenderWindow::~vtkPenumbraEGLRenderWindow()
{
  this->Finalize();
}

bool vtkPenumbraEGLRenderWindow::HasContext()
{
  return this->Impl->Context != EGL_NO_CONTEXT;
}

bool vtkPenumbraEGLRenderWindow::CreateContext(std::string& why)
{
  Internals& impl = *this->Impl;
  auto fail = [&](const std::string& reason)
  {
    if (impl.Display != EGL_NO_DISPLAY)
    {
      CloseDisplay(impl.Display);
      impl.Display = EGL_NO_DISPLAY;
    }
    why = reason;
    return false;
  };

  OpenedDisplay opened = OpenDisplay(this->DeviceIndex);
  if (opened.Display == EGL_NO_DISPLAY)
  {
    return fail(opened.Error);
  }
  impl.Display = opened.Display;
  this->ContextDescription = opened.Description;

  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE)
  {
    return fail("eglBindAPI(EGL_OPENGL_API) failed: this EGL has no desktop OpenGL");
  }
  // EGL_SURFACE_TYPE defaults to EGL_WINDOW_BIT in eglChooseConfig; no surface is ever made,
  // so any surface type (mask 0) will do. Colour and depth buffers are VTK's own FBOs.
  const EGLint configAttribs[] = { EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
    EGL_NONE };
  EGLConfig config = nullptr;
  EGLint numConfigs = 0;
  if (eglChooseConfig(impl.Display, configAttribs, &config, 1, &numConfigs) != EGL_TRUE ||
    numConfigs < 1)
  {
    return fail("no EGL config renders desktop OpenGL");
  }

  // Newest core profile first; VTK needs 3.2, the shadow techniques use 4.3 features and
  // check for them at run time.
  const int versions[][2] = { { 4, 5 }, { 4, 3 }, { 4, 1 }, { 3, 3 }, { 3, 2 } };
  for (const auto& v : versions)
  {
    const EGLint contextAttribs[] = { EGL_CONTEXT_MAJOR_VERSION, v[0], EGL_CONTEXT_MINOR_VERSION,
      v[1], EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE };
    impl.Context = eglCreateContext(impl.Display, config, EGL_NO_CONTEXT, contextAttribs);
    if (impl.Context != EGL_NO_CONTEXT)
    {
      break;
    }
  }
  if (impl.Context == EGL_NO_CONTEXT)
  {
    return fail("no OpenGL 3.2+ core context could be created");
  }
  vtkPenumbraOSMesaRenderWindow::ReleaseCurrentOSMesa();
  if (eglMakeCurrent(impl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl.Context) != EGL_TRUE)
  {
    eglDestroyContext(impl.Display, impl.Context);
    impl.Context = EGL_NO_CONTEXT;
    return fail("eglMakeCurrent without a surface failed");
  }
  return true;
}

void vtkPenumbraEGLRenderWindow::DestroyContext()
{
  Internals& impl = *this->Impl;
  if (impl.Context != EGL_NO_CONTEXT)
  {
    if (eglGetCurrentContext() == impl.Context)
    {
      eglMakeCurrent(impl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(impl.Display, impl.Context);
    impl.Context = EGL_NO_CONTEXT;
  }
  if (impl.Display != EGL_NO_DISPLAY)
  {
    CloseDisplay(impl.Display);
    impl.Display = EGL_NO_DISPLAY;
  }
}

void vtkPenumbraEGLRenderWindow::MakeCurrent()
{
  Internals& impl = *this->Impl;
  if (impl.Context != EGL_NO_CONTEXT && eglGetCurrentContext() != impl.Context)
  {
    // glvnd keeps one current context per thread: an OSMesa window's must be released first.
    vtkPenumbraOSMesaRenderWindow::ReleaseCurrentOSMesa();
    eglMakeCurrent(impl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl.Context);
  }
}

void vtkPenumbraEGLRenderWindow::ReleaseCurrent()
{
  Internals& impl = *this->Impl;
  if (impl.Context != EGL_NO_CONTEXT && eglGetCurrentContext() == impl.Context)
  {
    eglMakeCurrent(impl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  }
}

bool vtkPenumbraEGLRenderWindow::IsCurrent()
{
  return this->Impl->Context != EGL_NO_CONTEXT && eglGetCurrentContext() == this->Impl->Context;
}

void* vtkPenumbraEGLRenderWindow::GetGenericContext()
{
  return this->Impl->Context;
}

void* vtkPenumbraEGLRenderWindow::GetGenericDisplayId()
{
  return this->Impl->Display;
}

int vtkPenumbraEGLRenderWindow::GetColorBufferSizes(int* rgba)
{
  if (!rgba)
  {
    return 0;
  }
  if (this->Initialized && this->HasContext())
  {
    this->MakeCurrent();
    GLint bound = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    if (bound != 0)
    {
      return this->Superclass::GetColorBufferSizes(rgba);
    }
  }
  for (int i = 0; i < 4; ++i)
  {
    rgba[i] = 8;
  }
  return 32;
}

void vtkPenumbraEGLRenderWindow::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "DeviceIndex: " << this->DeviceIndex << "\n";
}
