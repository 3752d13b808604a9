#include "vtkPenumbraTechniques.h"

#include "vtkCameraPass.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAutoShadows.h"
#include "vtkPenumbraConservativeShadows.h"
#include "vtkPenumbraGearsShadows.h"
#include "vtkPenumbraRayTracedShadows.h"
#include "vtkPenumbraShadowMapShadows.h"
#include "vtkPenumbraShadowPass.h"
#include "vtkPenumbraShadowVolumeShadows.h"
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

// Reads the options a technique knows and rejects the rest, so a typo never silently falls
// back to a default.
class Options
{
public:
  explicit Options(const json& j)
    : J(j)
  {
  }

  int Integer(const char* key, int def, int lo, int hi)
  {
    this->Known.emplace_back(key);
    if (!this->J.contains(key))
    {
      return def;
    }
    const json& v = this->J.at(key);
    if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi)
    {
      throw OptionError(std::string(key) + ": expected an integer in [" + std::to_string(lo) +
        ", " + std::to_string(hi) + "], got " + v.dump());
    }
    return static_cast<int>(v.get<long long>());
  }

  double Number(const char* key, double def, double lo, double hi)
  {
    this->Known.emplace_back(key);
    if (!this->J.contains(key))
    {
      return def;
    }
    const json& v = this->J.at(key);
    if (!v.is_number() || !(v.get<double>() >= lo) || !(v.get<double>() <= hi))
    {
      throw OptionError(std::string(key) + ": expected a number in [" + json(lo).dump() + ", " +
        json(hi).dump() + "], got " + v.dump());
    }
    return v.get<double>();
  }

  bool Boolean(const char* key, bool def)
  {
    this->Known.emplace_back(key);
    if (!this->J.contains(key))
    {
      return def;
    }
    const json& v = this->J.at(key);
    if (!v.is_boolean())
    {
      throw OptionError(std::string(key) + ": expected true or false, got " + v.dump());
    }
    return v.get<bool>();
  }

  // One of `choices` (index returned); the first choice is the default.
  int Choice(const char* key, const std::vector<std::string>& choices)
  {
    this->Known.emplace_back(key);
    if (!this->J.contains(key))
    {
      return 0;
    }
    const json& v = this->J.at(key);
    for (size_t i = 0; v.is_string() && i < choices.size(); ++i)
    {
      if (v.get<std::string>() == choices[i])
      {
        return static_cast<int>(i);
      }
    }
    std::string allowed;
    for (const auto& c : choices)
    {
      allowed += (allowed.empty() ? "\"" : ", \"") + c + "\"";
    }
    throw OptionError(std::string(key) + ": expected one of " + allowed + ", got " + v.dump());
  }

  void RejectUnknown() const
  {
    for (auto it = this->J.begin(); it != this->J.end(); ++it)
    {
      bool known = false;
      for (const auto& k : this->Known)
      {
        known = known || k == it.key();
      }
      if (!known)
      {
        std::string allowed;
        for (const auto& k : this->Known)
        {
          allowed += (allowed.empty() ? "" : ", ") + k;
        }
        throw OptionError(it.key() + ": unknown option" +
          (allowed.empty() ? std::string(" (this technique has none)")
                           : " (allowed: " + allowed + ")"));
      }
    }
  }

private:
  const json& J;
  std::vector<std::string> Known;
};

// A pass dropped while it still holds GL objects leaks them (VTK's shadow baker even reports
// it as an error), so the outgoing pass releases its resources first.
void InstallPass(vtkRenderer* ren, vtkRenderPass* pass)
{
  vtkRenderPass* old = ren->GetPass();
  if (old && old != pass && ren->GetRenderWindow())
  {
    old->ReleaseGraphicsResources(ren->GetRenderWindow());
  }
  ren->SetPass(pass);
}

// The Penumbra composition every technique of ours uses: camera pass -> shadow pass.
void InstallShadowPass(vtkRenderer* ren, vtkPenumbraShadowTechnique* technique)
{
  vtkNew<vtkPenumbraShadowPass> shadows;
  shadows->SetTechnique(technique);
  vtkNew<vtkCameraPass> camera;
  camera->SetDelegatePass(shadows);
  InstallPass(ren, camera);
}

struct Technique
{
  const char* Name;
  const char* Description;
  std::function<void(vtkRenderer*, Options&)> Install;
};

void InstallNone(vtkRenderer* ren, Options& opts)
{
  opts.RejectUnknown();
  InstallPass(ren, nullptr);
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
        vtkWarningMacro("Light " << index << " gets no shadow from vtk-shadowmap: VTK's "
                        "vtkShadowMapPass shadows only directional lights and spot lights with a "
                        "cone under 90 degrees (not point, area, linear or head lights); use "
                        "auto, shadowmap or raytraced to shadow it");
      }
      ++index;
    }
    this->Superclass::Render(s);
  }

private:
  std::set<vtkLight*> Told;
};
vtkStandardNewMacro(CheckedShadowMapPass);

