#include "PenumbraCLI.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOutputWindow.h"
#include "vtkPenumbraHeadlessRenderWindow.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWindowToImageFilter.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <regex>

namespace
{
class MessageWindow : public vtkOutputWindow
{
public:
  static MessageWindow* New();
  vtkTypeMacro(MessageWindow, vtkOutputWindow);
  void DisplayText(const char* text) override
  {
    const MessageTypes type = this->GetCurrentMessageType();
    if (type == MESSAGE_TYPE_ERROR && this->HasObserver(vtkCommand::ErrorEvent))
    {
      return; // an ErrorLog has it and the program reports it
    }
    const char* kind = type == MESSAGE_TYPE_ERROR                            ? "error: "
      : type == MESSAGE_TYPE_WARNING || type == MESSAGE_TYPE_GENERIC_WARNING ? "warning: "
                                                                             : "";
    std::cerr << (this->BelowProgress ? "\n" : "") << this->Program << ": " << kind
              << penumbra_cli::MessageText(text) << std::endl;
  }
  std::string Program = "penumbra";
  bool BelowProgress = false;
};
vtkStandardNewMacro(MessageWindow);
}

namespace penumbra_cli
{
std::string MessageText(const char* text)
{
  std::string s = text ? text : "";
  // "ERROR: In file, line N\n", "Warning: In ...", "Generic Warning: In ...".
  static const std::regex location(R"(^\s*(ERROR|Warning|Generic Warning|Debug): In [^\n]*\n)");
  s = std::regex_replace(s, location, "", std::regex_constants::format_first_only);
  // "vtkSomeClass (0x55d0c0ffee00): " of vtkErrorMacro and vtkWarningMacro.
  static const std::regex object(R"(^\s*[A-Za-z_][A-Za-z0-9_:<>]* \((0x)?[0-9a-fA-F]+\): )");
  s = std::regex_replace(s, object, "", std::regex_constants::format_first_only);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
  {
    s.pop_back();
  }
  return s;
}

void InstallMessageWindow(const char* program, bool belowProgress)
{
  vtkNew<MessageWindow> window;
  window->Program = program;
  window->BelowProgress = belowProgress;
  vtkOutputWindow::SetInstance(window);
  // VTK's logger would print every message a second time, with its own prefix.
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
}

ErrorLog::ErrorLog()
  : Command(vtkSmartPointer<vtkCallbackCommand>::New())
{
  this->Command->SetCallback(&ErrorLog::OnError);
  this->Command->SetClientData(this);
  this->Watch(vtkOutputWindow::GetInstance());
}

ErrorLog::~ErrorLog()
{
  vtkOutputWindow::GetInstance()->RemoveObserver(this->Command);
}

void ErrorLog::Watch(vtkObject* object)
{
  object->AddObserver(vtkCommand::ErrorEvent, this->Command);
}

void ErrorLog::OnError(vtkObject*, unsigned long, void* client, void* data)
{
  auto* log = static_cast<ErrorLog*>(client);
  if (log->First.empty())
  {
    log->First = data ? MessageText(static_cast<const char*>(data)) : "unknown VTK error";
  }
}

vtkSmartPointer<vtkRenderWindow> MakeWindow(
  int width, int height, vtkRenderer* renderer, ErrorLog& log, std::string& error)
{
  auto window = vtkSmartPointer<vtkRenderWindow>::Take(vtkRenderWindow::New());
  const char* display = std::getenv("DISPLAY");
  if (!vtkPenumbraHeadlessRenderWindow::SafeDownCast(window) && (!display || !*display))
  {
    error = "no X display is set but VTK's X window was requested (PENUMBRA_HEADLESS=0); "
            "unset PENUMBRA_HEADLESS to render headless";
    return nullptr;
  }
  log.Watch(window);
  log.Watch(renderer);
  window->SetOffScreenRendering(1);
  window->SetStencilCapable(1);
  window->SetMultiSamples(0);
  window->SetSize(width, height);
  window->AddRenderer(renderer);
  return window;
}

vtkSmartPointer<vtkImageData> GrabRGB(vtkRenderWindow* window)
{
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(grab->GetOutput());
  return image;
}

vtkSmartPointer<vtkImageData> GrabLuminance(vtkRenderWindow* window)
{
  vtkSmartPointer<vtkImageData> rgb = GrabRGB(window);
  int dims[3];
  rgb->GetDimensions(dims);
  auto lum = vtkSmartPointer<vtkImageData>::New();
  lum->SetDimensions(dims[0], dims[1], 1);
  lum->AllocateScalars(VTK_FLOAT, 1);
  auto* in = vtkUnsignedCharArray::SafeDownCast(rgb->GetPointData()->GetScalars());
  auto* out = vtkFloatArray::SafeDownCast(lum->GetPointData()->GetScalars());
  for (vtkIdType i = 0; i < out->GetNumberOfTuples(); ++i)
  {
    const unsigned char* p = in->GetPointer(3 * i);
    out->SetValue(i, (p[0] + p[1] + p[2]) / (3.0f * 255.0f));
  }
  return lum;
}

bool ParseSize(const std::string& text, int& width, int& height)
{
  char tail = 0;
  int w = 0, h = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 1 || h < 1 || w > 16384 ||
    h > 16384)
  {
    return false;
  }
  width = w;
  height = h;
  return true;
}
}
