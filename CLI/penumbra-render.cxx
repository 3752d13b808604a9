// penumbra-render: renders a Penumbra scene file with shadows to an image, headless.
//
//   penumbra-render scene.json -o out.png [--size WxH] [--technique NAME] [--option K=V]...
//                   [--explain]
//                   [--baseline ref.png [--threshold T] [--fail-percent P] [--diff d.png]]
//
// Prints the time of each phase on stdout; with --explain also, per light, the technique that
// shadowed it and why, or why it got no shadow work (vtkPenumbraShadowPass::GetExplanation()).
// Any problem with the arguments or the scene gives one message on stderr, exit status 2, and
// no output file. With --baseline the written image is compared with ref.png
// (vtkPenumbraImageCompare: OpenImageIO's idiff semantics); a mismatch writes a difference
// image (default: OUT.diff.png) and exits with status 1.

#include "PenumbraCLI.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraImageCompare.h"
#include "vtkPenumbraImageIO.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtksys/SystemTools.hxx"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;

int Usage(const char* why)
{
  if (why)
  {
    std::cerr << "penumbra-render: " << why << "\n";
  }
  std::cerr
    << "usage: penumbra-render SCENE.json -o OUT.png [--size WxH] [--technique NAME]"
       " [--option KEY=VALUE]... [--explain]\n"
       "         [--baseline REF.png [--threshold T] [--fail-percent P] [--diff DIFF.png]]\n"
       "       penumbra-render --list-techniques\n"
       "       penumbra-render --options-markdown   (the technique section of SCHEMA.md)\n"
       "exit status: 0 rendered (and matches the baseline), 1 differs from the baseline,\n"
       "             2 bad arguments or scene, 3 rendering failed\n";
  return 2;
}

// A number in [lo, hi] from a command-line value; false if it is not one.
bool ParseFraction(const std::string& text, double lo, double hi, double& out)
{
  char* end = nullptr;
  out = std::strtod(text.c_str(), &end);
  return !text.empty() && *end == '\0' && out >= lo && out <= hi;
}

// Compares the written image with the baseline; the exit status of the program.
int CheckBaseline(const std::string& outPath, const penumbra_cli::BaselineOptions& baseline)
{
  vtkNew<vtkPenumbraImageCompare> compare;
  if (baseline.Threshold >= 0.0)
  {
    compare->SetThreshold(baseline.Threshold);
  }
  if (baseline.FailPercent >= 0.0)
  {
    compare->SetFailFraction(baseline.FailPercent / 100.0);
  }
  const int verdict = compare->Compare(outPath.c_str(), baseline.Path.c_str());
  if (verdict == 1)
  {
    std::cout << "baseline   " << compare->GetMessage() << "\n";
    return 0;
  }
  if (verdict < 0)
  {
    std::cerr << "penumbra-render: baseline: " << compare->GetMessage() << "\n";
    return 1;
  }
  const std::string diff = baseline.DiffPath.empty()
    ? vtksys::SystemTools::GetFilenamePath(outPath) +
      (vtksys::SystemTools::GetFilenamePath(outPath).empty() ? "" : "/") +
      vtksys::SystemTools::GetFilenameWithoutLastExtension(outPath) + ".diff.png"
    : baseline.DiffPath;
  const bool wrote = compare->WriteDifference(diff.c_str());
  std::cerr << "penumbra-render: " << outPath << " " << compare->GetMessage()
            << (wrote ? "; difference image: " + diff : std::string("; ") + compare->GetMessage())
            << "\n";
  return 1;
}
}

