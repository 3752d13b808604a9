#include "vtkPVPenumbraShadowView.h"

#include "vtkActor.h"
#include "vtkCameraPass.h"
#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkCommunicator.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOutputWindow.h"
#include "vtkPVSynchronizedRenderer.h"
#include "vtkPenumbraCasterExchange.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraHeadlessFactory.h"
#include "vtkPenumbraRayQueries.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniques.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkPropCollection.h"
#include "vtkRenderPass.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"
#include "vtk_glew.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <vector>

// Defined by the Penumbra::Headless module: registers the EGL window (and a generic
// interactor) when no X display is set. ParaView creates its render windows through VTK's
// object factory, so this must happen before the first view exists: at plugin load, when this
// library's static objects are constructed.
void vtkPenumbraHeadless_AutoInit_Construct();

namespace
{
struct RegisterHeadlessWindow
{
  RegisterHeadlessWindow() { vtkPenumbraHeadless_AutoInit_Construct(); }
};
const RegisterHeadlessWindow registerHeadlessWindow;
}

struct vtkPVPenumbraShadowView::Internals
{
  vtkSmartPointer<vtkRenderPass> Pass;
  vtkNew<vtkStringArray> Names;
  // Per technique, the values its option properties set: {"resolution": 2048, ...}.
  std::map<std::string, nlohmann::json> OptionValues;

  // The other ranks' casters (GatherCasters), or their answers to this rank's rays.
  penumbra::CasterExchange Exchange;
  vtkNew<vtkPenumbraRayQueries> Queries;
  std::string ExchangeReport;
};

vtkStandardNewMacro(vtkPVPenumbraShadowView);

vtkPVPenumbraShadowView::vtkPVPenumbraShadowView()
  : Technique(vtkPenumbraTechniques::GetDefaultTechnique())
  , Impl(new Internals)
{
  this->LODRenderingThreshold = std::numeric_limits<double>::max();
  if (vtkRenderWindow* window = this->GetRenderWindow())
  {
    this->WindowErrorObserver =
      window->AddObserver(vtkCommand::ErrorEvent, this, &vtkPVPenumbraShadowView::OnWindowError);
  }
}

vtkPVPenumbraShadowView::~vtkPVPenumbraShadowView()
{
  if (this->WindowErrorObserver && this->GetRenderWindow())
  {
    this->GetRenderWindow()->RemoveObserver(this->WindowErrorObserver);
  }
  if (this->Impl->Pass && this->GetRenderWindow())
  {
    this->Impl->Pass->ReleaseGraphicsResources(this->GetRenderWindow());
  }
}

void vtkPVPenumbraShadowView::OnWindowError(vtkObject*, unsigned long, void* text)
{
  const char* message = static_cast<const char*>(text);
  // glewGetErrorString() says "Unknown error" only for GLEW_ERROR_NO_GLX_DISPLAY (GLEW 2.x
  // has no higher code); GL 3.2 being there shows that glewInit() loaded the GL entry points
  // before it looked for the GLX display. Only under Penumbra's headless windows, whose EGL or
  // OSMesa context has no GLX display by design.
  const bool harmless = message && vtkPenumbraHeadlessFactory::IsInstalled() &&
    std::strstr(message, "GLEW could not be initialized: Unknown error") != nullptr &&
    GLEW_VERSION_3_2;
  if (!harmless)
  {
    // What VTK does with an error of an object that nobody observes.
    vtkOutputWindowDisplayErrorText(message ? message : "");
  }
}

void vtkPVPenumbraShadowView::SetShadowTechnique(const char* name)
{
  const std::string value = name ? name : "";
  if (value != this->Technique)
  {
    this->Technique = value;
    this->Modified();
  }
}

void vtkPVPenumbraShadowView::SetShadowOptions(const char* options)
{
  const std::string value = options ? options : "";
  if (value != this->Options)
  {
    this->Options = value;
    this->Modified();
  }
}

