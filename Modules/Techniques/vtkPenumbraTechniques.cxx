#include "vtkPenumbraTechniques.h"

#include "vtkActor.h"
#include "vtkCameraPass.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAutoShadows.h"
#include "vtkPenumbraExactTechniques.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraGearsTechniques.h"
#include "vtkPenumbraMapperDraws.h"
#include "vtkPenumbraShadowMapTechniques.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraTechniqueOptions.h"
#include "vtkProperty.h"
#include "vtkRenderPassCollection.h"
#include "vtkRenderState.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSequencePass.h"
#include "vtkShadowMapBakerPass.h"
#include "vtkShadowMapPass.h"

#include <nlohmann/json.hpp>

#include <cstring>
#include <functional>
#include <set>
#include <string>
#include <vector>

using namespace penumbra_options;

namespace
{
// The renderer's pass that Penumbra last put on it (its information): what Apply() finds
// there again is its own; anything else is the user's.
vtkInformationObjectBaseKey* PenumbraTop()
{
  static vtkInformationObjectBaseKey* key =
    new vtkInformationObjectBaseKey("PENUMBRA_TOP_PASS", "vtkPenumbraTechniques");
  return key;
}

// The pass the renderer draws with apart from Penumbra: none, or the user's own, which
// Penumbra's shadow pass wraps (its delegate) while shadows are on.
vtkRenderPass* UserPass(vtkRenderer* ren)
{
  vtkRenderPass* top = ren->GetPass();
  vtkInformation* info = ren->GetInformation();
  if (!top || !info->Has(PenumbraTop()) || info->Get(PenumbraTop()) != top)
  {
    return top;
  }
  auto* shadows = vtkPenumbraShadowPass::SafeDownCast(top);
  return shadows && !shadows->GetDrawsWithRenderer() ? shadows->GetDelegatePass() : nullptr;
}

// A pass dropped while it still holds GL objects leaks them (VTK's shadow baker even reports
// it as an error), so the outgoing pass releases its resources first. `ours`: Penumbra's
// composition (recorded), or the user's pass given back.
void InstallPass(vtkRenderer* ren, vtkRenderPass* pass, bool ours)
{
  vtkRenderPass* old = ren->GetPass();
  if (old && old != pass && ren->GetRenderWindow())
  {
    old->ReleaseGraphicsResources(ren->GetRenderWindow());
  }
  ren->SetPass(pass);
  if (ours && pass)
  {
    ren->GetInformation()->Set(PenumbraTop(), pass);
  }
  else
  {
    ren->GetInformation()->Remove(PenumbraTop());
  }
}

// VTK's own shadow passes (vtkShadowMapBakerPass, vtkShadowMapPass) in a composition of the
// user's, replaced by a Penumbra shadow pass where they stand (the canonical
// CameraPass -> Sequence[baker, shadows], or a camera pass delegating to the shadow pass), so
// the scene is not shadowed twice; the replaced passes are kept on the renderer and put back
// when the shadows are removed.
class ReplacedVTKShadows : public vtkObject
{
public:
  static ReplacedVTKShadows* New();
  vtkTypeMacro(ReplacedVTKShadows, vtkObject);
  struct Slot
  {
    vtkSmartPointer<vtkRenderPassCollection> Collection; // or
    vtkSmartPointer<vtkCameraPass> Camera;
    int Index = -1;
    vtkSmartPointer<vtkRenderPass> Original;
  };
  std::vector<Slot> Slots;

