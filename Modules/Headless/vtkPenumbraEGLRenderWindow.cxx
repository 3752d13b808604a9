#include "vtkPenumbraEGLRenderWindow.h"

#include "vtkObjectFactory.h"
#include "vtkOpenGLState.h"
#include "vtkRenderer.h"
#include "vtkRendererCollection.h"
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
std::mutex DisplayMutex;
std::map<EGLDisplay, int> DisplayUsers;

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
  auto getPlatformDisplay =
    reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
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
      candidate =
        getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[static_cast<size_t>(deviceIndex)], nullptr);
      out.Description = "EGL device " + std::to_string(deviceIndex);
    }
    else
    {
      // Prefer real hardware (e.g. an NVIDIA GPU); Mesa's software device is handled below
      // through the surfaceless platform, which is what it is meant for.
      for (EGLint i = 0; i < count && candidate == EGL_NO_DISPLAY; ++i)
      {
        const char* deviceExtensions =
          queryDeviceString ? queryDeviceString(devices[static_cast<size_t>(i)], EGL_EXTENSIONS) : nullptr;
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
    std::lock_guard<std::mutex> lock(DisplayMutex);
    ++DisplayUsers[candidate];
  }
  out.Description += std::string(", EGL ") + std::to_string(major) + "." + std::to_string(minor) +
    " (" + eglQueryString(candidate, EGL_VENDOR) + ")";
  out.Display = candidate;
  return out;
}

void CloseDisplay(EGLDisplay display)
{
  std::lock_guard<std::mutex> lock(DisplayMutex);
  auto it = DisplayUsers.find(display);
  if (it != DisplayUsers.end() && --it->second == 0)
  {
    DisplayUsers.erase(it);
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
  std::string Description;
  std::string Capabilities;
  bool FailureReported = false;
};

vtkStandardNewMacro(vtkPenumbraEGLRenderWindow);

vtkPenumbraEGLRenderWindow::vtkPenumbraEGLRenderWindow()
  : DeviceIndex(DefaultDeviceIndex())
  , Usable(false)
  , Impl(new Internals)
{
  // Nothing is ever shown: all rendering stays in VTK's offscreen framebuffers.
  this->ShowWindow = false;
  this->UseOffScreenBuffers = true;
  this->OwnContext = 1;
  this->ScreenSize[0] = 16384;
  this->ScreenSize[1] = 16384;
}

vtkPenumbraEGLRenderWindow::~vtkPenumbraEGLRenderWindow()
{
  this->Finalize();
  vtkRenderer* ren;
  vtkCollectionSimpleIterator rit;
  this->Renderers->InitTraversal(rit);
  while ((ren = this->Renderers->GetNextRenderer(rit)))
  {
    ren->SetRenderWindow(nullptr);
  }
}

void vtkPenumbraEGLRenderWindow::CreateAWindow()
{
  Internals& impl = *this->Impl;
  if (impl.Context != EGL_NO_CONTEXT)
  {
    return;
  }
  auto fail = [&](const std::string& why) {
    if (!impl.FailureReported)
    {
      vtkErrorMacro("Cannot create a headless OpenGL context: " << why);
      impl.FailureReported = true;
    }
    if (impl.Display != EGL_NO_DISPLAY)
    {
      CloseDisplay(impl.Display);
      impl.Display = EGL_NO_DISPLAY;
    }
    this->Usable = false;
  };

  OpenedDisplay opened = OpenDisplay(this->DeviceIndex);
  if (opened.Display == EGL_NO_DISPLAY)
  {
    fail(opened.Error);
    return;
  }
  impl.Display = opened.Display;
  impl.Description = opened.Description;

  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE)
  {
    fail("eglBindAPI(EGL_OPENGL_API) failed: this EGL has no desktop OpenGL");
    return;
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
    fail("no EGL config renders desktop OpenGL");
    return;
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
    fail("no OpenGL 3.2+ core context could be created");
    return;
  }
  if (eglMakeCurrent(impl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, impl.Context) != EGL_TRUE)
  {
    eglDestroyContext(impl.Display, impl.Context);
    impl.Context = EGL_NO_CONTEXT;
    fail("eglMakeCurrent without a surface failed");
    return;
  }

  this->Initialized = false;
  this->OpenGLInit();
  if (!this->Initialized)
  {
    // OpenGLInitContext reported why; release everything so nothing renders on a bad context.
    eglMakeCurrent(impl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(impl.Display, impl.Context);
    impl.Context = EGL_NO_CONTEXT;
    impl.FailureReported = true;
    fail("OpenGL initialisation failed");
    return;
  }
  this->Usable = true;
  this->Mapped = 0;
}

void vtkPenumbraEGLRenderWindow::OpenGLInitContext()
{
  if (!this->Initialized)
  {
    // Debian's GLEW is GLX-built: glewInit() loads every GL entry point, then fails to find a
    // GLX display. The GL part is what VTK needs, so that code counts as success here.
    glewExperimental = GL_TRUE;
    const GLenum result = glewInit();
    if (result != GLEW_OK && result != GLEW_ERROR_NO_GLX_DISPLAY)
    {
      vtkErrorMacro("GLEW could not load OpenGL: "
        << reinterpret_cast<const char*>(glewGetErrorString(result)));
      return;
    }
    if (!GLEW_VERSION_3_2)
    {
      vtkErrorMacro("OpenGL 3.2 or newer is required; this context offers "
        << reinterpret_cast<const char*>(glGetString(GL_VERSION)));
      return;
    }
    this->GlewInitValid = true;
    this->Initialized = true;
    GLfloat range[2] = { 1.0f, 1.0f };
    glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, range);
    this->MaximumHardwareLineWidth = (glGetError() == GL_NO_ERROR) ? range[1] : 1.0f;
  }
  // Now Initialized: the base class only records the context creation time.
  this->Superclass::OpenGLInitContext();
}