bool vtkPVPenumbraShadowView::SetOptionValue(const char* key, const std::string& json)
{
  const std::string text = key ? key : "";
  const size_t slash = text.find('/');
  const std::string technique = text.substr(0, slash), option = text.substr(slash + 1);
  bool known = false;
  for (int i = 0; slash != std::string::npos &&
       i < vtkPenumbraTechniques::GetNumberOfOptions(technique.c_str());
       ++i)
  {
    known = known || option == vtkPenumbraTechniques::GetOptionName(technique.c_str(), i);
  }
  if (!known)
  {
    vtkErrorMacro("Penumbra shadows: no technique option \""
      << text << "\" (expected \"<technique>/<option>\")");
    return false;
  }
  nlohmann::json& values = this->Impl->OptionValues[technique];
  const nlohmann::json value = nlohmann::json::parse(json);
  if (!values.is_object() || !values.contains(option) || values[option] != value)
  {
    values[option] = value;
    this->Modified();
  }
  return true;
}

void vtkPVPenumbraShadowView::SetShadowOptionInteger(const char* key, int value)
{
  this->SetOptionValue(key, std::to_string(value));
}

void vtkPVPenumbraShadowView::SetShadowOptionNumber(const char* key, double value)
{
  this->SetOptionValue(key, nlohmann::json(value).dump());
}

void vtkPVPenumbraShadowView::SetShadowOptionBoolean(const char* key, int value)
{
  this->SetOptionValue(key, value ? "true" : "false");
}

void vtkPVPenumbraShadowView::SetShadowOptionChoice(const char* key, const char* value)
{
  this->SetOptionValue(key, nlohmann::json(value ? value : "").dump());
}

std::string vtkPVPenumbraShadowView::ComposeOptions(const std::string& technique)
{
  auto found = this->Impl->OptionValues.find(technique);
  nlohmann::json options =
    found != this->Impl->OptionValues.end() ? found->second : nlohmann::json::object();
  if (!this->Options.empty())
  {
    const nlohmann::json text = nlohmann::json::parse(this->Options, nullptr, false);
    if (!text.is_object())
    {
      return this->Options; // the registry reports what is wrong with it
    }
    for (const auto& item : text.items())
    {
      options[item.key()] = item.value();
    }
  }
  return options.empty() ? std::string() : options.dump();
}

vtkStringArray* vtkPVPenumbraShadowView::GetShadowTechniqueNames()
{
  vtkStringArray* names = this->Impl->Names;
  names->Initialize();
  const std::string preferred = vtkPenumbraTechniques::GetDefaultTechnique();
  names->InsertNextValue(preferred);
  for (int i = 0; i < vtkPenumbraTechniques::GetNumberOfTechniques(); ++i)
  {
    if (preferred != vtkPenumbraTechniques::GetTechniqueName(i))
    {
      names->InsertNextValue(vtkPenumbraTechniques::GetTechniqueName(i));
    }
  }
  return names;
}

const char* vtkPVPenumbraShadowView::GetShadowTechniqueHelp()
{
  this->Help = vtkPenumbraTechniques::GetTechniqueList();
  return this->Help.c_str();
}

const char* vtkPVPenumbraShadowView::GetShadowReport()
{
  auto* pass = vtkPenumbraShadowPass::SafeDownCast(this->Impl->Pass);
  this->Report = pass ? pass->GetExplanation() : std::string();
  return this->Report.c_str();
}

void vtkPVPenumbraShadowView::SetLODRenderingThreshold(double)
{
  this->Superclass::SetLODRenderingThreshold(std::numeric_limits<double>::max());
}