  // Replaces VTK's shadow passes under `pass` by `ours`; true when there were any.
  bool Replace(vtkRenderPass* pass, vtkPenumbraShadowPass* ours, int depth = 0)
  {
    bool any = false;
    if (auto* camera = vtkCameraPass::SafeDownCast(pass))
    {
      if (vtkShadowMapPass::SafeDownCast(camera->GetDelegatePass()))
      {
        this->Slots.push_back({ nullptr, camera, -1, camera->GetDelegatePass() });
        camera->SetDelegatePass(ours);
        return true;
      }
      return depth < 16 && this->Replace(camera->GetDelegatePass(), ours, depth + 1);
    }
    auto* sequence = vtkSequencePass::SafeDownCast(pass);
    vtkRenderPassCollection* passes = sequence ? sequence->GetPasses() : nullptr;
    for (int i = 0; passes && i < passes->GetNumberOfItems(); ++i)
    {
      auto* item = vtkRenderPass::SafeDownCast(passes->GetItemAsObject(i));
      vtkRenderPass* replacement = vtkShadowMapPass::SafeDownCast(item) ? ours
        : vtkShadowMapBakerPass::SafeDownCast(item) ? ours->GetShadowMapBakerPass()
                                                    : nullptr;
      if (replacement)
      {
        this->Slots.push_back({ passes, nullptr, i, item });
        passes->ReplaceItem(i, replacement);
        any = true;
      }
      else if (depth < 16)
      {
        any = this->Replace(item, ours, depth + 1) || any;
      }
    }
    return any;
  }

  // Puts VTK's passes back.
  void Restore()
  {
    for (auto& slot : this->Slots)
    {
      if (slot.Camera)
      {
        slot.Camera->SetDelegatePass(slot.Original);
      }
      else
      {
        slot.Collection->ReplaceItem(slot.Index, slot.Original);
      }
    }
    this->Slots.clear();
  }

protected:
  ReplacedVTKShadows() = default;
  ~ReplacedVTKShadows() override = default;
};
vtkStandardNewMacro(ReplacedVTKShadows);

vtkInformationObjectBaseKey* ReplacedKey()
{
  static vtkInformationObjectBaseKey* key =
    new vtkInformationObjectBaseKey("PENUMBRA_REPLACED_VTK_SHADOWS", "vtkPenumbraTechniques");
  return key;
}

// Gives the user's composition its VTK shadow passes back, if Penumbra replaced them.
void RestoreVTKShadows(vtkRenderer* ren)
{
  vtkInformation* info = ren->GetInformation();
  if (auto* replaced = ReplacedVTKShadows::SafeDownCast(info->Get(ReplacedKey())))
  {
    replaced->Restore();
    info->Remove(ReplacedKey());
  }
}

// Shadows with `technique`, composed with what the renderer draws with. The renderer's own
// drawing: camera pass -> shadow pass. A pass of the user's (vtkOutlineGlowPass,
// vtkSSAOPass, a render-steps pass ...): the shadow pass stands before it and it draws the
// shadowed scene (its own camera pass included), so nothing of it is lost. A composition
// that already holds a Penumbra shadow pass (the drop-in vtkPenumbraShadowMapPass in
// `CameraPass -> Sequence[baker, shadows]`): its technique is replaced where it stands.
void InstallShadowPass(vtkRenderer* ren, vtkPenumbraShadowTechnique* technique)
{
  vtkRenderPass* user = UserPass(ren);
  if (vtkPenumbraShadowPass* placed = vtkPenumbraShadowPass::FindIn(user))
  {
    placed->SetTechnique(technique);
    return;
  }
  vtkNew<vtkPenumbraShadowPass> shadows;
  shadows->SetTechnique(technique);
  vtkNew<ReplacedVTKShadows> replaced;
  if (user && replaced->Replace(user, shadows))
  {
    ren->GetInformation()->Set(ReplacedKey(), replaced);
    return;
  }
  if (user)
  {
    shadows->SetDelegatePass(user);
    InstallPass(ren, shadows, true);
    return;
  }
  vtkNew<vtkCameraPass> camera;
  camera->SetDelegatePass(shadows);
  InstallPass(ren, camera, true);
}

struct Technique
{
  const char* Name;
  const char* Description;
  OptionTable Table;
  std::function<void(vtkRenderer*, const Options&)> Install;
};

// A technique a family (or auto) describes, installed as the shadow pass's technique.
Technique Installed(const TechniqueInfo& info)
{
  auto create = info.Create;
  return { info.Name, info.Description, info.Table,
    [create](vtkRenderer* ren, const Options& opts) { InstallShadowPass(ren, create(opts)); } };
}

// No shadows: the renderer draws as it did before Penumbra, with the user's own pass if it
// had one; a user's composition holding a Penumbra pass keeps it, without a technique.
void InstallNone(vtkRenderer* ren, const Options&)
{
  RestoreVTKShadows(ren);
  vtkRenderPass* user = UserPass(ren);
  if (vtkPenumbraShadowPass* placed = vtkPenumbraShadowPass::FindIn(user))
  {
    placed->SetTechnique(nullptr);
    return;
  }
  InstallPass(ren, user, false);
}

// VTK's vtkShadowMapPass with one addition: it says, once per light, which lights it leaves
// unshadowed (its baker's LightCreatesShadow(): headlights, positional lights with a cone of
// 90 degrees or more, i.e. point lights and Penumbra's area lights), instead of drawing them
// without a shadow and without a word.
class CheckedShadowMapPass : public vtkShadowMapPass
{
public:
  static CheckedShadowMapPass* New();
  vtkTypeMacro(CheckedShadowMapPass, vtkShadowMapPass);
  void Render(const vtkRenderState* s) override
  {
    vtkLightCollection* lights = s->GetRenderer()->GetLights();
    vtkCollectionSimpleIterator it;
    lights->InitTraversal(it);
    int index = 0;
    while (vtkLight* light = lights->GetNextLight(it))
    {
      if (!light->GetSwitch())
      {
        continue;
      }
      if (!this->GetShadowMapBakerPass()->LightCreatesShadow(light) &&
        this->Told.insert(light).second)
      {
        vtkWarningMacro(
          "Light " << index
                   << " gets no shadow from vtk-shadowmap: VTK's "
                      "vtkShadowMapPass shadows only directional lights and spot lights with a "
                      "cone under 90 degrees (not point, area, linear or head lights); use "
                      "auto, shadowmap or raytraced to shadow it");
      }
      ++index;
    }
    this->Superclass::Render(s);
  }

