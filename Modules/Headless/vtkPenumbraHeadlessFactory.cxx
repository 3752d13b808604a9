#include "vtkPenumbraHeadlessFactory.h"

#include "vtkGenericRenderWindowInteractor.h"
#include "vtkObjectFactoryCollection.h"
#include "vtkPenumbraEGLRenderWindow.h"
#include "vtkPenumbraOSMesaRenderWindow.h"
#include "vtkVersion.h"

#include <cctype>
#include <cstdlib>
#include <string>

// Defined by VTK's RenderingOpenGL2 library; registering it first makes the order in which
// the two factories are initialised irrelevant.
void vtkRenderingOpenGL2_AutoInit_Construct();

namespace
{
vtkObject* CreateEGLRenderWindow()
{
  return vtkPenumbraEGLRenderWindow::New();
}

vtkObject* CreateOSMesaRenderWindow()
{
  return vtkPenumbraOSMesaRenderWindow::New();
}

// PENUMBRA_HEADLESS in lower case ("" if unset).
std::string HeadlessSetting()
{
  const char* env = std::getenv("PENUMBRA_HEADLESS");
  std::string v(env ? env : "");
  for (auto& c : v)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return v;
}

// VTK's X interactor would open the (absent) X display as soon as a window initialises it,
// e.g. inside vtkContextView; the generic interactor needs no window system.
vtkObject* CreateGenericInteractor()
{
  return vtkGenericRenderWindowInteractor::New();
}

vtkPenumbraHeadlessFactory* InstalledFactory = nullptr;
unsigned int AutoInitCount = 0;
}

vtkStandardNewMacro(vtkPenumbraHeadlessFactory);

vtkPenumbraHeadlessFactory::vtkPenumbraHeadlessFactory()
{
  if (vtkPenumbraHeadlessFactory::OSMesaRequested())
  {
    this->RegisterOverride("vtkRenderWindow", "vtkPenumbraOSMesaRenderWindow",
      "Headless OSMesa render window", 1, CreateOSMesaRenderWindow);
  }
  else
  {
    this->RegisterOverride("vtkRenderWindow", "vtkPenumbraEGLRenderWindow",
      "Headless EGL render window", 1, CreateEGLRenderWindow);
  }
  this->RegisterOverride("vtkRenderWindowInteractor", "vtkGenericRenderWindowInteractor",
    "Interactor without a window system", 1, CreateGenericInteractor);
}

const char* vtkPenumbraHeadlessFactory::GetVTKSourceVersion()
{
  return VTK_SOURCE_VERSION;
}

bool vtkPenumbraHeadlessFactory::HeadlessRequested()
{
  const std::string v = HeadlessSetting();
  if (v == "1" || v == "on" || v == "yes" || v == "true" || v == "egl" || v == "osmesa")
  {
    return true;
  }
  if (v == "0" || v == "off" || v == "no" || v == "false" || v == "x" || v == "x11")
  {
    return false;
  }
  const char* display = std::getenv("DISPLAY");
  return display == nullptr || *display == '\0';
}

bool vtkPenumbraHeadlessFactory::OSMesaRequested()
{
  return HeadlessSetting() == "osmesa";
}

void vtkPenumbraHeadlessFactory::Install()
{
  if (InstalledFactory)
  {
    return;
  }
  vtkRenderingOpenGL2_AutoInit_Construct();
  // Disable everyone else's vtkRenderWindow override (VTK's X window) before adding ours.
  vtkObjectFactory::SetAllEnableFlags(0, "vtkRenderWindow");
  vtkObjectFactory::SetAllEnableFlags(0, "vtkRenderWindowInteractor");
  InstalledFactory = vtkPenumbraHeadlessFactory::New();
  vtkObjectFactory::RegisterFactory(InstalledFactory);
}

void vtkPenumbraHeadlessFactory::Uninstall()
{
  if (!InstalledFactory)
  {
    return;
  }
  vtkObjectFactory::UnRegisterFactory(InstalledFactory);
  InstalledFactory->Delete();
  InstalledFactory = nullptr;
  vtkObjectFactory::SetAllEnableFlags(1, "vtkRenderWindow");
  vtkObjectFactory::SetAllEnableFlags(1, "vtkRenderWindowInteractor");
}

bool vtkPenumbraHeadlessFactory::IsInstalled()
{
  return InstalledFactory != nullptr;
}

void vtkPenumbraHeadlessFactory::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Installed: " << (IsInstalled() ? "yes" : "no") << "\n";
}

// Called by vtk_module_autoinit (C++) and by the Python module's initialisation.
VTKPENUMBRAHEADLESS_EXPORT void vtkPenumbraHeadless_AutoInit_Construct()
{
  if (++AutoInitCount == 1 && vtkPenumbraHeadlessFactory::HeadlessRequested())
  {
    vtkPenumbraHeadlessFactory::Install();
  }
}

VTKPENUMBRAHEADLESS_EXPORT void vtkPenumbraHeadless_AutoInit_Destruct()
{
  if (AutoInitCount > 0 && --AutoInitCount == 0)
  {
    vtkPenumbraHeadlessFactory::Uninstall();
  }
}