void InstallVTKShadowMap(vtkRenderer* ren, Options& opts)
{
  const int resolution = opts.Integer("resolution", 1024, 16, 16384);
  opts.RejectUnknown();
  // The composition of VTK's own TestShadowMapPass: bake the maps, then shade with them.
  vtkNew<CheckedShadowMapPass> shadows;
  shadows->GetShadowMapBakerPass()->SetResolution(resolution);
  vtkNew<vtkRenderPassCollection> passes;
  passes->AddItem(shadows->GetShadowMapBakerPass());
  passes->AddItem(shadows);
  vtkNew<vtkSequencePass> sequence;
  sequence->SetPasses(passes);
  vtkNew<vtkCameraPass> camera;
  camera->SetDelegatePass(sequence);
  InstallPass(ren, camera);
}

// Light samples per axis for area/linear lights: 0 keeps the light's own k; otherwise one of
// the values Wang et al. 2014 measure, so GEARS and the ray tracer can be compared at equal k.
int SamplesOption(Options& opts)
{
  const int k = opts.Integer("samples", 0, 0, 32);
  if (k != 0 && k != 4 && k != 8 && k != 16 && k != 32)
  {
    throw OptionError("samples: expected 0 (the light's own) or one of 4, 8, 16, 32, got " +
      std::to_string(k));
  }
  return k;
}

void InstallRayTraced(vtkRenderer* ren, Options& opts)
{
  const int samples = SamplesOption(opts);
  opts.RejectUnknown();
  vtkNew<vtkPenumbraRayTracedShadows> technique;
  technique->SetSamplesPerAxis(samples);
  InstallShadowPass(ren, technique);
}

void InstallConservative(vtkRenderer* ren, Options& opts)
{
  const int resolution = opts.Integer("resolution", 1024, 64, 8192);
  const int layers = opts.Integer("layers", 2, 2, 4);
  const int map = opts.Choice("map", { "cpu", "gpu" });
  opts.RejectUnknown();
  vtkNew<vtkPenumbraConservativeShadows> technique;
  technique->SetResolution(resolution);
  technique->SetLayers(layers);
  technique->SetMapBuilder(map == 1 ? vtkPenumbraConservativeShadows::MAP_GPU
                                    : vtkPenumbraConservativeShadows::MAP_CPU);
  InstallShadowPass(ren, technique);
}

void InstallShadowMap(vtkRenderer* ren, Options& opts)
{
  const int resolution = opts.Integer("resolution", 2048, 64, 8192);
  const int filter = opts.Choice("filter", { "none", "pcf" });
  const int kernel = opts.Integer("pcf_kernel", 3, 3, 9);
  if (kernel % 2 == 0)
  {
    throw OptionError("pcf_kernel: expected an odd integer in [3, 9], got " + std::to_string(kernel));
  }
  const double bias = opts.Number("bias", 1e-4, 0.0, 0.1);
  const double slopeBias = opts.Number("slope_bias", 1.0, 0.0, 16.0);
  const int depth = opts.Choice("depth", { "linear", "midpoint" });
  const int point = opts.Choice("point", { "cube", "paraboloid" });
  const int lookup = opts.Choice("lookup", { "gpu", "cpu" });
  opts.RejectUnknown();
  vtkNew<vtkPenumbraShadowMapShadows> technique;
  technique->SetResolution(resolution);
  technique->SetFilter(filter == 1 ? vtkPenumbraShadowMapShadows::FILTER_PCF
                                   : vtkPenumbraShadowMapShadows::FILTER_NONE);
  technique->SetPCFKernel(kernel);
  technique->SetBias(bias);
  technique->SetSlopeBias(slopeBias);
  technique->SetDepthMode(depth == 1 ? vtkPenumbraShadowMapShadows::DEPTH_MIDPOINT
                                     : vtkPenumbraShadowMapShadows::DEPTH_LINEAR);
  technique->SetPointMode(point == 1 ? vtkPenumbraShadowMapShadows::POINT_PARABOLOID
                                     : vtkPenumbraShadowMapShadows::POINT_CUBE);
  technique->SetLookup(lookup == 1 ? vtkPenumbraShadowMapShadows::LOOKUP_CPU
                                   : vtkPenumbraShadowMapShadows::LOOKUP_GPU);
  InstallShadowPass(ren, technique);
}