  // VTK 9.1's pass injects its lookup into every shader of every prop and fails to compile
  // it where the shader has no view position (lines without normals, unlit props; the next
  // frame then crashes in the mapper). Its receivers here are lit surfaces only, the props
  // VTK's pass is written for: the others are drawn unshadowed.
  // VTK injects again when a prop holds the pass twice in its keys (an actor drawn by itself
  // and as an assembly part): once is enough.
  bool PreReplaceShaderValues(std::string& vs, std::string& gs, std::string& fs,
    vtkAbstractMapper* mapper, vtkProp* prop) override
  {
    return !Receives(mapper, prop) || fs.find("calcShadow") != std::string::npos ||
      this->Superclass::PreReplaceShaderValues(vs, gs, fs, mapper, prop);
  }
  bool PostReplaceShaderValues(std::string& vs, std::string& gs, std::string& fs,
    vtkAbstractMapper* mapper, vtkProp* prop) override
  {
    return !Receives(mapper, prop) ||
      this->Superclass::PostReplaceShaderValues(vs, gs, fs, mapper, prop);
  }

private:
  static bool Receives(vtkAbstractMapper* mapper, vtkProp* prop)
  {
    auto* actor = vtkActor::SafeDownCast(prop);
    return actor && actor->GetProperty()->GetLighting() &&
      penumbra_draws::DrawsSurface(mapper, prop);
  }
  std::set<vtkLight*> Told;
};
vtkStandardNewMacro(CheckedShadowMapPass);

// VTK's baker, injecting its depth output once per shader even when a prop holds the pass
// twice in its keys (VTK 9.1 redeclares its uniforms and the next frame crashes).
class CheckedShadowMapBakerPass : public vtkShadowMapBakerPass
{
public:
  static CheckedShadowMapBakerPass* New();
  vtkTypeMacro(CheckedShadowMapBakerPass, vtkShadowMapBakerPass);
  bool PreReplaceShaderValues(std::string& vs, std::string& gs, std::string& fs,
    vtkAbstractMapper* mapper, vtkProp* prop) override
  {
    return fs.find("uniform float depthC;") != std::string::npos ||
      this->Superclass::PreReplaceShaderValues(vs, gs, fs, mapper, prop);
  }
};
vtkStandardNewMacro(CheckedShadowMapBakerPass);

const OptionTable VTKShadowMapOptions = {
  { "resolution", OptionType::Integer, 1024, 16, 16384, {}, "texels",
    "shadow map texels per side" },
};

void InstallVTKShadowMap(vtkRenderer* ren, const Options& opts)
{
  // The composition of VTK's own TestShadowMapPass: bake the maps, then shade with them.
  // It draws the opaque props itself, so it cannot stand before a pass of the user's; a
  // composition of the user's with VTK's shadow passes gets them back.
  RestoreVTKShadows(ren);
  vtkRenderPass* user = UserPass(ren);
  vtkNew<ReplacedVTKShadows> probe; // whether the user's composition has VTK's passes
  vtkNew<vtkPenumbraShadowPass> scratch;
  if (user && probe->Replace(user, scratch))
  {
    probe->Restore(); // it has: they are VTK's shadow map already
    return;
  }
  if (user)
  {
    throw OptionError(std::string("the renderer draws with its own ") + user->GetClassName() +
      ", which VTK's vtkShadowMapPass cannot be composed with (it draws the opaque props "
      "itself); use a Penumbra technique, e.g. shadowmap");
  }
  vtkNew<CheckedShadowMapPass> shadows;
  shadows->SetShadowMapBakerPass(vtkNew<CheckedShadowMapBakerPass>());
  shadows->GetShadowMapBakerPass()->SetResolution(opts.Integer("resolution"));
  vtkNew<vtkRenderPassCollection> passes;
  passes->AddItem(shadows->GetShadowMapBakerPass());
  passes->AddItem(shadows);
  vtkNew<vtkSequencePass> sequence;
  sequence->SetPasses(passes);
  vtkNew<vtkCameraPass> camera;
  camera->SetDelegatePass(sequence);
  InstallPass(ren, camera, true);
}

// Per light, an exact technique chosen by light type (vtkPenumbraAutoShadows says which and
// why).
const OptionTable AutoOptions = {
  { "quality", OptionType::Choice, "balanced", 0, 0, { "balanced", "exact", "fast" }, "",
    "\"balanced\" and \"exact\": the faster exact technique for each light's type; "
    "\"fast\": area and linear lights at 4 x 4 light samples" },
  SamplesOption(),
};

vtkSmartPointer<vtkPenumbraShadowTechnique> CreateAuto(const Options& opts)
{
  const int quality = opts.Choice("quality");
  auto technique = vtkSmartPointer<vtkPenumbraAutoShadows>::New();
  technique->SetQuality(quality == 1 ? vtkPenumbraAutoShadows::QUALITY_EXACT
      : quality == 2                 ? vtkPenumbraAutoShadows::QUALITY_FAST
                                     : vtkPenumbraAutoShadows::QUALITY_BALANCED);
  technique->SetSamplesPerAxis(opts.Integer("samples"));
  return technique;
}

// Every technique: the registry's own (no shadows, auto, VTK's pass), then each family's list
// (a family describes its techniques beside their classes; one line here per family).
const std::vector<Technique>& Registry()
{
  static const std::vector<Technique> techniques = []()
  {
    std::vector<Technique> all = {
      { "none", "plain VTK rendering without shadows", {}, InstallNone },
      Installed({ "auto",
        "per light, an exact technique chosen by its type: raytraced for hard lights, gears "
        "for area and linear lights; quality=fast uses 4 x 4 light samples",
        AutoOptions, CreateAuto }),
      { "vtk-shadowmap",
        "VTK's vtkShadowMapPass (exponential shadow map; directional lights and spot lights "
        "under 90 degrees, opaque props only; peer for comparison)",
        VTKShadowMapOptions, InstallVTKShadowMap },
    };
    for (const TechniqueList* family : { &penumbra_exact_shadows::Techniques(),
           &penumbra_shadow_maps::Techniques(), &penumbra_gears::Techniques() })
    {
      for (const TechniqueInfo& info : *family)
      {
        all.push_back(Installed(info));
      }
    }
    return all;
  }();
  return techniques;
}

const Technique* Find(const char* name)
{
  for (const auto& t : Registry())
  {
    if (name && std::strcmp(t.Name, name) == 0)
    {
      return &t;
    }
  }
  return nullptr;
}
}

