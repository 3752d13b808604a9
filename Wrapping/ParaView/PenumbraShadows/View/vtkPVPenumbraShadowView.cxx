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
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraHeadlessFactory.h"
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

namespace
{
// A triangle's 9 world coordinates, hashed bit for bit (splitmix64 per coordinate).
std::uint64_t HashTriangle(const double* t)
{
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (int k = 0; k < 9; ++k)
  {
    std::uint64_t z;
    std::memcpy(&z, t + k, sizeof z);
    z = (z ^ h) + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    h = z ^ (z >> 31);
  }
  return h;
}
}

struct vtkPVPenumbraShadowView::Internals
{
  vtkSmartPointer<vtkRenderPass> Pass;
  vtkNew<vtkStringArray> Names;
  // Per technique, the values its option properties set: {"resolution": 2048, ...}.
  std::map<std::string, nlohmann::json> OptionValues;

  // Caster gathering across ranks (GatherCasters).
  vtkNew<vtkPenumbraSceneGeometry> Local; // this rank's props only
  vtkNew<vtkDoubleArray> LocalCasters;
  vtkNew<vtkPolyData> Remote; // the other ranks' casters, world coordinates
  vtkNew<vtkActor> RemoteActor;
  vtkNew<vtkPropCollection> ShadowOnly;
  penumbra::CastersStamp Sent; // the local casters last sent to the other ranks
  double GatherMs = 0.0;
  vtkIdType RemoteTriangles = 0, BytesReceived = 0;
  int Gathers = 0;

  Internals()
  {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputData(this->Remote);
    this->RemoteActor->SetMapper(mapper);
    // Drawn by the rank that owns them; here they only cast.
    vtkPenumbraShadowKeys::SetReceivesShadows(this->RemoteActor, false);
    vtkPenumbraSceneGeometry::SetPropName(this->RemoteActor, "other ranks' casters");
    this->ShadowOnly->AddItem(this->RemoteActor);
  }

  // All ranks' caster triangles in, the other ranks' distinct ones (not already local) out.
  bool Exchange(vtkMultiProcessController* controller);
  void BuildRemote(const std::vector<double>& all, const std::vector<vtkIdType>& lengths,
    const std::vector<vtkIdType>& offsets, int me);
};

bool vtkPVPenumbraShadowView::Internals::Exchange(vtkMultiProcessController* controller)
{
  const int ranks = controller->GetNumberOfProcesses();
  const int me = controller->GetLocalProcessId();
  const vtkIdType length = 9 * this->LocalCasters->GetNumberOfTuples();
  std::vector<vtkIdType> lengths(ranks, 0), offsets(ranks, 0);
  controller->AllGather(&length, lengths.data(), 1);
  vtkIdType total = 0;
  for (int r = 0; r < ranks; ++r)
  {
    offsets[r] = total;
    total += lengths[r];
  }
  // MPI counts and displacements are ints.
  if (total > INT_MAX)
  {
    return false;
  }
  std::vector<double> all(static_cast<size_t>(total));
  if (total > 0)
  {
    controller->AllGatherV(
      this->LocalCasters->GetPointer(0), all.data(), length, lengths.data(), offsets.data());
  }
  this->BytesReceived = static_cast<vtkIdType>(sizeof(double)) * (total - length);
  this->BuildRemote(all, lengths, offsets, me);
  return true;
}

