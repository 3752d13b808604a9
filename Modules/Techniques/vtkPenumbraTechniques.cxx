#include "vtkPenumbraTechniques.h"

#include "vtkCameraPass.h"
#include "vtkActor.h"
#include "vtkPenumbraMapperDraws.h"
#include "vtkProperty.h"
#include "vtkInformation.h"
#include "vtkRenderPassCollection.h"
#include "vtkSequencePass.h"
#include "vtkShadowMapBakerPass.h"
#include "vtkShadowMapPass.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAutoShadows.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraLinkedListShadows.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraResolutionMatchedShadows.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowVolumeShadows.h"
#include "vtkPenumbraSoftShadowMapShadows.h"
#include "vtkRenderPassCollection.h"
#include "vtkRenderState.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSequencePass.h"
#include "vtkShadowMapBakerPass.h"
#include "vtkShadowMapPass.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <functional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

using json = nlohmann::json;

namespace
{
struct OptionError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

enum class OptionType
{
  Integer,
  Number,
  Boolean,
  Choice
};

// One row of a technique's option table: everything validation, --list-techniques, the
// scene schema and the Python docstrings say about the option comes from here (the pbrt-v4
// rule: each option and its default named once).
struct OptionSpec
{
  const char* Name;
  OptionType Type;
  json Default;
  double Min = 0.0; // Integer, Number: inclusive range
  double Max = 0.0;
  std::vector<json> Values = {}; // Choice: the strings; Integer: the only values allowed, if any
  const char* Unit = "";
  const char* Doc = "";
};

using OptionTable = std::vector<OptionSpec>;

const char* TypeName(OptionType type)
{
  switch (type)
  {
    case OptionType::Integer:
      return "integer";
    case OptionType::Number:
      return "number";
    case OptionType::Boolean:
      return "boolean";
    case OptionType::Choice:
      return "choice";
  }
  return "";
}

std::string JoinValues(const std::vector<json>& values)
{
  std::string text;
  for (const auto& v : values)
  {
    text += (text.empty() ? "" : ", ") + v.dump();
  }
  return text;
}

// "64..8192", "0, 4, 8, 16, 32", "\"cpu\", \"gpu\"" or "true, false".
std::string RangeText(const OptionSpec& spec)
{
  switch (spec.Type)
  {
    case OptionType::Integer:
      return spec.Values.empty() ? json(static_cast<long long>(spec.Min)).dump() + ".." +
          json(static_cast<long long>(spec.Max)).dump()
                                 : JoinValues(spec.Values);
    case OptionType::Number:
      return json(spec.Min).dump() + ".." + json(spec.Max).dump();
    case OptionType::Boolean:
      return "true, false";
    case OptionType::Choice:
      return JoinValues(spec.Values);
  }
  return "";
}

// Checks `j` against a technique's table: known names only, each value of its type and in its
// range. Values are then read by name; an absent option gives the table's default.
class Options
{
public:
  Options(const json& j, const OptionTable& table)
    : J(j)
    , Table(table)
  {
    for (const auto& spec : table)
    {
      if (j.contains(spec.Name))
      {
        Check(spec, j.at(spec.Name));
      }
    }
    this->RejectUnknown();
  }

  int Integer(const char* key) const { return static_cast<int>(this->Value(key).get<long long>()); }
  double Number(const char* key) const { return this->Value(key).get<double>(); }
  bool Boolean(const char* key) const { return this->Value(key).get<bool>(); }

  // The index of the chosen value in the option's choices.
  int Choice(const char* key) const
  {
    const json& v = this->Value(key);
    const auto& values = this->Spec(key).Values;
    return static_cast<int>(std::find(values.begin(), values.end(), v) - values.begin());
  }

private:
  static void Check(const OptionSpec& spec, const json& v)
  {
    const std::string key = spec.Name;
    switch (spec.Type)
    {
      case OptionType::Integer:
        if (!v.is_number_integer() || v.get<long long>() < spec.Min ||
          v.get<long long>() > spec.Max)
        {
          throw OptionError(key + ": expected an integer in [" +
            json(static_cast<long long>(spec.Min)).dump() + ", " +
            json(static_cast<long long>(spec.Max)).dump() + "], got " + v.dump());
        }
        if (!spec.Values.empty() &&
          std::find(spec.Values.begin(), spec.Values.end(), v) == spec.Values.end())
        {
          throw OptionError(
            key + ": expected one of " + JoinValues(spec.Values) + ", got " + v.dump());
        }
        return;
      case OptionType::Number:
        if (!v.is_number() || !(v.get<double>() >= spec.Min) || !(v.get<double>() <= spec.Max))
        {
          throw OptionError(key + ": expected a number in [" + json(spec.Min).dump() + ", " +
            json(spec.Max).dump() + "], got " + v.dump());
        }
        return;
      case OptionType::Boolean:
        if (!v.is_boolean())
        {
          throw OptionError(key + ": expected true or false, got " + v.dump());
        }
        return;
      case OptionType::Choice:
        if (std::find(spec.Values.begin(), spec.Values.end(), v) == spec.Values.end())
        {
          throw OptionError(
            key + ": expected one of " + JoinValues(spec.Values) + ", got " + v.dump());
        }
        return;
    }
  }

  void RejectUnknown() const
  {
    for (auto it = this->J.begin(); it != this->J.end(); ++it)
    {
      const bool known = std::any_of(this->Table.begin(), this->Table.end(),
        [&](const OptionSpec& spec) { return it.key() == spec.Name; });
      if (!known)
      {
        std::string allowed;
        for (const auto& spec : this->Table)
        {
          allowed += (allowed.empty() ? "" : ", ") + std::string(spec.Name);
        }
        throw OptionError(it.key() + ": unknown option" +
          (allowed.empty() ? std::string(" (this technique has none)")
                           : " (allowed: " + allowed + ")"));
      }
    }
  }