namespace
{
// What the command line asks for.
struct Arguments
{
  std::string ScenePath, OutPath, Technique, SizeArg;
  bool Explain = false;
  penumbra_cli::BaselineOptions Baseline;
  nlohmann::json Overrides = nlohmann::json::object();
  int Width = 0, Height = 0;
};

// Reads one flag (and its value) at argv[i]; returns an exit status to stop with, or -1.
int ParseFlag(int argc, char* argv[], int& i, Arguments& args)
{
  const std::string a = argv[i];
  auto value = [&](const char* flag) -> const char*
  {
    if (i + 1 >= argc)
    {
      Usage((std::string(flag) + " needs a value").c_str());
      std::exit(2);
    }
    return argv[++i];
  };
  penumbra_cli::BaselineOptions& baseline = args.Baseline;
  if (a == "-o" || a == "--output")
  {
    args.OutPath = value("-o");
  }
  else if (a == "--size")
  {
    args.SizeArg = value("--size");
  }
  else if (a == "--baseline")
  {
    baseline.Path = value("--baseline");
  }
  else if (a == "--threshold")
  {
    if (!ParseFraction(value("--threshold"), 0.0, 1.0, baseline.Threshold))
    {
      return Usage("--threshold expects a number from 0 to 1 (per-channel difference)");
    }
    baseline.ThresholdGiven = true;
  }
  else if (a == "--fail-percent")
  {
    if (!ParseFraction(value("--fail-percent"), 0.0, 100.0, baseline.FailPercent))
    {
      return Usage("--fail-percent expects a number from 0 to 100");
    }
    baseline.ThresholdGiven = true;
  }
  else if (a == "--diff")
  {
    baseline.DiffPath = value("--diff");
    baseline.ThresholdGiven = true;
  }
  else if (a == "--technique")
  {
    args.Technique = value("--technique");
  }
  else if (a == "--option")
  {
    const std::string kv = value("--option");
    const size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0)
    {
      return Usage("--option expects KEY=VALUE");
    }
    // Values are JSON when they parse as JSON (numbers, booleans), strings otherwise.
    const std::string v = kv.substr(eq + 1);
    nlohmann::json parsed = nlohmann::json::parse(v, nullptr, false);
    args.Overrides[kv.substr(0, eq)] = parsed.is_discarded() ? nlohmann::json(v) : parsed;
  }
  else if (a == "--explain")
  {
    args.Explain = true;
  }
  else if (a == "--list-techniques")
  {
    std::cout << vtkPenumbraTechniques::GetTechniqueList();
    return 0;
  }
  else if (a == "--options-markdown")
  {
    std::cout << vtkPenumbraTechniques::GetOptionsMarkdown();
    return 0;
  }
  else if (a == "-h" || a == "--help")
  {
    Usage(nullptr);
    return 0;
  }
  else if (!a.empty() && a[0] == '-')
  {
    return Usage(("unknown option " + a).c_str());
  }
  else if (args.ScenePath.empty())
  {
    args.ScenePath = a;
  }
  else
  {
    return Usage("only one scene file may be given");
  }
  return -1;
}

// The whole command line, checked; returns an exit status to stop with, or -1.
int ParseArguments(int argc, char* argv[], Arguments& args)
{
  for (int i = 1; i < argc; ++i)
  {
    const int status = ParseFlag(argc, argv, i, args);
    if (status >= 0)
    {
      return status;
    }
  }
  if (args.ScenePath.empty())
  {
    return Usage("no scene file given");
  }
  if (args.OutPath.empty())
  {
    return Usage("no output file given (-o OUT.png)");
  }
  if (args.Baseline.Path.empty() && args.Baseline.ThresholdGiven)
  {
    return Usage("--threshold, --fail-percent and --diff need --baseline");
  }
  if (!args.Baseline.Path.empty() && !vtksys::SystemTools::FileExists(args.Baseline.Path, true))
  {
    return Usage(
      ("baseline " + args.Baseline.Path + " not found (render once without --baseline to make one)")
        .c_str());
  }
  if (!args.SizeArg.empty() && !penumbra_cli::ParseSize(args.SizeArg, args.Width, args.Height))
  {
    return Usage("--size expects WxH with 1..16384 pixels per side, e.g. 800x600");
  }
  return -1;
}

// Installs the scene's technique, or the command line's (which starts from its defaults);
// --option overrides both. Returns the technique's name, empty on failure (said on stderr).
std::string ApplyTechnique(vtkPenumbraSceneReader* reader, const Arguments& args)
{
  const std::string name = args.Technique.empty() ? reader->GetTechniqueName() : args.Technique;
  nlohmann::json options = args.Technique.empty()
    ? nlohmann::json::parse(reader->GetTechniqueOptions())
    : nlohmann::json::object();
  for (auto it = args.Overrides.begin(); it != args.Overrides.end(); ++it)
  {
    options[it.key()] = it.value();
  }
  vtkNew<vtkPenumbraTechniques> techniques;
  if (!techniques->Apply(reader->GetRenderer(), name.c_str(), options.dump().c_str()))
  {
    std::cerr << "penumbra-render: " << reader->GetSceneLabel() << ": technique"
              << (args.Technique.empty() ? "" : " (from --technique/--option)") << ": "
              << techniques->GetErrorMessage() << "\n";
    return "";
  }
  return name;
}