void vtkPVPenumbraShadowView::Internals::BuildRemote(const std::vector<double>& all,
  const std::vector<vtkIdType>& lengths, const std::vector<vtkIdType>& offsets, int me)
{
  // Each distinct triangle once: replicated data, or boundary cells duplicated by a
  // redistribution, would otherwise shadow the very samples they are drawn with. Equal
  // triangles end up next to each other, a local one first: it drops the others; otherwise
  // the first of them is kept.
  const vtkIdType count = static_cast<vtkIdType>(all.size() / 9);
  const vtkIdType localBegin = offsets[me] / 9, localEnd = (offsets[me] + lengths[me]) / 9;
  auto local = [&](vtkIdType t) { return t >= localBegin && t < localEnd; };
  std::vector<std::pair<std::uint64_t, vtkIdType>> order(static_cast<size_t>(count));
  for (vtkIdType t = 0; t < count; ++t)
  {
    order[t] = { HashTriangle(all.data() + 9 * t), t };
  }
  auto same = [&](vtkIdType a, vtkIdType b)
  { return std::memcmp(all.data() + 9 * a, all.data() + 9 * b, 9 * sizeof(double)) == 0; };
  std::sort(order.begin(), order.end(),
    [&](const auto& a, const auto& b)
    {
      if (a.first != b.first)
      {
        return a.first < b.first;
      }
      const int bytes = std::memcmp(all.data() + 9 * a.second, all.data() + 9 * b.second, 72);
      return bytes != 0
        ? bytes < 0
        : std::make_pair(!local(a.second), a.second) < std::make_pair(!local(b.second), b.second);
    });
  std::vector<vtkIdType> kept;
  for (size_t i = 0; i < order.size(); ++i)
  {
    const vtkIdType t = order[i].second;
    const bool first =
      i == 0 || order[i - 1].first != order[i].first || !same(order[i - 1].second, t);
    if (first && !local(t))
    {
      kept.push_back(t);
    }
  }
  std::sort(kept.begin(), kept.end()); // the ranks' order, as they extracted them

  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(3 * static_cast<vtkIdType>(kept.size()));
  vtkNew<vtkIdTypeArray> connectivity, cellOffsets;
  connectivity->SetNumberOfValues(3 * static_cast<vtkIdType>(kept.size()));
  cellOffsets->SetNumberOfValues(static_cast<vtkIdType>(kept.size()) + 1);
  double* xyz = coordinates->GetPointer(0);
  for (size_t k = 0; k < kept.size(); ++k)
  {
    std::copy_n(all.data() + 9 * kept[k], 9, xyz + 9 * k);
    cellOffsets->SetValue(static_cast<vtkIdType>(k), 3 * static_cast<vtkIdType>(k));
  }
  cellOffsets->SetValue(
    static_cast<vtkIdType>(kept.size()), 3 * static_cast<vtkIdType>(kept.size()));
  for (vtkIdType i = 0; i < connectivity->GetNumberOfValues(); ++i)
  {
    connectivity->SetValue(i, i);
  }
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  vtkNew<vtkCellArray> polys;
  polys->SetData(cellOffsets, connectivity);
  this->Remote->Initialize();
  this->Remote->SetPoints(points);
  this->Remote->SetPolys(polys);
  this->RemoteTriangles = static_cast<vtkIdType>(kept.size());
}

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
    }
    return;
  }
  const auto start = penumbra::Clock::now();
  // A rank whose extraction fails (NaN coordinates: reported by the geometry) sends nothing
  // but still takes part, so no rank waits for it.
  if (!impl.Local->Update(this->GetRenderer()))
  {
    impl.LocalCasters->SetNumberOfTuples(0);
  }
  int changed = impl.Sent.Changed(impl.Local);
  int anyChanged = 0;
  controller->AllReduce(&changed, &anyChanged, 1, vtkCommunicator::MAX_OP);
  if (anyChanged)
  {
    impl.Local->GetCasterWorldTriangles(impl.LocalCasters);
    if (!impl.Exchange(controller))
    {
      vtkErrorMacro("Penumbra shadows: the casters of all ranks exceed one MPI message "
                    "(2^31 coordinates); shadows from other ranks are left out");
      impl.Remote->Initialize();
    }
    impl.Sent.Remember(impl.Local);
    impl.GatherMs = penumbra::ElapsedMs(start);
    ++impl.Gathers;
  }
  pass->GetGeometry()->SetShadowOnlyProps(impl.ShadowOnly);
}

double vtkPVPenumbraShadowView::GetLastCasterGatherMs()
{
  return this->Impl->GatherMs;
}

vtkIdType vtkPVPenumbraShadowView::GetNumberOfRemoteCasterTriangles()
{
  return this->Impl->RemoteTriangles;
}

vtkIdType vtkPVPenumbraShadowView::GetCasterBytesReceived()
{
  return this->Impl->BytesReceived;
}

int vtkPVPenumbraShadowView::GetNumberOfCasterGathers()
{
  return this->Impl->Gathers;
}

void vtkPVPenumbraShadowView::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ShadowTechnique: " << this->Technique << "\n";
  os << indent << "ShadowOptions: " << this->Options << "\n";
  os << indent << "InstalledTechnique: " << this->InstalledTechnique << "\n";
  os << indent << "InstalledShadowOptions: " << this->InstalledOptionsText << "\n";
  os << indent << "ShadowRequestRefused: " << (this->Refused ? "yes" : "no") << "\n";
}
