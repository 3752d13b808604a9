#include "PenumbraBench.h"

#include "PenumbraCLI.h"

#include "vtkCameraPass.h"
#include "vtkContextView.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraImageIO.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace penumbra_bench
{
using penumbra::Clock;
using penumbra::ElapsedMs;

const double Palette[PaletteSize][3] = { { 0.1, 0.1, 0.1 }, { 0.85, 0.33, 0.1 },
  { 0.0, 0.45, 0.74 }, { 0.47, 0.67, 0.19 }, { 0.49, 0.18, 0.56 }, { 0.93, 0.69, 0.13 },
  { 0.3, 0.75, 0.93 } };

std::vector<std::string> Split(const std::string& s, char sep)
{
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, sep))
  {
    if (!item.empty())
    {
      out.push_back(item);
    }
  }
  return out;
}

bool ParseTechnique(const std::string& text, TechniqueSpec& spec, std::string& error)
{
  const size_t colon = text.find(':');
  spec.Name = text.substr(0, colon);
  spec.Setting = "default";
  if (!vtkPenumbraTechniques::HasTechnique(spec.Name.c_str()))
  {
    error = "unknown technique \"" + spec.Name + "\" (see penumbra-render --list-techniques)";
    return false;
  }
  if (colon != std::string::npos)
  {
    spec.Setting = text.substr(colon + 1);
    for (const auto& kv : Split(spec.Setting, ';'))
    {
      const size_t eq = kv.find('=');
      if (eq == std::string::npos || eq == 0)
      {
        error = "technique setting \"" + kv + "\" is not KEY=VALUE";
        return false;
      }
      const std::string v = kv.substr(eq + 1);
      nlohmann::json parsed = nlohmann::json::parse(v, nullptr, false);
      spec.Options[kv.substr(0, eq)] = parsed.is_discarded() ? nlohmann::json(v) : parsed;
    }
  }
  return true;
}

vtkPenumbraShadowPass* ShadowPassOf(vtkRenderer* ren)
{
  return vtkPenumbraShadowPass::GetInstalled(ren);
}

void Progress(int done, int total, const std::string& what)
{
  const int width = 30;
  const int filled = total > 0 ? width * done / total : width;
  std::cerr << "\r[" << std::string(static_cast<size_t>(filled), '#')
            << std::string(static_cast<size_t>(width - filled), '.') << "] " << done << "/" << total
            << " " << std::left << std::setw(48) << what.substr(0, 48) << std::flush;
  if (done == total)
  {
    std::cerr << "\n";
  }
}

std::string Fixed(double v, int digits)
{
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

namespace
{
// "120 s", "0.512 s", "1e-06 s": three significant digits, a small value not rounded to 0.
std::string Seconds(double ms)
{
  std::ostringstream s;
  s << std::setprecision(3) << ms / 1000.0 << " s";
  return s.str();
}
}

FrameTimes TimeFrames(vtkRenderWindow* win, int warmup, int frames, double budgetMs,
  const std::function<void(int)>& before, const std::function<void()>& afterTimed)
{
  FrameTimes result;
  double timedMs = 0.0;
  const int lastWarmup = std::max(warmup - 1, 0);
  for (int f = 0; f < warmup + frames; ++f)
  {
    before(f);
    const auto t0 = Clock::now();
    win->Render();
    win->WaitForCompletion();
    const double ms = ElapsedMs(t0);
    if (f >= warmup)
    {
      result.Ms.push_back(ms);
      timedMs += ms;
      if (afterTimed)
      {
        afterTimed();
      }
    }
    const bool more = f + 1 < warmup + frames;
    if (more && f < warmup && ms > budgetMs)
    {
      result.OverBudget = "a warm-up frame took " + Seconds(ms) +
        ", more than the whole budget of " + Seconds(budgetMs);
    }
    else if (more && f == lastWarmup && ms > budgetMs / frames)
    {
      result.OverBudget = "one frame took " + Seconds(ms) + ", more than the budget of " +
        Seconds(budgetMs) + " over " + std::to_string(frames) + " frames";
    }
    else if (more && timedMs > budgetMs)
    {
      result.OverBudget = std::to_string(result.Ms.size()) + " of " + std::to_string(frames) +
        " frames took " + Seconds(timedMs) + ", more than the budget of " + Seconds(budgetMs);
    }
    if (!result.OverBudget.empty())
    {
      break;
    }
  }
  std::sort(result.Ms.begin(), result.Ms.end());
  return result;
}

bool SaveChart(vtkContextView* view, const std::string& path, std::string& error)
{
  penumbra_cli::ErrorLog log;
  log.Watch(view->GetRenderWindow());
  view->GetRenderWindow()->Render();
  vtkSmartPointer<vtkImageData> image = penumbra_cli::GrabRGB(view->GetRenderWindow());
  vtkNew<vtkPenumbraImageIO> io;
  if (log.Raised() || !io->Write(image, path.c_str()))
  {
    error = log.Raised() ? log.FirstError() : io->GetErrorMessage();
    return false;
  }
  return true;
}
}