void vtkPVPenumbraShadowView::UpdateShadowPass()
{
  const std::string name =
    this->Technique.empty() ? vtkPenumbraTechniques::GetDefaultTechnique() : this->Technique;
  const std::string options = this->ComposeOptions(name);
  // Tried once per change: a refused request is reported once, not at every render.
  if (this->Tried && name == this->TriedTechnique && options == this->TriedOptions)
  {
    return;
  }
  this->Tried = true;
  this->TriedTechnique = name;
  this->TriedOptions = options;
  // Back to what draws (vtkSMPenumbraShadowViewProxy restores a refused request): nothing to
  // rebuild.
  if (!this->InstalledTechnique.empty() && name == this->InstalledTechnique &&
    options == this->InstalledOptions)
  {
    this->Refused = false;
    return;
  }
  // The registry builds camera pass -> technique pass on a renderer; ParaView brings its own
  // camera pass, so only the delegate is handed over ("none" installs no pass at all, and
  // ParaView then uses its default pass).
  vtkNew<vtkRenderer> scratch;
  vtkNew<vtkPenumbraTechniques> techniques;
  if (!techniques->Apply(scratch, name.c_str(), options.c_str()))
  {
    vtkErrorMacro("Penumbra shadows: technique \""
      << name << "\" with options \"" << options << "\" refused: " << techniques->GetErrorMessage()
      << "; still drawing with \"" << this->InstalledTechnique << "\"");
    this->Refused = true;
    return;
  }
  this->Refused = false;
  vtkCameraPass* camera = vtkCameraPass::SafeDownCast(scratch->GetPass());
  vtkRenderPass* pass = camera ? camera->GetDelegatePass() : scratch->GetPass();
  if (this->Impl->Pass && this->Impl->Pass != pass && this->GetRenderWindow())
  {
    this->Impl->Pass->ReleaseGraphicsResources(this->GetRenderWindow());
  }
  this->Impl->Pass = pass;
  this->SynchronizedRenderers->SetRenderPass(pass);
  // ParaView wraps the pass (IceT's compositing pass under MPI): record it for
  // vtkPenumbraShadowPass::GetInstalled(), which the plugin's tests read.
  vtkPenumbraShadowPass::SetInstalled(
    this->GetRenderer(), vtkPenumbraShadowPass::SafeDownCast(pass));
  this->InstalledTechnique = name;
  this->InstalledOptions = options;
  this->InstalledOptionsText = this->Options;
  auto values = this->Impl->OptionValues.find(name);
  this->InstalledOptionValues =
    values != this->Impl->OptionValues.end() ? values->second.dump() : std::string("{}");
}

void vtkPVPenumbraShadowView::Render(bool interactive, bool skip_rendering)
{
  this->UpdateShadowPass();
  this->Superclass::Render(interactive, skip_rendering);
}

void vtkPVPenumbraShadowView::AboutToRenderOnLocalProcess(bool interactive)
{
  this->Superclass::AboutToRenderOnLocalProcess(interactive);
  this->GatherCasters();
}

void vtkPVPenumbraShadowView::GatherCasters()
{
  Internals& impl = *this->Impl;
  auto* pass = vtkPenumbraShadowPass::SafeDownCast(impl.Pass);
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  // The same decision on every rank: the technique, the process count and the distributed
  // rendering mode are the same everywhere (the last is all-reduced by ParaView). Without
  // distributed rendering the data is collected where it is drawn, and nothing is missing.
  // The LOD mesh is never drawn (see the class description), so the still-render mode holds.
  const bool distributed = controller && controller->GetNumberOfProcesses() > 1 &&
    this->GetUseDistributedRenderingForRender();
  if (!pass || !distributed)
  {
    if (pass)
    {
      pass->GetGeometry()->SetShadowOnlyProps(nullptr);
      pass->GetGeometry()->SetSceneBounds(nullptr);
      pass->SetRemoteShadows(nullptr);
    }
    return;
  }
  std::string error;
  if (!impl.Exchange.Update(controller, this->GetRenderer(),
        static_cast<penumbra::CasterExchange::Mode>(this->CasterExchange),
        this->CasterMemoryBudget * 1048576.0, error))
  {
    vtkErrorMacro("Penumbra shadows: " << error);
  }
  pass->GetGeometry()->SetShadowOnlyProps(impl.Exchange.GetShadowOnlyProps());
  // The origin and the epsilons of the whole scene, as in one process.
  pass->GetGeometry()->SetSceneBounds(impl.Exchange.GetSceneBounds());
  // Without the other ranks' casters, their shadows come back as answers to rays.
  if (impl.Exchange.GetEffectiveMode() == penumbra::CasterExchange::Distributed)
  {
    impl.Queries->SetCasterBoxes(controller, impl.Exchange.GetCasterBoxes());
    impl.Queries->SetCastersChanged(impl.Exchange.GetExchangedLastUpdate());
    pass->SetRemoteShadows(impl.Queries);
  }
  else
  {
    pass->SetRemoteShadows(nullptr);
  }
}