void vtkPenumbraEGLRenderWindow::DestroyWindow()
{
  Internals& impl = *this->Impl;
  if (impl.Context != EGL_NO_CONTEXT)
  {
    this->MakeCurrent();
    this->ReleaseGraphicsResources(this);
    eglMakeCurrent(impl.Display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(impl.Display, impl.Context);
    impl.Context = EGL_NO_CONTEXT;
  }
  if (impl.Display != EGL_NO_DISPLAY)
  {
    CloseDisplay(impl.Display);
    impl.Display = EGL_NO_DISPLAY;
  }
  this->Usable = false;
  this->Initialized = false;
  this->Mapped = 0;
}

void vtkPenumbraEGLRenderWindow::Initialize()
{
  if (this->Impl->Context == EGL_NO_CONTEXT)
  {
    this->CreateAWindow();
  }
}

void vtkPenumbraEGLRenderWindow::Finalize()
{
  this->DestroyWindow();
}

void vtkPenumbraEGLRenderWindow::Render()
{
  this->Initialize();
  if (!this->Usable)
  {
    return;
  }
  this->Superclass::Render();
}

int vtkPenumbraEGLRenderWindow::ReadPixels(
  const vtkRecti& rect, int front, int glFormat, int glType, void* data, int right)
{
  if (!this->Usable)
  {
    vtkErrorMacro("Cannot read pixels: the window has no usable OpenGL context");
    return VTK_ERROR;
  }
  return this->Superclass::ReadPixels(rect, front, glFormat, glType, data, right);
}

void vtkPenumbraEGLRenderWindow::Start()
{
  this->Initialize();
  if (!this->Usable)
  {
    return;
  }
  this->Superclass::Start();
}

void vtkPenumbraEGLRenderWindow::Frame()
{
  if (!this->Usable)
  {
    return;
  }
  this->MakeCurrent();
  this->Superclass::Frame();
}

void vtkPenumbraEGLRenderWindow::MakeCurrent()
{
  Internals& impl = *this->Impl;
  if (impl.Context != EGL_NO_CONTEXT && eglGetCurrentContext() != impl.Context)
  {
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

void vtkPenumbraEGLRenderWindow::SetSize(int width, int height)
{
  if (width < 1 || height < 1)
  {
    vtkErrorMacro("Window size must be positive, got " << width << "x" << height);
    return;
  }
  this->Superclass::SetSize(width, height);
}

int* vtkPenumbraEGLRenderWindow::GetScreenSize()
{
  // No screen: report the largest framebuffer we are willing to allocate.
  return this->ScreenSize;
}

void vtkPenumbraEGLRenderWindow::SetShowWindow(bool)
{
  // There is nothing to show; keep rendering offscreen whatever the caller asks.
}

void* vtkPenumbraEGLRenderWindow::GetGenericContext()
{
  return this->Impl->Context;
}

void* vtkPenumbraEGLRenderWindow::GetGenericDisplayId()
{
  return this->Impl->Display;
}

const char* vtkPenumbraEGLRenderWindow::GetContextDescription()
{
  return this->Impl->Description.c_str();
}

const char* vtkPenumbraEGLRenderWindow::ReportCapabilities()
{
  Internals& impl = *this->Impl;
  this->Initialize();
  if (!this->Usable)
  {
    impl.Capabilities = "no usable headless OpenGL context";
    return impl.Capabilities.c_str();
  }
  this->MakeCurrent();
  std::ostringstream out;
  out << "EGL: " << impl.Description << "\n";
  out << "OpenGL vendor string:  " << glGetString(GL_VENDOR) << "\n";
  out << "OpenGL renderer string:  " << glGetString(GL_RENDERER) << "\n";
  out << "OpenGL version string:  " << glGetString(GL_VERSION) << "\n";
  impl.Capabilities = out.str();
  return impl.Capabilities.c_str();
}

void vtkPenumbraEGLRenderWindow::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "DeviceIndex: " << this->DeviceIndex << "\n";
  os << indent << "Usable: " << (this->Usable ? "yes" : "no") << "\n";
  os << indent << "Context: " << this->Impl->Description << "\n";
}
