// Pieces the command-line programs share: error capture, the headless window, read-back,
// argument parsing. Not a public API.
#ifndef PenumbraCLI_h
#define PenumbraCLI_h

#include "vtkSmartPointer.h"

#include <string>

class vtkCallbackCommand;
class vtkObject;
class vtkImageData;
class vtkRenderWindow;
class vtkRenderer;

namespace penumbra_cli
{
// Records VTK errors raised while rendering (shader compile failures, GL errors) so a run
// fails instead of producing a silently wrong image. VTK's own printing is kept off stderr.
class ErrorLog
{
public:
  ErrorLog();
  ~ErrorLog();
  void Watch(vtkObject* object);
  bool Raised() const { return !this->First.empty(); }
  const std::string& FirstError() const { return this->First; }
  // Forgets what was raised, so a run can go on after reporting a failure.
  void Clear() { this->First.clear(); }

private:
  static void OnError(vtkObject*, unsigned long, void* client, void* data);
  vtkSmartPointer<vtkCallbackCommand> Command;
  std::string First;
};

// The sentence of a VTK message, without the "ERROR: In /path/file.cxx, line N" line and the
// "vtkClass (0x...): " prefix VTK's macros put before it: a user needs what went wrong, not
// where in VTK's sources it was noticed.
std::string MessageText(const char* text);

// Makes VTK's output window print each message as "program: [warning: ]sentence" on stderr
// (MessageText()). Errors are left to an ErrorLog when one watches the output window (the
// program then reports them once, with what it was doing). `belowProgress`: each message
// starts on a new line, below a progress bar drawn with '\r'.
void InstallMessageWindow(const char* program, bool belowProgress = false);

// Offscreen window (a headless EGL or OSMesa window when no X display is set) with a stencil buffer
// and no multisampling, so pixels map one to one onto view samples. Returns nullptr with
// `error` set when no window can work (VTK's X window forced without an X display, which
// VTK would answer with an abort).
vtkSmartPointer<vtkRenderWindow> MakeWindow(
  int width, int height, vtkRenderer* renderer, ErrorLog& log, std::string& error);

// The last frame: RGB unsigned char, rows bottom-up.
vtkSmartPointer<vtkImageData> GrabRGB(vtkRenderWindow* window);

// The last frame as float luminance per pixel (mean of RGB in [0, 1]), rows bottom-up.
vtkSmartPointer<vtkImageData> GrabLuminance(vtkRenderWindow* window);

// penumbra-render's regression-image check (--baseline and its settings).
struct BaselineOptions
{
  std::string Path;          // baseline image; empty: no check
  double Threshold = -1.0;   // per-channel difference a pixel may have; < 0: the compare's default
  double FailPercent = -1.0; // percentage of pixels allowed over the threshold; < 0: default
  std::string DiffPath;      // difference image on a mismatch; empty: OUT.diff.png
  bool ThresholdGiven = false; // a setting that only makes sense with Path
};

// "WxH" with 1..16384 per side.
bool ParseSize(const std::string& text, int& width, int& height);
}

#endif