namespace
{
// The pass's fallback for lights its technique cannot shadow (area and linear lights under a
// hard-shadow technique): exact soft shadows at the light's own k (Wang, Wang, Shi, Popescu,
// "GEARS: A General and Efficient Algorithm for Rendering Shadows", Computer Graphics Forum
// 33(6), 2014). Registered here, when this library is loaded: the contract names no technique.
vtkPenumbraShadowTechnique* NewSoftFallback()
{
  return vtkPenumbraGearsShadows::New();
}
const bool SoftFallbackRegistered =
  (vtkPenumbraShadowPass::SetDefaultFallbackFactory(&NewSoftFallback), true);
}

vtkStandardNewMacro(vtkPenumbraTechniques);

const char* vtkPenumbraTechniques::GetDefaultTechnique()
{
  return "auto";
}

int vtkPenumbraTechniques::GetNumberOfTechniques()
{
  return static_cast<int>(Registry().size());
}

const char* vtkPenumbraTechniques::GetTechniqueName(int index)
{
  return (index >= 0 && index < GetNumberOfTechniques())
    ? Registry()[static_cast<size_t>(index)].Name
    : nullptr;
}

const char* vtkPenumbraTechniques::GetTechniqueDescription(int index)
{
  return (index >= 0 && index < GetNumberOfTechniques())
    ? Registry()[static_cast<size_t>(index)].Description
    : nullptr;
}