// Per light, what shadowed it and why (--explain).
void Explain(vtkRenderer* ren, const std::string& name)
{
  vtkPenumbraShadowPass* pass = vtkPenumbraShadowPass::GetInstalled(ren);
  std::cout << "explain    technique " << name << "\n";
  if (pass)
  {
    std::cout << pass->GetExplanation();
  }
  else
  {
    std::cout << (name == "none" ? "no shadows: every light is unshadowed\n"
                                 : "VTK's vtkShadowMapPass: directional lights and spot lights "
                                   "under 90 degrees are shadowed, no other light\n");
  }
}
}

int main(int argc, char* argv[])
{
  penumbra_cli::InstallMessageWindow("penumbra-render");
  Arguments args;
  const int status = ParseArguments(argc, argv, args);
  if (status >= 0)
  {
    return status;
  }

  const auto t0 = Clock::now();
  vtkNew<vtkPenumbraSceneReader> reader;
  reader->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
  reader->SetFileName(args.ScenePath.c_str());
  if (!reader->Read())
  {
    std::cerr << "penumbra-render: " << reader->GetErrorMessage() << "\n";
    return 2;
  }
  const double loadMs = ElapsedMs(t0);

  const auto t1 = Clock::now();
  vtkRenderer* ren = reader->GetRenderer();
  const std::string name = ApplyTechnique(reader, args);
  if (name.empty())
  {
    return 2;
  }
  const double setupMs = ElapsedMs(t1);

  const auto t2 = Clock::now();
  penumbra_cli::ErrorLog errors;
  std::string windowError;
  vtkSmartPointer<vtkRenderWindow> win =
    penumbra_cli::MakeWindow(args.Width ? args.Width : reader->GetWidth(),
      args.Height ? args.Height : reader->GetHeight(), ren, errors, windowError);
  if (!win)
  {
    std::cerr << "penumbra-render: " << windowError << "\n";
    return 3;
  }
  win->Render();
  win->WaitForCompletion(); // glFinish: time the work, not its submission
  const double firstMs = ElapsedMs(t2);
  if (errors.Raised())
  {
    std::cerr << "penumbra-render: rendering failed: " << errors.FirstError() << "\n";
    return 3;
  }

  const auto t3 = Clock::now();
  win->Render();
  win->WaitForCompletion(); // glFinish: time the work, not its submission
  const double frameMs = ElapsedMs(t3);

  const auto t4 = Clock::now();
  vtkSmartPointer<vtkImageData> image = penumbra_cli::GrabRGB(win);
  vtkNew<vtkPenumbraImageIO> io;
  if (errors.Raised() || !io->Write(image, args.OutPath.c_str()))
  {
    std::cerr << "penumbra-render: "
              << (errors.Raised() ? "reading the image back failed: " + errors.FirstError()
                                  : std::string(io->GetErrorMessage()))
              << "\n";
    return 3;
  }
  const double writeMs = ElapsedMs(t4);

  int* size = win->GetSize();
  std::cout << "scene      " << reader->GetSceneLabel() << " (" << reader->GetNumberOfObjects()
            << " objects, " << size[0] << "x" << size[1] << ", technique " << name << ")\n";
  std::printf("load       %9.1f ms  (parse, read meshes, run generators)\n", loadMs);
  std::printf("setup      %9.1f ms  (technique)\n", setupMs);
  std::printf("first      %9.1f ms  (context, upload, shader compile, shadows, frame)\n", firstMs);
  std::printf("frame      %9.1f ms  (second frame, steady state)\n", frameMs);
  std::printf("write      %9.1f ms  (read back, encode)\n", writeMs);
  std::printf("total      %9.1f ms\n", ElapsedMs(t0));
  std::cout << "wrote      " << args.OutPath << "\n";
  if (args.Explain)
  {
    Explain(ren, name);
  }
  return args.Baseline.Path.empty() ? 0 : CheckBaseline(args.OutPath, args.Baseline);
}
