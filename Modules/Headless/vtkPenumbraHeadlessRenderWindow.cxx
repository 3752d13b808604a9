#include "vtkPenumbraHeadlessRenderWindow.h"

#include "vtkOpenGLState.h"
#include "vtkRenderer.h"
#include "vtkRendererCollection.h"
#include "vtk_glew.h"

#include <sstream>

vtkPenumbraHeadlessRenderWindow::vtkPenumbraHeadlessRenderWindow()
  : Usable(false)
  , FailureReported(false)
{
  // Nothing is ever shown: all rendering stays in VTK's offscreen framebuffers.
  this->ShowWindow = false;
  this->UseOffScreenBuffers = true;
  this->OwnContext = 1;
  this->ScreenSize[0] = 16384;
  this->ScreenSize[1] = 16384;
}

vtkPenumbraHeadlessRenderWindow::~vtkPenumbraHeadlessRenderWindow()
{
  vtkRenderer* ren;
  vtkCollectionSimpleIterator rit;
  this->Renderers->InitTraversal(rit);
  while ((ren = this->Renderers->GetNextRenderer(rit)))
  {
    ren->SetRenderWindow(nullptr);
  }
}

void vtkPenumbraHeadlessRenderWindow::CreateAWindow()
{
  if (this->HasContext())
  {
    return;
  }
  auto fail = [&](const std::string& why)
  {
    if (!this->FailureReported)
    {
      vtkErrorMacro("Cannot create a headless OpenGL context: " << why);
      this->FailureReported = true;
    }
    this->Usable = false;
  };
  std::string why;
  if (!this->CreateContext(why))
  {
    fail(why);
    return;
  }
  this->Initialized = false;
  this->OpenGLInit();
  if (!this->Initialized)
  {
    // OpenGLInitContext reported why; release everything so nothing renders on a bad context.
    this->DestroyContext();
    this->FailureReported = true;
    fail("OpenGL initialisation failed");
    return;
  }
  this->Usable = true;
  this->Mapped = 0;
}

void vtkPenumbraHeadlessRenderWindow::OpenGLInitContext()
{
  if (!this->Initialized)
  {
    // Debian's GLEW is GLX-built: glewInit() loads every GL entry point, then fails to find a
    // GLX display. The GL part is what VTK needs, so that code counts as success here.
    glewExperimental = GL_TRUE;
    const GLenum result = glewInit();
    if (result != GLEW_OK && result != GLEW_ERROR_NO_GLX_DISPLAY)
    {
      vtkErrorMacro("GLEW could not load OpenGL: " << reinterpret_cast<const char*>(
                      glewGetErrorString(result)));
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

void vtkPenumbraHeadlessRenderWindow::DestroyWindow()
{
  if (this->HasContext())
  {
    this->MakeCurrent();
    this->ReleaseGraphicsResources(this);
    this->DestroyContext();
  }
  this->Usable = false;
  this->Initialized = false;
  this->Mapped = 0;
}

void vtkPenumbraHeadlessRenderWindow::Initialize()
{
  if (!this->HasContext())
  {
    this->CreateAWindow();
  }
}

void vtkPenumbraHeadlessRenderWindow::Finalize()
{
  this->DestroyWindow();
}

void vtkPenumbraHeadlessRenderWindow::Render()
{
  this->Initialize();
  if (!this->Usable)
  {
    return;
  }
  this->Superclass::Render();
}

int vtkPenumbraHeadlessRenderWindow::ReadPixels(
  const vtkRecti& rect, int front, int glFormat, int glType, void* data, int right)
{
  if (!this->Usable)
  {
    vtkErrorMacro("Cannot read pixels: the window has no usable OpenGL context");
    return VTK_ERROR;
  }
  return this->Superclass::ReadPixels(rect, front, glFormat, glType, data, right);
}

void vtkPenumbraHeadlessRenderWindow::Start()
{
  this->Initialize();
  if (!this->Usable)
  {
    return;
  }
  this->Superclass::Start();
}

void vtkPenumbraHeadlessRenderWindow::Frame()
{
  if (!this->Usable)
  {
    return;
  }
  this->MakeCurrent();
  this->Superclass::Frame();
}

void vtkPenumbraHeadlessRenderWindow::SetSize(int width, int height)
{
  if (width < 1 || height < 1)
  {
    vtkErrorMacro("Window size must be positive, got " << width << "x" << height);
    return;
  }
  this->Superclass::SetSize(width, height);
}

int* vtkPenumbraHeadlessRenderWindow::GetScreenSize()
{
  // No screen: report the largest framebuffer we are willing to allocate.
  return this->ScreenSize;
}

void vtkPenumbraHeadlessRenderWindow::SetShowWindow(bool)
{
  // There is nothing to show; keep rendering offscreen whatever the caller asks.
}

const char* vtkPenumbraHeadlessRenderWindow::ReportCapabilities()
{
  this->Initialize();
  if (!this->Usable)
  {
    this->Capabilities = "no usable headless OpenGL context";
    return this->Capabilities.c_str();
  }
  this->MakeCurrent();
  std::ostringstream out;
  out << "Context: " << this->ContextDescription << "\n";
  out << "OpenGL vendor string:  " << glGetString(GL_VENDOR) << "\n";
  out << "OpenGL renderer string:  " << glGetString(GL_RENDERER) << "\n";
  out << "OpenGL version string:  " << glGetString(GL_VERSION) << "\n";
  this->Capabilities = out.str();
  return this->Capabilities.c_str();
}

void vtkPenumbraHeadlessRenderWindow::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Usable: " << (this->Usable ? "yes" : "no") << "\n";
  os << indent << "Context: " << this->ContextDescription << "\n";
}