  const OptionSpec& Spec(const char* key) const
  {
    for (const auto& spec : this->Table)
    {
      if (std::strcmp(spec.Name, key) == 0)
      {
        return spec;
      }
    }
    throw std::logic_error(std::string("option not in the technique's table: ") + key);
  }

  const json& Value(const char* key) const
  {
    const OptionSpec& spec = this->Spec(key);
    return this->J.contains(key) ? this->J.at(key) : spec.Default;
  }

  const json& J;
  const OptionTable& Table;
};

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
    return !Receives(mapper, prop) || this->Superclass::PostReplaceShaderValues(vs, gs, fs, mapper, prop);
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

// Light samples per axis for area/linear lights: 0 keeps the light's own k; otherwise one of
// the values Wang et al. 2014 measure, so GEARS and the ray tracer can be compared at equal k.
const OptionSpec SamplesOption = { "samples", OptionType::Integer, 0, 0, 32, { 0, 4, 8, 16, 32 },
  "samples per axis",
  "light samples per axis of area and linear lights (k x k, at the light's cell centres); 0 "
  "keeps the light's own `samples`" };

const OptionTable RayTracedOptions = { SamplesOption };

const OptionTable AdaptiveSoftOptions = { SamplesOption,
  { "block", OptionType::Integer, 8, 2, 16, {}, "pixels",
    "top block size: the exact rays are traced at the corners and centre of blocks this "
    "wide; a block whose corners predict its centre is interpolated, any other is split in "
    "four, down to 2 pixels" },
  { "tolerance", OptionType::Number, 0.05, 0.0, 1.0, {}, "visibility",
    "largest difference between a block centre's traced visibility and its bilinear "
    "prediction for which the block is interpolated" } };

// raytraced; adaptive-soft is the same tracer with its adaptive block set.
void InstallRayTraced(vtkRenderer* ren, const Options& opts, bool adaptive)
{
  vtkNew<vtkPenumbraRayTracedShadows> technique;
  technique->SetSamplesPerAxis(opts.Integer("samples"));
  if (adaptive)
  {
    technique->SetAdaptiveBlock(opts.Integer("block"));
    technique->SetAdaptiveTolerance(opts.Number("tolerance"));
  }
  InstallShadowPass(ren, technique);
}

const OptionTable ConservativeOptions = {
  { "resolution", OptionType::Integer, 1024, 64, 8192, {}, "texels",
    "conservative shadow map texels per side (per cube face for point lights)" },
  { "layers", OptionType::Integer, 2, 2, 4, {}, "",
    "depth-peeled map layers; more layers let more samples look past their own and "
    "neighbouring triangles, but cost more than the rays they save on llvmpipe" },
  { "map", OptionType::Choice, "cpu", 0, 0, { "cpu", "gpu" }, "",
    "who builds the map: \"cpu\", exact conservative rasterization in double precision with "
    "vtkSMPTools (several times faster on llvmpipe), or \"gpu\", a geometry-shader program with "
    "one draw per layer, read back; both are exact" },
};

void InstallConservative(vtkRenderer* ren, const Options& opts)
{
  vtkNew<vtkPenumbraConservativeShadows> technique;
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetLayers(opts.Integer("layers"));
  technique->SetMapBuilder(opts.Choice("map") == 1 ? vtkPenumbraConservativeShadows::MAP_GPU
                                                   : vtkPenumbraConservativeShadows::MAP_CPU);
  InstallShadowPass(ren, technique);
}

const OptionTable LinkedListOptions = {
  { "resolution", OptionType::Integer, 1024, 1, 4096, {}, "texels",
    "list-grid texels per side (per cube face for point lights); only speed depends on it: "
    "fewer texels give longer lists, 1 tests every caster against every sample" },
  { "capacity", OptionType::Integer, 0, 0, 2147483647, {}, "samples",
    "node-pool size: at most this many samples are listed per pass, the others in further "
    "passes (none is dropped); 0: one node per sample, one pass" },
  { "lists", OptionType::Choice, "cpu", 0, 0, { "cpu", "gpu" }, "",
    "who builds the per-texel lists: \"cpu\", a sort by texel (measured faster on Mesa "
    "llvmpipe), or \"gpu\", Ferko 2014's construction in a GL 4.3 compute shader (node pool, "
    "atomic counter, atomic head exchange; an overflowing pool lists the rest in another "
    "pass); the same lists and visibility, and the CPU builds them (with an error) where "
    "OpenGL 4.3 is missing" },
};

// llsm-hybrid: llsm's options and its classifier's.
OptionTable LinkedListHybridTable()
{
  OptionTable table = LinkedListOptions;
  table.push_back({ "classify_resolution", OptionType::Integer, 1024, 64, 8192, {}, "texels",
    "texels per side of the conservative shadow map that decides the easy samples" });
  table.push_back({ "classify_layers", OptionType::Integer, 3, 2, 4, {}, "",
    "depth-peeled layers of that map: each decides more samples without the lists (3 "
    "against 2: 0.6 % instead of 5.8 % of the city's samples listed, 4.6 % instead of 7.7 % "
    "of the isosurface's) at one more layer to build when the light or the view moves; 3 "
    "was the fastest with a still and with a moving light" });
  return table;
}
const OptionTable LinkedListHybridOptions = LinkedListHybridTable();

void InstallLinkedList(vtkRenderer* ren, const Options& opts, bool hybrid)
{
  vtkNew<vtkPenumbraLinkedListShadows> technique;
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetListCapacity(opts.Integer("capacity"));
  technique->SetListBuilder(opts.Choice("lists") == 1 ? vtkPenumbraLinkedListShadows::LISTS_GPU
                                                      : vtkPenumbraLinkedListShadows::LISTS_CPU);
  technique->SetHybrid(hybrid);
  if (hybrid)
  {
    technique->GetClassifier()->SetResolution(opts.Integer("classify_resolution"));
    technique->GetClassifier()->SetLayers(opts.Integer("classify_layers"));
  }
  InstallShadowPass(ren, technique);
}

const OptionTable ShadowMapOptions = {
  { "resolution", OptionType::Integer, 2048, 64, 8192, {}, "texels",
    "texels per side (per cube face or paraboloid hemisphere for point lights)" },
  { "filter", OptionType::Choice, "none", 0, 0, { "none", "pcf", "bilinear" }, "",
    "\"none\": the nearest texel, 0/1 like a hardware compare; \"pcf\": percentage-closer "
    "filtering, the mean of the compared taps (fractional visibility at shadow edges); "
    "\"bilinear\": Fast PCF (Brabec 2003, ch. 5), the 2 x 2 adjacent compared texels weighted "
    "bilinearly (a one-texel ramp at edges, four taps)" },
  { "pcf_kernel", OptionType::Integer, 3, 3, 9, { 3, 5, 7, 9 }, "texels",
    "odd kernel width of \"pcf\"" },
  { "bias", OptionType::Number, 1e-4, 0.0, 0.1, {}, "fraction of the depth range",
    "constant depth bias as a fraction of the light view's depth range (orthographic: the "
    "fitted receiver depth span; perspective/paraboloid: the farthest receiver's distance)" },
  { "slope_bias", OptionType::Number, 1.0, 0.0, 16.0, {}, "texel footprints",
    "slope-scaled bias in texel footprints (times 1 + the filter's reach: PCF radius, 1 for "
    "bilinear; the slope's tangent is capped "
    "at 1000)" },
  { "depth", OptionType::Choice, "linear", 0, 0, { "linear", "midpoint" }, "",
    "\"linear\": nearest surface; \"midpoint\": Woo's midpoint of the first two surfaces, one "
    "more depth-peeled pass per view" },
  { "point", OptionType::Choice, "cube", 0, 0, { "cube", "paraboloid" }, "",
    "point lights: \"cube\", six 90-degree faces (only those holding receivers are rendered), "
    "or \"paraboloid\", two dual-paraboloid hemispheres with exact per-sample projection" },
  { "fit_rectangle", OptionType::Choice, "axis", 0, 0, { "axis", "minimum", "square" }, "",
    "directional lights: the map's rectangle in the light plane, \"axis\" aligned with an "
    "arbitrary basis of the light direction (ch. 4.2.1), \"minimum\" the minimum-area "
    "rectangle around the hull of the receivers' tile boxes (Brabec 2003, ch. 4.2.2: fewer "
    "texels for the same density, but longer ones along one side of a square map), "
    "\"square\" the one whose longer side is shortest (the square map's coarser texel side)" },
  { "fit", OptionType::Choice, "auto", 0, 0, { "auto", "view", "scene" }, "",
    "what the maps cover: \"view\", the receivers the view samples see (densest, fitted and "
    "rendered again when the camera moves), \"scene\", every triangle of the scene as VTK's "
    "shadow pass fits (coarser, but kept while only the camera moves), or \"auto\", the scene "
    "while the camera sees all of it (the view would be as large) and the view otherwise; "
    "resm always fits the view" },
  { "lookup", OptionType::Choice, "gpu", 0, 0, { "gpu", "cpu", "gbuffer" }, "",
    "\"gpu\": compared on the GPU (a `texelFetch` of the depth and a test per tap), the maps "
    "never leave the GPU; lights with one "
    "map (directional, spot) are compared in the receivers' own shaders while they are shaded, "
    "as VTK's shadow pass does; \"cpu\": maps read back and compared in double precision with "
    "vtkSMPTools (same answers up to float rounding); \"gbuffer\": \"gpu\", always as a "
    "full-screen pass over the view samples (the same values, one pass more)" },
};

// Everything shadowmap and resm share but how big the maps are.
// The map options every shadow-map technique has (shadowmap, resm, pcss).
void ReadMapOptions(const Options& opts, vtkPenumbraShadowMapShadows* technique)
{
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetBias(opts.Number("bias"));
  technique->SetSlopeBias(opts.Number("slope_bias"));
  technique->SetDepthMode(opts.Choice("depth") == 1 ? vtkPenumbraShadowMapShadows::DEPTH_MIDPOINT
                                                    : vtkPenumbraShadowMapShadows::DEPTH_LINEAR);
  technique->SetPointMode(opts.Choice("point") == 1 ? vtkPenumbraShadowMapShadows::POINT_PARABOLOID
                                                    : vtkPenumbraShadowMapShadows::POINT_CUBE);
  const int fits[] = { vtkPenumbraShadowMapShadows::FIT_AXIS,
    vtkPenumbraShadowMapShadows::FIT_MINIMUM, vtkPenumbraShadowMapShadows::FIT_SQUARE };
  technique->SetFitRectangle(fits[opts.Choice("fit_rectangle")]);
}

// shadowmap's and resm's: the map options, the filter and where the lookup runs.
void ReadShadowMapOptions(const Options& opts, vtkPenumbraShadowMapShadows* technique)
{
  ReadMapOptions(opts, technique);
  const int filters[] = { vtkPenumbraShadowMapShadows::FILTER_NONE,
    vtkPenumbraShadowMapShadows::FILTER_PCF, vtkPenumbraShadowMapShadows::FILTER_BILINEAR };
  technique->SetFilter(filters[opts.Choice("filter")]);
  technique->SetPCFKernel(opts.Integer("pcf_kernel"));
  const int lookups[] = { vtkPenumbraShadowMapShadows::LOOKUP_GPU,
    vtkPenumbraShadowMapShadows::LOOKUP_CPU, vtkPenumbraShadowMapShadows::LOOKUP_GBUFFER };
  technique->SetLookup(lookups[opts.Choice("lookup")]);
  const int fits[] = { vtkPenumbraShadowMapShadows::FIT_TO_AUTO,
    vtkPenumbraShadowMapShadows::FIT_TO_VIEW, vtkPenumbraShadowMapShadows::FIT_TO_SCENE };
  technique->SetFitTo(fits[opts.Choice("fit")]);
}

void InstallShadowMap(vtkRenderer* ren, const Options& opts)
{
  vtkNew<vtkPenumbraShadowMapShadows> technique;
  ReadShadowMapOptions(opts, technique);
  InstallShadowPass(ren, technique);
}

// RESM: shadowmap's options (resolution then only sizes point lights' faces) and the
// estimate's.
OptionTable RESMTable()
{
  OptionTable table = ShadowMapOptions;
  table[0].Doc = "point lights only (not estimated): texels per cube face or paraboloid "
                 "hemisphere";
  table.push_back({ "max_resolution", OptionType::Integer, 4096, 64, 16384, {}, "texels",
    "largest map side the estimate may choose" });
  table.push_back({ "coverage", OptionType::Number, 0.99, 0.5, 1.0, {}, "",
    "share of the view's 4 x 4-sample tiles whose samples get the resolution they need (1: the "
    "largest need, which one grazing sample drives to max_resolution)" });
  table.push_back({ "analysis_step", OptionType::Integer, 2, 1, 4, {}, "samples",
    "the estimate analyses every n-th sample per axis (n^2 times less work)" });
  return table;
}
const OptionTable RESMOptions = RESMTable();

void InstallRESM(vtkRenderer* ren, const Options& opts)
{
  vtkNew<vtkPenumbraShadowMapShadows> technique;
  ReadShadowMapOptions(opts, technique);
  technique->SetResolutionMode(vtkPenumbraShadowMapShadows::RESOLUTION_ESTIMATED);
  technique->SetMaxResolution(opts.Integer("max_resolution"));
  technique->SetCoverage(opts.Number("coverage"));
  technique->SetAnalysisStep(opts.Integer("analysis_step"));
  InstallShadowPass(ren, technique);
}

// RMSM (Lefohn et al. 2007): the virtual map's size, the physical atlas, the cache and the
// bias.
const OptionTable RMSMOptions = {
  { "max_resolution", OptionType::Integer, 32768, 2048, 32768, { 2048, 4096, 8192, 16384, 32768 },
    "texels", "effective resolution of the finest level, texels per side of the virtual map" },
  { "atlas_size", OptionType::Integer, 4096, 512, 8192, { 512, 1024, 2048, 4096, 8192 }, "texels",
    "side of the physical page atlas ((atlas_size / 32)^2 pages of 32 x 32 texels; 4 bytes a "
    "texel: 64 MiB at 4096)" },
  { "filter", OptionType::Choice, "none", 0, 0, { "none", "bilinear" }, "",
    "\"none\": the nearest texel of the requested level, 0/1; \"bilinear\": 2 x 2 PCF at "
    "that level, the taps resolved through the page table and weighted bilinearly (the "
    "paper blends two levels; this uses one)" },
  { "footprint", OptionType::Choice, "area", 0, 0, { "width", "area" }, "",
    "how a sample's footprint in the map sets its level: \"area\", the paper's Eq. 1, texels "
    "as large as the square root of its area (coarser across slanted receivers; their shadow "
    "edges are refined); \"width\", texels as small as the footprint's smallest width (more "
    "pages)" },
  { "lod_bias", OptionType::Integer, 1, 0, 2, {}, "levels",
    "request levels this much finer than the one whose texel matches a sample's footprint "
    "(0: matched, rounded up; each level quadruples the pages)" },
  { "refine", OptionType::Integer, 3, 0, 4, {}, "levels",
    "levels finer at shadow edges: the samples whose 2 x 2 texels at their level disagree "
    "request the page this much finer once the requested pages are resident (0: off)" },
  { "analysis_step", OptionType::Integer, 2, 1, 2, {}, "samples",
    "the request pass computes the level of one sample per n x n block (2: four times fewer "
    "level computations; the block's samples request their own pages at that level, those "
    "on another surface add their own level and the block takes the finest)" },
  { "cached", OptionType::Boolean, true, 0, 0, {}, "",
    "keep the pages while the light, the casters and the settings are unchanged (only new "
    "requests are rendered); false rebuilds every frame" },
  { "bias", OptionType::Number, 1e-4, 0.0, 0.1, {}, "fraction of the depth range",
    "constant depth bias as a fraction of the virtual map's depth range" },
  { "slope_bias", OptionType::Number, 0.25, 0.0, 16.0, {}, "texel footprints",
    "slope-scaled bias in texel footprints of the level a sample is compared at, on top of the "
    "receiver plane (each texel is compared with the sample's tangent plane at its centre; the "
    "slope's "
    "tangent is capped at 1000)" },
};

void InstallRMSM(vtkRenderer* ren, const Options& opts)
{
  vtkNew<vtkPenumbraResolutionMatchedShadows> technique;
  technique->SetMaxResolution(opts.Integer("max_resolution"));
  technique->SetAtlasSize(opts.Integer("atlas_size"));
  technique->SetFilter(opts.Choice("filter") == 1
      ? vtkPenumbraResolutionMatchedShadows::FILTER_BILINEAR
      : vtkPenumbraResolutionMatchedShadows::FILTER_NONE);
  technique->SetFootprint(opts.Choice("footprint") == 1
      ? vtkPenumbraResolutionMatchedShadows::FOOTPRINT_AREA
      : vtkPenumbraResolutionMatchedShadows::FOOTPRINT_WIDTH);
  technique->SetLODBias(opts.Integer("lod_bias"));
  technique->SetRefineLevels(opts.Integer("refine"));
  technique->SetAnalysisStep(opts.Integer("analysis_step"));
  technique->SetCached(opts.Boolean("cached"));
  technique->SetBias(opts.Number("bias"));
  technique->SetSlopeBias(opts.Number("slope_bias"));
  InstallShadowPass(ren, technique);
}

// PCSS: shadowmap's map options (no filter: the soft lookup is the filter) and the soft
// lookup's taps and reach (Fernando 2005).
OptionTable PCSSTable()
{
  OptionTable table;
  for (const OptionSpec& spec : ShadowMapOptions)
  {
    const std::string name = spec.Name;
    if (name != "filter" && name != "pcf_kernel" && name != "lookup")
    {
      table.push_back(spec);
    }
  }
  table.push_back({ "search_taps", OptionType::Integer, 4, 1, 16, {}, "taps per light axis",
    "blocker-search taps on a stratified grid over the light (n x n for a rectangle, 2 n for a "
    "line)" });
  table.push_back({ "filter_taps", OptionType::Integer, 6, 1, 32, {}, "taps per light axis",
    "PCF taps over the light's image at the blockers' depth (n x n for a rectangle, 2 n for a "
    "line): the number of visibility levels" });
  table.push_back({ "search_depth", OptionType::Number, 0.2, 0.01, 0.99, {},
    "fraction of the receiver's distance",
    "the nearest blocker the search looks for, as a fraction of the receiver's distance from "
    "the light (smaller: a wider search)" });
  table.push_back({ "max_radius", OptionType::Number, 64.0, 1.0, 4096.0, {}, "texels",
    "no tap lies farther from the sample (bounds the cost of huge lights)" });
  table.push_back({ "block", OptionType::Integer, 4, 1, 16, {}, "pixels",
    "adaptive sampling (Brabec 2003, ch. 11.3): search at the corners of block x block pixel "
    "blocks and interpolate where the four corners lie on the pixel's prop and share its hard "
    "shadow test; 1 searches at every pixel" });
  return table;
}
const OptionTable PCSSOptions = PCSSTable();

// Single-sample soft shadows (Brabec 2003, ch. 11): shadowmap's map options, the search box
// and the two ways of sizing the penumbra (the light's size, or the thesis's radii).
OptionTable SingleSampleTable()
{
  OptionTable table;
  for (const OptionSpec& spec : PCSSOptions)
  {
    const std::string name = spec.Name;
    if (name != "search_taps" && name != "filter_taps")
    {
      table.push_back(spec);
    }
  }
  table.push_back({ "search_taps", OptionType::Integer, 4, 1, 16, {}, "taps per half side",
    "the nearest-blocker / nearest-lit search scans a (2n + 1) x (2n + 1) box of texels around "
    "the sample (one tap per texel while the box is narrower, else spread evenly over it)" });
  table.push_back({ "physical", OptionType::Boolean, true, 0, 0, {}, "",
    "true: every penumbra from the light's own size (similar triangles through the blocker "
    "texel found, no calibration); false: the thesis's radii r_scale, r_bias, r_shrink" });
  table.push_back({ "r_scale", OptionType::Number, 4.0, 0.0, 1e6, {}, "texels per unit length",
    "physical=false: search radius grows by this per unit of the receiver's distance from the "
    "light along its axis" });
  table.push_back({ "r_bias", OptionType::Number, 0.0, 0.0, 4096.0, {}, "texels",
    "physical=false: search radius at zero distance" });
  table.push_back({ "r_shrink", OptionType::Number, 1.0, 1e-9, 1e9, {}, "per unit length",
    "physical=false: at a blocker of depth d the radius becomes r_max r_shrink (w - d), w the "
    "receiver's depth (contact shadows sharpen)" });
  return table;
}
const OptionTable SingleSampleOptions = SingleSampleTable();

// The options pcss and single-sample-soft share: the map's, the search and the adaptive
// sampling.
void ReadSoftOptions(const Options& opts, vtkPenumbraShadowMapShadows* technique, int mode)
{
  ReadMapOptions(opts, technique);
  technique->SetAreaLightMode(mode);
  technique->SetSearchTaps(opts.Integer("search_taps"));
  technique->SetSearchDepth(opts.Number("search_depth"));
  technique->SetMaxRadius(opts.Number("max_radius"));
  technique->SetAdaptiveBlock(opts.Integer("block"));
}

void InstallSingleSample(vtkRenderer* ren, const Options& opts)
{
  vtkNew<vtkPenumbraShadowMapShadows> technique;
  ReadSoftOptions(opts, technique, vtkPenumbraShadowMapShadows::AREA_SINGLE_SAMPLE);
  technique->SetPhysical(opts.Boolean("physical"));
  technique->SetRScale(opts.Number("r_scale"));
  technique->SetRBias(opts.Number("r_bias"));
  technique->SetRShrink(opts.Number("r_shrink"));
  InstallShadowPass(ren, technique);
}

void InstallPCSS(vtkRenderer* ren, const Options& opts)
{
  vtkNew<vtkPenumbraShadowMapShadows> technique;
  ReadSoftOptions(opts, technique, vtkPenumbraShadowMapShadows::AREA_PCSS);
  technique->SetFilterTaps(opts.Integer("filter_taps"));
  InstallShadowPass(ren, technique);
}

// Soft shadow maps (Brabec 2003, ch. 10): the light samples, the maps and the skins'
// threshold; the bias as shadowmap's.
const OptionTable SoftShadowMapOptions = {
  { "samples", OptionType::Integer, 3, 2, 16, {}, "light samples",
    "linear lights: samples along the line, both endpoints included (2 shows the overlap "
    "artifact of ch. 10.1.2)" },
  { "grid", OptionType::Integer, 2, 2, 4, {}, "light samples per axis",
    "rectangular lights: a k x k grid whose outer samples are the corners (2: the 4 corners), "
    "split into elements (see elements)" },
  { "elements", OptionType::Choice, "cells", 0, 0, { "cells", "triangles" }, "",
    "rectangular lights: \"cells\", per grid cell the polygon of its lit corners and the "
    "skins' split points on its edges (Ying et al.'s variant, ch. 10.1.3); \"triangles\", two "
    "triangles per cell with per-vertex visibility channels (the thesis's own)" },
  { "resolution", OptionType::Integer, 1024, 64, 4096, {}, "texels",
    "texels per side of each light sample's depth map" },
  { "fit", OptionType::Choice, "scene", 0, 0, { "scene", "view" }, "",
    "what each light sample's map covers: \"scene\", the whole scene when it lies within 85 "
    "degrees of the axis from the light to it (maps and skins kept while only the camera "
    "moves; coarser texels when the view shows part of the scene), else as \"view\"; "
    "\"view\", the visible receivers (rebuilt whenever the view changes)" },
  { "threshold", OptionType::Number, 0.02, 0.001, 1.0, {}, "fraction of the depth",
    "depth discontinuity (skin) threshold: the 3 x 3 Laplacian and the jump across a 2 x 2 "
    "cell, relative to the depth from the light sample" },
  { "bias", OptionType::Number, 5e-4, 0.0, 0.1, {}, "fraction of the depth range",
    "constant depth bias of the shadow test and the skins' depth test (1e-4 leaves acne on "
    "city_area_light's roofs)" },
  { "slope_bias", OptionType::Number, 1.0, 0.0, 16.0, {}, "texel footprints",
    "slope-scaled bias: the receiver's depth change across this many texels at its angle to "
    "the light sample" },
  { "block", OptionType::Integer, 4, 1, 16, {}, "samples",
    "lookup block side: blocks whose corners agree on full light or umbra and whose samples "
    "lie on one plane take the corners' value; 1 looks up every sample" },
};

void InstallSoftShadowMap(vtkRenderer* ren, const Options& opts)
{
  vtkNew<vtkPenumbraSoftShadowMapShadows> technique;
  technique->SetNumberOfLineSamples(opts.Integer("samples"));
  technique->SetGridSamples(opts.Integer("grid"));
  technique->SetElements(opts.Choice("elements") == 1
      ? vtkPenumbraSoftShadowMapShadows::ELEMENTS_TRIANGLES
      : vtkPenumbraSoftShadowMapShadows::ELEMENTS_CELLS);
  technique->SetResolution(opts.Integer("resolution"));
  technique->SetFit(opts.Choice("fit") == 1 ? vtkPenumbraSoftShadowMapShadows::FIT_VIEW
                                            : vtkPenumbraSoftShadowMapShadows::FIT_SCENE);
  technique->SetThreshold(opts.Number("threshold"));
  technique->SetBias(opts.Number("bias"));
  technique->SetSlopeBias(opts.Number("slope_bias"));
  technique->SetBlock(opts.Integer("block"));
  InstallShadowPass(ren, technique);
}

const OptionTable VolumesOptions = {
  { "silhouettes", OptionType::Choice, "cpu", 0, 0, { "cpu", "gpu", "none" }, "",
    "\"cpu\": silhouette edges from OpenMesh half-edges, in double; \"gpu\": a geometry shader "
    "with triangle adjacency finds and extrudes them (Brabec 2003, ch. 9); \"none\": one volume "
    "per triangle for every caster, the brute-force baseline" },
  { "method", OptionType::Choice, "auto", 0, 0, { "auto", "zfail", "zpass" }, "",
    "\"auto\": z-pass when the camera provably lies outside every volume, else z-fail; "
    "\"zfail\": always (caps and depth clamp make it correct with the camera inside a volume); "
    "\"zpass\": always, wrong where the camera is inside a volume (for comparison only)" },
  { "cull", OptionType::Boolean, true, 0, 0, {}, "",
    "skip casters whose volumes cannot reach the box of the light-facing samples" },
  { "cap_offset", OptionType::Number, 1.0 / 131072.0, 0.0, 1e-3, {}, "fraction of eye depth",
    "how far light caps are pushed back (default 2^-17), so that a sample never counts its own "
    "caster surface" },
  { "resolve", OptionType::Boolean, true, 0, 0, {}, "",
    "ray trace the samples next to a change of the stencil result, next to background or "
    "facing-away samples, and those the light grazes (cosine below 1e-3); false gives the pure "
    "stencil answer" },
  { "measure_fill", OptionType::Boolean, false, 0, 0, {}, "",
    "draw the volumes once more without depth test to count their fragments (the bench's fill "
    "column)" },
  { "lights_per_mask", OptionType::Integer, 4, 1, 4, {}, "lights",
    "lights counted into one RGBA mask before it is read back (Brabec 2003, ch. 8); only speed "
    "depends on it" },
};

void InstallVolumes(vtkRenderer* ren, const Options& opts)
{
  const int silhouettes = opts.Choice("silhouettes");
  const int method = opts.Choice("method");
  vtkNew<vtkPenumbraShadowVolumeShadows> technique;
  technique->SetSilhouettes(silhouettes != 2);
  technique->SetGPUSilhouettes(silhouettes == 1);
  technique->SetMethod(method == 1 ? vtkPenumbraShadowVolumeShadows::METHOD_ZFAIL
      : method == 2                ? vtkPenumbraShadowVolumeShadows::METHOD_ZPASS
                                   : vtkPenumbraShadowVolumeShadows::METHOD_AUTO);
  technique->SetCull(opts.Boolean("cull"));
  technique->SetCapOffset(opts.Number("cap_offset"));
  technique->SetResolve(opts.Boolean("resolve"));
  technique->SetMeasureFill(opts.Boolean("measure_fill"));
  technique->SetLightsPerMask(opts.Integer("lights_per_mask"));
  InstallShadowPass(ren, technique);
}

const OptionTable GearsOptions = {
  SamplesOption,
  { "grid", OptionType::Integer, 128, 1, 4096, {}, "cells per side",
    "grid cells per side over the projected view samples; only speed depends on it" },
  { "camera_distance", OptionType::Number, 1.0, 0.01, 100.0, {}, "light diagonals",
    "distance of the grid camera behind the light centre; only the tightness of the blocker "
    "lists depends on it" },
  { "trace_threshold", OptionType::Number, 0.5, 0.0, 1e6, {}, "triangles per light sample",
    "a cell whose blocker list is longer than this times k^2 has its samples ray traced whole "
    "instead of masked; 0 masks every cell, as the compute path always does; only speed "
    "depends on it" },
  { "dense", OptionType::Choice, "trace", 0, 0, { "trace", "tree" }, "",
    "the samples of a cell above trace_threshold: \"trace\" ray traces them whole, \"tree\" "
    "masks them from a walk of a bounding volume hierarchy over the casters that skips nodes "
    "whose light samples are blocked already (measured slower on llvmpipe's 2 cores); only "
    "speed depends on it" },
  { "path", OptionType::Choice, "auto", 0, 0, { "auto", "cpu", "gpu" }, "",
    "where the per-sample masks are built: \"auto\" (the path measured faster, the CPU on Mesa "
    "llvmpipe), \"cpu\" (vtkSMPTools) or \"gpu\" (a GL 4.3 compute shader, k <= 32); the same "
    "visibility bit for bit, and the CPU answers where the compute path cannot run" },
};

void InstallGears(vtkRenderer* ren, const Options& opts)
{
  const int path = opts.Choice("path");
  vtkNew<vtkPenumbraGearsShadows> technique;
  technique->SetPath(path == 2 ? vtkPenumbraGearsShadows::PATH_GPU
      : path == 1              ? vtkPenumbraGearsShadows::PATH_CPU
                               : vtkPenumbraGearsShadows::PATH_AUTO);
  technique->SetSamplesPerAxis(opts.Integer("samples"));
  technique->SetGridResolution(opts.Integer("grid"));
  technique->SetCameraDistanceFactor(opts.Number("camera_distance"));
  technique->SetTraceThreshold(opts.Number("trace_threshold"));
  technique->SetDenseCells(opts.Choice("dense") == 1 ? vtkPenumbraGearsShadows::DENSE_TREE
                                                     : vtkPenumbraGearsShadows::DENSE_TRACE);
  InstallShadowPass(ren, technique);
}

// Per light, the technique the measurements favour (vtkPenumbraAutoShadows says which and
// why, citing docs/benchmarks.md and docs/gears.md).
const OptionTable AutoOptions = {
  { "quality", OptionType::Choice, "balanced", 0, 0, { "balanced", "exact", "fast" }, "",
    "\"balanced\" and \"exact\": the exact technique measured fastest for each light; "
    "\"fast\": area and linear lights at 4 x 4 light samples" },
  SamplesOption,
};

void InstallAuto(vtkRenderer* ren, const Options& opts)
{
  const int quality = opts.Choice("quality");
  vtkNew<vtkPenumbraAutoShadows> technique;
  technique->SetQuality(quality == 1 ? vtkPenumbraAutoShadows::QUALITY_EXACT
      : quality == 2                 ? vtkPenumbraAutoShadows::QUALITY_FAST
                                     : vtkPenumbraAutoShadows::QUALITY_BALANCED);
  technique->SetSamplesPerAxis(opts.Integer("samples"));
  InstallShadowPass(ren, technique);
}

// The descriptions cite the papers by short name:
// - Hertel et al. 2009: Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for
//   Alias-Free Hard Shadows", Eurographics 2009 Areas Papers;
// - Brabec 2003: Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD
//   thesis, 2003;
// - Ferko 2013: Ferko, resolution-estimation shadow mapping (RESM), in the alias-free shadow
//   mapping work of his doctoral thesis (Comenius University Bratislava);
// - Ferko 2014: Ferko, linked-list shadow maps (LLSM), the irregular z-buffer of Johnson et al.
//   2005 built with per-texel linked lists, in the same thesis;
// - Lefohn et al. 2007: Lefohn, Sengupta, Owens, "Resolution-Matched Shadow Maps", ACM TOG
//   26(4), 2007;
// - Wang et al. 2014: Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for
//   Rendering Shadows", Computer Graphics Forum 33(6), 2014.
const std::vector<Technique>& Registry()
{
  static const std::vector<Technique> techniques = {
    { "none", "plain VTK rendering without shadows", {}, InstallNone },
    { "auto",
      "per light, the technique measured best for it: raytraced for hard lights, gears for area "
      "and linear lights (exact); quality=fast uses 4 x 4 light samples",
      AutoOptions, InstallAuto },
    { "vtk-shadowmap",
      "VTK's vtkShadowMapPass (exponential shadow map; directional lights and spot lights under "
      "90 degrees, opaque props only; peer for comparison)",
      VTKShadowMapOptions, InstallVTKShadowMap },
    { "raytraced",
      "exact shadows from every light type, ray traced on the CPU (Embree) for every view sample "
      "and light sample",
      RayTracedOptions,
      [](vtkRenderer* ren, const Options& opts) { InstallRayTraced(ren, opts, false); } },
    { "adaptive-soft",
      "approximate soft shadows for area and linear lights: the exact rays of raytraced at a "
      "lattice of view samples, blocks whose corners predict their centre interpolated, the "
      "others split down to 2 pixels (the adaptive sampling of Brabec 2003, ch. 11.3); hard "
      "lights exact",
      AdaptiveSoftOptions,
      [](vtkRenderer* ren, const Options& opts) { InstallRayTraced(ren, opts, true); } },
    { "conservative",
      "exact hard shadows from point, spot and directional lights: a conservative shadow map "
      "classifies the samples as lit, shadowed or uncertain, CPU rays resolve the uncertain ones "
      "(Hertel et al. 2009)",
      ConservativeOptions, InstallConservative },
    { "llsm",
      "exact hard shadows without rays where they can be decided: linked-list shadow maps "
      "(Ferko 2014), per light-view texel a list of the view samples, every caster rasterized "
      "conservatively and tested exactly against the samples of the texels it covers; CPU rays "
      "only for undecidable ones; point, spot and directional lights",
      LinkedListOptions,
      [](vtkRenderer* ren, const Options& opts) { InstallLinkedList(ren, opts, false); } },
    { "llsm-hybrid",
      "llsm for the hard samples only: a conservative shadow map (Hertel et al. 2009) decides "
      "the easy ones, the lists the rest (the hybrid LLSM of Ferko's thesis, with an exact "
      "classifier)",
      LinkedListHybridOptions,
      [](vtkRenderer* ren, const Options& opts) { InstallLinkedList(ren, opts, true); } },
    { "shadowmap",
      "practical shadow maps (Brabec 2003, ch. 4-6): linear 32-bit float depth fitted to the "
      "visible receivers with depth clamping, PCF, Woo's midpoint depth, cube or dual-paraboloid "
      "maps for point lights; point, spot and directional lights",
      ShadowMapOptions, InstallShadowMap },
    { "resm",
      "shadow maps at the resolution the view samples need (RESM, Ferko 2013): the tight fit of "
      "shadowmap, per light and axis the size at which a texel covers at most a pixel, up to "
      "max_resolution; directional and spot lights (point lights: shadowmap's fixed size)",
      RESMOptions, InstallRESM },
    { "rmsm",
      "resolution-matched shadow maps (Lefohn et al. 2007): per view sample the level of a "
      "virtual map up to max_resolution^2 whose texel matches the sample's footprint, only the "
      "requested 32 x 32 pages rendered (by superpage) into a page atlas, kept while the light "
      "and casters stay put; directional and spot lights (up to 60 degrees)",
      RMSMOptions, InstallRMSM },
    { "volumes",
      "exact hard shadows with stencil shadow volumes (Brabec 2003, ch. 3, 8, 9): OpenMesh "
      "silhouettes for closed meshes, per-triangle volumes otherwise, z-fail with caps and "
      "depth clamp, four lights per RGBA mask; point, spot and directional lights",
      VolumesOptions, InstallVolumes },
    { "gears",
      "exact soft shadows from area and linear lights (GEARS, Wang et al. 2014): per-cell lists of "
      "potential blockers, k x k light-sample masks built on the CPU or by a compute shader; "
      "other lights are ray traced",
      GearsOptions, InstallGears },
    { "pcss",
      "percentage-closer soft shadows (Fernando 2005) from area and linear lights: one "
      "perspective map from the light's centre, a blocker search and a PCF kernel shaped like "
      "the light's image in the map; other lights get shadowmap's hard shadows",
      PCSSOptions, InstallPCSS },
    { "single-sample-soft",
      "single-sample soft shadows (Brabec 2003, ch. 11) from area and linear lights: one "
      "perspective map from the light's centre, the nearest blocker (outer penumbra) or nearest "
      "lit texel (inner penumbra) in a box around each sample; other lights get shadowmap's hard "
      "shadows",
      SingleSampleOptions, InstallSingleSample },
    { "soft-shadowmap",
      "soft shadow maps (Brabec 2003, ch. 10) from area and linear lights: a depth map per light "
      "sample (line: endpoints and interior samples; rectangle: corner grid), skins across "
      "depth discontinuities warped into the neighbouring samples' maps as visibility channels; "
      "other lights get shadowmap's hard shadows",
      SoftShadowMapOptions, InstallSoftShadowMap },
  };
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
    "<!-- Generated by `penumbra-render --options-markdown` from the option tables in\n"
    "     Modules/Techniques/vtkPenumbraTechniques.cxx: edit those, then regenerate. -->\n";
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