bool vtkPenumbraTechniques::HasTechnique(const char* name)
{
  return Find(name) != nullptr;
}

namespace
{
// Row `index` of technique `name`'s option table, or nullptr.
const OptionSpec* FindOption(const char* technique, int index)
{
  const Technique* t = Find(technique);
  return (t && index >= 0 && index < static_cast<int>(t->Table.size()))
    ? &t->Table[static_cast<size_t>(index)]
    : nullptr;
}

std::string MarkdownCell(std::string text)
{
  for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2))
  {
    text.replace(at, 1, "\\|");
  }
  return text;
}
}

int vtkPenumbraTechniques::GetNumberOfOptions(const char* technique)
{
  const Technique* t = Find(technique);
  return t ? static_cast<int>(t->Table.size()) : 0;
}

const char* vtkPenumbraTechniques::GetOptionName(const char* technique, int index)
{
  const OptionSpec* spec = FindOption(technique, index);
  return spec ? spec->Name : nullptr;
}

const char* vtkPenumbraTechniques::GetOptionType(const char* technique, int index)
{
  const OptionSpec* spec = FindOption(technique, index);
  return spec ? TypeName(spec->Type) : nullptr;
}

std::string vtkPenumbraTechniques::GetOptionDefault(const char* technique, int index)
{
  const OptionSpec* spec = FindOption(technique, index);
  return spec ? spec->Default.dump() : std::string();
}

std::string vtkPenumbraTechniques::GetOptionRange(const char* technique, int index)
{
  const OptionSpec* spec = FindOption(technique, index);
  return spec ? RangeText(*spec) : std::string();
}

