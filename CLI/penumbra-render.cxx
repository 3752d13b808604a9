// penumbra-render: renders a Penumbra scene file with shadows to an image, headless.
//
//   penumbra-render scene.json -o out.png [--size WxH] [--technique NAME] [--option K=V]...
//                   [--explain]
//
// Prints the time of each phase on stdout; with --explain also, per light, the technique that
// shadowed it and why, or why it got no shadow work (vtkPenumbraShadowPass::GetExplanation()). Any problem with the arguments or the scene gives
// one message on stderr, exit status 2, and no output file.

#include "PenumbraCLI.h"

#include "vtkCommand.h"
#include "vtkCallbackCommand.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPenumbraImageIO.h"
#include "vtkPenumbraSceneReader.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

namespace
{
using penumbra_cli::Clock;
using penumbra_cli::MsSince;

int Usage(const char* why)
{
  if (why)
  {
    std::cerr << "penumbra-render: " << why << "\n";
  }
  std::cerr << "usage: penumbra-render SCENE.json -o OUT.png [--size WxH] [--technique NAME]"
               " [--option KEY=VALUE]... [--explain]\n"
               "       penumbra-render --list-techniques\n"
               "       penumbra-render --options-markdown   (the technique section of SCHEMA.md)\n";
  return 2;
}
}

int main(int argc, char* argv[])
{
  penumbra_cli::InstallMessageWindow("penumbra-render");
  std::string scenePath, outPath, technique, sizeArg;
  bool explain = false;
  nlohmann::json overrides = nlohmann::json::object();
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto value = [&](const char* flag) -> const char* {
      if (i + 1 >= argc)
      {
        Usage((std::string(flag) + " needs a value").c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "-o" || a == "--output")
    {
      outPath = value("-o");
    }
    else if (a == "--size")
    {
      sizeArg = value("--size");
    }
    else if (a == "--technique")
    {
      technique = value("--technique");
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
      overrides[kv.substr(0, eq)] = parsed.is_discarded() ? nlohmann::json(v) : parsed;
    }
    else if (a == "--explain")
    {
      explain = true;
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
    else if (scenePath.empty())
    {
      scenePath = a;
    }
    else
    {
      return Usage("only one scene file may be given");
    }
  }
  if (scenePath.empty())
  {
    return Usage("no scene file given");
  }
  if (outPath.empty())
  {
    return Usage("no output file given (-o OUT.png)");
  }
  int width = 0, height = 0;
  if (!sizeArg.empty() && !penumbra_cli::ParseSize(sizeArg, width, height))
  {
    return Usage("--size expects WxH with 1..16384 pixels per side, e.g. 800x600");
  }

  const auto t0 = Clock::now();
  vtkNew<vtkPenumbraSceneReader> reader;
  reader->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
  reader->SetFileName(scenePath.c_str());
  if (!reader->Read())
  {
    std::cerr << "penumbra-render: " << reader->GetErrorMessage() << "\n";
    return 2;
  }
  const double loadMs = MsSince(t0);

  const auto t1 = Clock::now();
  vtkRenderer* ren = reader->GetRenderer();
  const std::string name = technique.empty() ? reader->GetTechniqueName() : technique;
  // A technique given on the command line starts from its defaults; --option overrides both.
  nlohmann::json options = technique.empty() ? nlohmann::json::parse(reader->GetTechniqueOptions())
                                             : nlohmann::json::object();
  for (auto it = overrides.begin(); it != overrides.end(); ++it)
  {
    options[it.key()] = it.value();
  }
  vtkNew<vtkPenumbraTechniques> techniques;
  if (!techniques->Apply(ren, name.c_str(), options.dump().c_str()))
  {
    std::cerr << "penumbra-render: " << reader->GetSceneLabel() << ": technique"
              << (technique.empty() ? "" : " (from --technique/--option)") << ": "
              << techniques->GetErrorMessage() << "\n";
    return 2;
  }
  const double setupMs = MsSince(t1);

  const auto t2 = Clock::now();
  penumbra_cli::ErrorLog errors;
  std::string windowError;
  vtkSmartPointer<vtkRenderWindow> win = penumbra_cli::MakeWindow(
    width ? width : reader->GetWidth(), height ? height : reader->GetHeight(), ren, errors, windowError);
  if (!win)
  {
    std::cerr << "penumbra-render: " << windowError << "\n";
    return 3;
  }
  win->Render();
  win->WaitForCompletion(); // glFinish: time the work, not its submission
  const double firstMs = MsSince(t2);
  if (errors.Raised())
  {
    std::cerr << "penumbra-render: rendering failed: " << errors.FirstError() << "\n";
    return 3;
  }

  const auto t3 = Clock::now();
  win->Render();
  win->WaitForCompletion(); // glFinish: time the work, not its submission
  const double frameMs = MsSince(t3);

  const auto t4 = Clock::now();
  vtkSmartPointer<vtkImageData> image = penumbra_cli::GrabRGB(win);
  vtkNew<vtkPenumbraImageIO> io;
  if (errors.Raised() || !io->Write(image, outPath.c_str()))
  {
    std::cerr << "penumbra-render: "
              << (errors.Raised() ? "reading the image back failed: " + errors.FirstError()
                                  : std::string(io->GetErrorMessage()))
              << "\n";
    return 3;
  }
  const double writeMs = MsSince(t4);

  int* size = win->GetSize();
  std::cout << "scene      " << reader->GetSceneLabel() << " (" << reader->GetNumberOfObjects()
            << " objects, " << size[0] << "x" << size[1] << ", technique " << name << ")\n";
  std::printf("load       %9.1f ms  (parse, read meshes, run generators)\n", loadMs);
  std::printf("setup      %9.1f ms  (technique)\n", setupMs);
  std::printf("first      %9.1f ms  (context, upload, shader compile, shadows, frame)\n", firstMs);
  std::printf("frame      %9.1f ms  (second frame, steady state)\n", frameMs);
  std::printf("write      %9.1f ms  (read back, encode)\n", writeMs);
  std::printf("total      %9.1f ms\n", MsSince(t0));
  std::cout << "wrote      " << outPath << "\n";
  if (explain)
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
  return 0;
}