void vtkPVPenumbraShadowView::SetCasterExchange(int mode)
{
  if (mode < 0 || mode > 2)
  {
    vtkErrorMacro("CasterExchange " << mode
                                    << " is not 0 (need), 1 (all) or 2 (distributed); "
                                       "keeping "
                                    << this->CasterExchange);
    return;
  }
  if (mode != this->CasterExchange)
  {
    this->CasterExchange = mode;
    this->Modified();
  }
}

vtkIdType vtkPVPenumbraShadowView::GetNumberOfRaysSent()
{
  return this->RayQueriesActive() ? this->Impl->Queries->GetFigures().RaysSent : 0;
}

vtkIdType vtkPVPenumbraShadowView::GetRayBytesSent()
{
  return this->RayQueriesActive() ? this->Impl->Queries->GetFigures().BytesSent : 0;
}

vtkIdType vtkPVPenumbraShadowView::GetRayBytesReceived()
{
  return this->RayQueriesActive() ? this->Impl->Queries->GetFigures().BytesReceived : 0;
}

bool vtkPVPenumbraShadowView::RayQueriesActive()
{
  auto* pass = vtkPenumbraShadowPass::SafeDownCast(this->Impl->Pass);
  return pass && pass->GetRemoteShadows() == this->Impl->Queries.GetPointer();
}

void vtkPVPenumbraShadowView::SetCasterMemoryBudget(double megabytes)
{
  if (!std::isfinite(megabytes) || megabytes < 0.0)
  {
    vtkErrorMacro("CasterMemoryBudget " << megabytes
                                        << " MiB is not a finite number >= 0 (0: "
                                           "no limit); keeping "
                                        << this->CasterMemoryBudget);
    return;
  }
  if (megabytes != this->CasterMemoryBudget)
  {
    this->CasterMemoryBudget = megabytes;
    this->Modified();
  }
}

const char* vtkPVPenumbraShadowView::GetCasterExchangeReport()
{
  Internals& impl = *this->Impl;
  impl.ExchangeReport = impl.Exchange.GetReport();
  if (this->RayQueriesActive())
  {
    impl.ExchangeReport += impl.Queries->GetReport();
  }
  return impl.ExchangeReport.c_str();
}

vtkIdType vtkPVPenumbraShadowView::GetCasterBytesSent()
{
  return this->Impl->Exchange.GetFigures().BytesSent;
}

vtkIdType vtkPVPenumbraShadowView::GetNumberOfCasterTrianglesSent()
{
  return this->Impl->Exchange.GetFigures().TrianglesSent;
}

double vtkPVPenumbraShadowView::GetLastCasterGatherMs()
{
  return this->Impl->Exchange.GetFigures().TotalMs;
}

vtkIdType vtkPVPenumbraShadowView::GetNumberOfRemoteCasterTriangles()
{
  return this->Impl->Exchange.GetFigures().TrianglesHeld;
}

vtkIdType vtkPVPenumbraShadowView::GetCasterBytesReceived()
{
  return this->Impl->Exchange.GetFigures().BytesReceived;
}

int vtkPVPenumbraShadowView::GetNumberOfCasterGathers()
{
  return this->Impl->Exchange.GetFigures().Exchanges;
}

void vtkPVPenumbraShadowView::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ShadowTechnique: " << this->Technique << "\n";
  os << indent << "ShadowOptions: " << this->Options << "\n";
  os << indent << "InstalledTechnique: " << this->InstalledTechnique << "\n";
  os << indent << "InstalledShadowOptions: " << this->InstalledOptionsText << "\n";
  const char* modes[] = { "need", "all", "distributed" };
  os << indent << "CasterExchange: " << modes[this->CasterExchange] << "\n";
  os << indent << "CasterMemoryBudget: " << this->CasterMemoryBudget << " MiB\n";
  os << indent << "ShadowRequestRefused: " << (this->Refused ? "yes" : "no") << "\n";
}