void InstallVolumes(vtkRenderer* ren, Options& opts)
{
  const int silhouettes = opts.Choice("silhouettes", { "cpu", "gpu", "none" });
  const int method = opts.Choice("method", { "auto", "zfail", "zpass" });
  const bool cull = opts.Boolean("cull", true);
  const double capOffset = opts.Number("cap_offset", 1.0 / 131072.0, 0.0, 1e-3);
  const bool resolve = opts.Boolean("resolve", true);
  const bool measureFill = opts.Boolean("measure_fill", false);
  const int lightsPerMask = opts.Integer("lights_per_mask", 4, 1, 4);
  opts.RejectUnknown();
  vtkNew<vtkPenumbraShadowVolumeShadows> technique;
  technique->SetSilhouettes(silhouettes != 2);
  technique->SetGPUSilhouettes(silhouettes == 1);
  technique->SetMethod(method == 1 ? vtkPenumbraShadowVolumeShadows::METHOD_ZFAIL
      : method == 2                ? vtkPenumbraShadowVolumeShadows::METHOD_ZPASS
                                   : vtkPenumbraShadowVolumeShadows::METHOD_AUTO);
  technique->SetCull(cull);
  technique->SetCapOffset(capOffset);
  technique->SetResolve(resolve);
  technique->SetMeasureFill(measureFill);
  technique->SetLightsPerMask(lightsPerMask);
  InstallShadowPass(ren, technique);
}

void InstallGears(vtkRenderer* ren, Options& opts)
{
  const int samples = SamplesOption(opts);
  const int grid = opts.Integer("grid", 128, 1, 4096);
  const double cameraDistance = opts.Number("camera_distance", 1.0, 0.01, 100.0);
  const double traceThreshold = opts.Number("trace_threshold", 0.5, 0.0, 1e6);
  const int path = opts.Choice("path", { "auto", "cpu", "gpu" });
  opts.RejectUnknown();
  vtkNew<vtkPenumbraGearsShadows> technique;
  technique->SetPath(path == 2 ? vtkPenumbraGearsShadows::PATH_GPU
      : path == 1              ? vtkPenumbraGearsShadows::PATH_CPU
                               : vtkPenumbraGearsShadows::PATH_AUTO);
  technique->SetSamplesPerAxis(samples);
  technique->SetGridResolution(grid);
  technique->SetCameraDistanceFactor(cameraDistance);
  technique->SetTraceThreshold(traceThreshold);
  InstallShadowPass(ren, technique);
}

// Per light, the technique the measurements favour (vtkPenumbraAutoShadows says which and
// why, citing docs/benchmarks.md and docs/gears.md).
void InstallAuto(vtkRenderer* ren, Options& opts)
{
  const int quality = opts.Choice("quality", { "balanced", "exact", "fast" });
  const int samples = SamplesOption(opts);
  opts.RejectUnknown();
  vtkNew<vtkPenumbraAutoShadows> technique;
  technique->SetQuality(quality == 1 ? vtkPenumbraAutoShadows::QUALITY_EXACT
      : quality == 2                 ? vtkPenumbraAutoShadows::QUALITY_FAST
                                     : vtkPenumbraAutoShadows::QUALITY_BALANCED);
  technique->SetSamplesPerAxis(samples);
  InstallShadowPass(ren, technique);
}

// The descriptions cite the papers by short name:
// - Hertel et al. 2009: Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for
//   Alias-Free Hard Shadows", Eurographics 2009 Areas Papers;
// - Brabec 2003: Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD
//   thesis, 2003;
// - Wang et al. 2014: Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for
//   Rendering Shadows", Computer Graphics Forum 33(6), 2014.
const std::vector<Technique>& Registry()
{
  static const std::vector<Technique> techniques = {
    { "none", "plain VTK rendering without shadows", InstallNone },
    { "auto",
      "per light, the technique measured best for it: raytraced for hard lights, gears for area "
      "and linear lights (exact); quality=fast uses 4 x 4 light samples",
      InstallAuto },
    { "vtk-shadowmap", "VTK's vtkShadowMapPass (exponential shadow map; peer for comparison)",
      InstallVTKShadowMap },
    { "raytraced", "exact shadows ray traced on the CPU for every view sample (Embree reference)",
      InstallRayTraced },
    { "conservative",
      "exact hard shadows: conservative shadow map classifies, CPU rays resolve the uncertain "
      "samples (Hertel et al. 2009)",
      InstallConservative },
    { "shadowmap",
      "practical shadow maps (Brabec 2003): linear depth, fitted to the visible receivers, PCF, "
      "cube or dual-paraboloid maps for point lights",
      InstallShadowMap },
    { "volumes",
      "exact hard shadows with stencil shadow volumes (Brabec 2003, ch. 3, 8, 9): OpenMesh "
      "silhouettes for closed meshes, per-triangle volumes otherwise, z-fail with caps and "
      "depth clamp, four lights per RGBA mask",
      InstallVolumes },
    { "gears",
      "exact soft shadows from area and linear lights (GEARS, Wang et al. 2014): per-cell lists of "
      "potential blockers, k x k light-sample masks on the CPU",
      InstallGears },
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

vtkStandardNewMacro(vtkPenumbraTechniques);

int vtkPenumbraTechniques::GetNumberOfTechniques()
{
  return static_cast<int>(Registry().size());
}

const char* vtkPenumbraTechniques::GetTechniqueName(int index)
{
  return (index >= 0 && index < GetNumberOfTechniques()) ? Registry()[static_cast<size_t>(index)].Name
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
    Options opts(parsed);
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