bool vtkPenumbraTechniques::GetOptionBounds(const char* technique, int index, double bounds[2])
{
  const OptionSpec* spec = FindOption(technique, index);
  if (!spec || !spec->Values.empty() ||
    (spec->Type != OptionType::Integer && spec->Type != OptionType::Number))
  {
    return false;
  }
  bounds[0] = spec->Min;
  bounds[1] = spec->Max;
  return true;
}

std::vector<std::string> vtkPenumbraTechniques::GetOptionChoices(const char* technique, int index)
{
  std::vector<std::string> choices;
  if (const OptionSpec* spec = FindOption(technique, index))
  {
    for (const json& value : spec->Values)
    {
      choices.push_back(value.dump());
    }
  }
  return choices;
}

const char* vtkPenumbraTechniques::GetOptionUnit(const char* technique, int index)
{
  const OptionSpec* spec = FindOption(technique, index);
  return spec ? spec->Unit : nullptr;
}

const char* vtkPenumbraTechniques::GetOptionDoc(const char* technique, int index)
{
  const OptionSpec* spec = FindOption(technique, index);
  return spec ? spec->Doc : nullptr;
}

std::string vtkPenumbraTechniques::GetTechniqueList()
{
  std::string text;
  for (const auto& t : Registry())
  {
    text += std::string(t.Name) + "\t" + t.Description + "\n";
    for (const auto& spec : t.Table)
    {
      text += "    " + std::string(spec.Name) + " (" + TypeName(spec.Type) + "; default " +
        spec.Default.dump() + "; " + RangeText(spec) +
        (*spec.Unit ? std::string("; ") + spec.Unit : "") + "): " + spec.Doc + "\n";
    }
  }
  return text;
}

std::string vtkPenumbraTechniques::GetOptionsMarkdown()
{
  std::string text =
    "<!-- Generated by `penumbra-render --options-markdown` from the option tables beside\n"
    "     each family (Modules/*/vtkPenumbra*Techniques.cxx): edit those, then regenerate. -->\n";
  for (const auto& t : Registry())
  {
    text += "\n### `" + std::string(t.Name) + "`\n\n" + t.Description + ".\n\n";
    if (t.Table.empty())
    {
      text += "No options.\n";
      continue;
    }
    text += "| option | type | default | range or choices | unit | meaning |\n"
            "|---|---|---|---|---|---|\n";
    for (const auto& spec : t.Table)
    {
      text += "| `" + std::string(spec.Name) + "` | " + TypeName(spec.Type) + " | " +
        MarkdownCell(spec.Default.dump()) + " | " + MarkdownCell(RangeText(spec)) + " | " +
        (*spec.Unit ? spec.Unit : "—") + " | " + MarkdownCell(spec.Doc) + " |\n";
    }
  }
  return text;
}

int vtkPenumbraTechniques::Apply(vtkRenderer* renderer, const char* name, const char* options)
{
  this->ErrorMessage.clear();
  const Technique* technique = Find(name);
  if (!technique)
  {
    std::string known;
    for (const auto& t : Registry())
    {
      known += (known.empty() ? "" : ", ") + std::string(t.Name);
    }
    this->ErrorMessage =
      "unknown technique \"" + std::string(name ? name : "") + "\" (available: " + known + ")";
    return 0;
  }
  if (!renderer)
  {
    this->ErrorMessage = "no renderer given";
    return 0;
  }
  try
  {
    const json parsed = (options && *options) ? json::parse(options) : json::object();
    if (!parsed.is_object())
    {
      throw OptionError("options must be a JSON object");
    }
    const Options opts(parsed, technique->Table);
    technique->Install(renderer, opts);
  }
  catch (const OptionError& e)
  {
    this->ErrorMessage = e.what();
    return 0;
  }
  catch (const json::exception& e)
  {
    this->ErrorMessage = std::string("options are not valid JSON: ") + e.what();
    return 0;
  }
  return 1;
}

void vtkPenumbraTechniques::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  for (const auto& t : Registry())
  {
    os << indent << t.Name << ": " << t.Description << "\n";
  }
}
