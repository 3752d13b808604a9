#include "vtkPenumbraShadowPassInternals.h"

#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPenumbraShadowReach.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkRenderer.h"
#include "vtk_glew.h"

#include <algorithm>
#include <limits>
#include <sstream>

namespace
{
// Why `light` needs no shadow work for any of `samples`, or "" when some valid sample may be
// lit by it. The rules are the exact reference's (vtkPenumbraReference): a sample whose
// normal faces away from the light (N.L <= 0; for an area or linear light, from every point
// of the emitter, tested at its corners, which bound the light samples) and a sample outside
// a spot light's cone get visibility 0 without a ray, and VTK's own shading gives them no
// light from it either, so when that holds for every visible sample nothing needs shadowing.
// Whether the ray from p towards a directional light (`toLight`, `toPoint` null) or the
// segment from p to a positional light `toPoint` meets the box (slab test).
bool RayMeetsBox(
  const double p[3], const double toLight[3], const double* toPoint, const double box[6])
{
  const double d[3] = { toPoint ? toPoint[0] - p[0] : toLight[0],
    toPoint ? toPoint[1] - p[1] : toLight[1], toPoint ? toPoint[2] - p[2] : toLight[2] };
  return penumbra_reach::SegmentMeetsBox(
    p, d, toPoint ? 1.0 : std::numeric_limits<double>::infinity(), box);
}

// Why a light needs no shadow work this frame, or "" when it may shadow a visible sample:
// no visible surface, every visible sample faces away or lies outside the cone, or (hard
// lights) no visible sample's ray to the light meets the casters' box (world coordinates,
// padded; null: no casters at all). `witness`: a sample found shadowable by an earlier call
// (tested first; -1 when none), set to the one found now.
std::string NothingToShadow(vtkLight* light, vtkPenumbraViewSamples* samples,
  const double* casterBox, const double* sampleBox, vtkIdType& witness)
{
  double pos[3], focal[3];
  light->GetTransformedPosition(pos);
  light->GetTransformedFocalPoint(focal);
  double axis[3] = { focal[0] - pos[0], focal[1] - pos[1], focal[2] - pos[2] };
  const double axisLength = vtkMath::Normalize(axis);
  // Positional emitter points: an area light's corners (a disc's bounding square), which
  // enclose every light sample, or a point light's position; none for a directional light.
  std::vector<std::array<double, 3>> points;
  auto* area = vtkPenumbraAreaLight::SafeDownCast(light);
  penumbra_reach::LightReach reach;
  std::string unusable; // the technique reports it
  if (penumbra_reach::DescribeLight(light, reach, unusable))
  {
    for (size_t k = 0; k + 2 < reach.Points.size(); k += 3)
    {
      points.push_back({ reach.Points[k], reach.Points[k + 1], reach.Points[k + 2] });
    }
  }
  const bool spot =
    !area && light->GetPositional() && light->GetConeAngle() < 90.0 && axisLength > 0;
  const double cosCone = std::cos(vtkMath::RadiansFromDegrees(light->GetConeAngle()));
  // A directional light shines along the axis from the position toward the focal point.
  const double toLight[3] = { -axis[0], -axis[1], -axis[2] };
  const float* normals = samples->GetNormals()->GetPointer(0);
  bool anyValid = false, anyInCone = false, anyLit = false;
  // Hard lights: a lit sample matters only if its ray to the light can meet a caster.
  const bool hard = points.size() <= 1;
  if (hard && casterBox && sampleBox)
  {
    // All the visible samples' rays at once: for a directional light, p + t L meets the
    // casters' box C for some p in the samples' box S iff t L meets C - S (a box); for a
    // positional light every segment lies in the box around S and the light.
    double box[6];
    for (int a = 0; a < 3; ++a)
    {
      box[2 * a] = points.empty() ? casterBox[2 * a] - sampleBox[2 * a + 1]
                                  : std::min(sampleBox[2 * a], points[0][a]);
      box[2 * a + 1] = points.empty() ? casterBox[2 * a + 1] - sampleBox[2 * a]
                                      : std::max(sampleBox[2 * a + 1], points[0][a]);
    }
    const double zero[3] = { 0, 0, 0 };
    const bool apart = points.empty()
      ? !RayMeetsBox(zero, toLight, nullptr, box)
      : (box[0] > casterBox[1] || box[1] < casterBox[0] || box[2] > casterBox[3] ||
          box[3] < casterBox[2] || box[4] > casterBox[5] || box[5] < casterBox[4]);
    if (apart)
    {
      return "no caster lies between it and any visible surface";
    }
  }
  auto mayBeShadowed = [&](const double p[3])
  {
    anyLit = true;
    return hard && casterBox &&
      RayMeetsBox(p, toLight, points.empty() ? nullptr : points[0].data(), casterBox);
  };
  // The arrays read directly (this scan runs per light and frame), as far as all are long.
  const int* props = samples->GetPropIndices()->GetPointer(0);
  const float* positions = samples->GetPositions()->GetPointer(0);
  double origin[3];
  samples->GetOrigin(origin);
  const vtkIdType count =
    std::min({ samples->GetNumberOfSamples(), samples->GetPropIndices()->GetNumberOfTuples(),
      samples->GetPositions()->GetNumberOfTuples(), samples->GetNormals()->GetNumberOfTuples() });
  // Whether sample i may be shadowed by the light (it is a witness that the light needs
  // shadow work).
  auto shadowable = [&](vtkIdType i)
  {
    if (props[i] < 0)
    {
      return false;
    }
    const double p[3] = { positions[3 * i] + origin[0], positions[3 * i + 1] + origin[1],
      positions[3 * i + 2] + origin[2] };
    anyValid = true;
    const float* nrm = normals + 3 * i;
    if (points.empty())
    {
      return nrm[0] * toLight[0] + nrm[1] * toLight[1] + nrm[2] * toLight[2] > 0.0 &&
        mayBeShadowed(p);
    }
    if (spot)
    {
      double d[3] = { p[0] - pos[0], p[1] - pos[1], p[2] - pos[2] };
      const double len = vtkMath::Norm(d);
      if (len > 0 && vtkMath::Dot(d, axis) < cosCone * len)
      {
        return false; // outside the cone
      }
      anyInCone = true;
    }
    for (const auto& q : points)
    {
      if (nrm[0] * (q[0] - p[0]) + nrm[1] * (q[1] - p[1]) + nrm[2] * (q[2] - p[2]) > 0.0)
      {
        return !hard || mayBeShadowed(p);
      }
    }
    return false;
  };
  // The last frame's witness first: one sample that may be shadowed is the whole answer,
  // and in a still or slowly changing frame it still is one; else the scan, which visits
  // every sample up to the first witness and so costs most where that comes late in pixel
  // order.
  if (witness >= 0 && witness < count && shadowable(witness))
  {
    return "";
  }
  for (vtkIdType i = 0; i < count; ++i)
  {
    if (shadowable(i))
    {
      witness = i;
      return "";
    }
  }
  witness = -1;
  if (!anyValid)
  {
    return "no surface is visible";
  }
  if (anyLit)
  {
    return casterBox ? "no caster lies between it and any visible sample it lights"
                     : "nothing casts shadows";
  }
  return spot && !anyInCone ? "every visible sample lies outside its cone"
                            : "every visible sample faces away from it";
}

}

using namespace penumbra_shadow_pass;

void vtkPenumbraShadowPass::Internals::CollectLights(vtkPenumbraShadowPass* pass, vtkRenderer* ren)
{
  this->Lights.clear();
  this->LightsOff = 0;
  std::map<vtkLight*, Standin> kept; // stand-ins of this frame's lights only
  vtkLightCollection* lights = ren->GetLights();
  vtkCollectionSimpleIterator it;
  lights->InitTraversal(it);
  while (vtkLight* light = lights->GetNextLight(it))
  {
    if (light->GetSwitch())
    {
      this->Lights.emplace_back(this->AsShadowed(pass, light, kept));
    }
    else
    {
      ++this->LightsOff;
    }
  }
  this->Standins = std::move(kept);
}

// The light as the techniques shadow it: `light` itself, or for a positional light with a
// radius its disc (rebuilt only when the light or its information changed). A radius the
// pass cannot use is said once and the light shadowed as a point.
vtkLight* vtkPenumbraShadowPass::Internals::AsShadowed(
  vtkPenumbraShadowPass* pass, vtkLight* light, std::map<vtkLight*, Standin>& kept)
{
  const double radius = vtkPenumbraShadowKeys::GetLightRadius(light);
  if (radius == 0.0 || vtkPenumbraAreaLight::SafeDownCast(light))
  {
    return light;
  }
  if (!(radius > 0.0) || !std::isfinite(radius) || !light->GetPositional())
  {
    if (this->WarnedRadius.insert(light).second)
    {
      vtkWarningWithObjectMacro(pass,
        "Light radius " << radius << " not used: "
                        << (light->GetPositional()
                               ? "a radius must be a positive finite length"
                               : "a directional light's angular size is not supported")
                        << "; the light casts hard shadows");
    }
    return light;
  }
  const vtkMTimeType infoTime = light->GetInformation() ? light->GetInformation()->GetMTime() : 0;
  const auto known = this->Standins.find(light);
  Standin entry = known != this->Standins.end() ? known->second : Standin();
  if (!entry.Disc || entry.LightTime != light->GetMTime() || entry.InfoTime != infoTime)
  {
    entry.Disc = entry.Disc ? entry.Disc : vtkSmartPointer<vtkPenumbraAreaLight>::New();
    entry.Disc->SetFromLightRadius(light, radius);
    entry.LightTime = light->GetMTime();
    entry.InfoTime = infoTime;
  }
  kept[light] = entry;
  return entry.Disc;
}

// The technique that shadows light i this frame: the pass's technique's choice, or the
// fallback for a light it cannot shadow (said once per light, as a warning).
vtkPenumbraShadowTechnique* vtkPenumbraShadowPass::Internals::Choose(
  vtkPenumbraShadowPass* pass, size_t i)
{
  vtkLight* light = this->Lights[i];
  Report& report = this->Reports[i];
  vtkPenumbraShadowTechnique* chosen = this->Technique->SelectTechnique(light, report.Why);
  if (!chosen || !chosen->CanShadow(light))
  {
    const std::string refused =
      chosen ? chosen->GetTechniqueName() : this->Technique->GetTechniqueName();
    if (!this->Fallback && vtkPenumbraShadowPass::DefaultFallback)
    {
      this->Fallback.TakeReference(vtkPenumbraShadowPass::DefaultFallback());
    }
    chosen = this->Fallback;
    report.Why = chosen ? refused + " cannot shadow it; shadowed by " +
        chosen->GetTechniqueNameFor(light) + " instead"
                        : refused + " cannot shadow it and no fallback technique is set (" +
        "SetFallbackTechnique): not shadowed";
    if (this->Warned.insert({ light, chosen }).second)
    {
      vtkWarningWithObjectMacro(
        pass, "Light " << i << " (" << LightKind(light) << "): " << report.Why);
    }
  }
  report.Technique = chosen;
  return chosen;
}

// Lights no visible sample can receive (all face away, all outside the cone) get no shadow
// work. Tested only where the samples are on the CPU anyway (a technique of this frame reads
// them back, or an earlier frame of this view did): a GPU-only frame reads nothing back.
void vtkPenumbraShadowPass::Internals::SkipUnreachedLights(bool readsSamples)
{
  if (!readsSamples && !this->Frame->GetSamplesReadBack())
  {
    return;
  }
  vtkPenumbraViewSamples* samples = nullptr;
  for (size_t i = 0; i < this->Lights.size(); ++i)
  {
    Report& report = this->Reports[i];
    if (!report.Skipped.empty() || !report.Technique || this->ComposesAcrossProcesses(i))
    {
      continue;
    }
    samples = samples ? samples : this->Frame->GetSamples();
    if (!samples)
    {
      return;
    }
    this->Witness.resize(this->Lights.size(), -1);
    // Other processes' casters may lie anywhere (SetRemoteShadows()): only the samples
    // themselves can rule a light out.
    const double anywhere[6] = { -DBL_MAX / 4, DBL_MAX / 4, -DBL_MAX / 4, DBL_MAX / 4, -DBL_MAX / 4,
      DBL_MAX / 4 };
    report.Skipped = NothingToShadow(this->Lights[i], samples,
      this->Remote ? anywhere : this->CasterBox(), this->SampleBox(samples), this->Witness[i]);
    if (!report.Skipped.empty())
    {
      report.Technique = nullptr;
      ++this->NumberOfSkipped;
    }
  }
}

void vtkPenumbraShadowPass::Internals::ComputeVisibility(vtkPenumbraShadowPass* pass)
{
  vtkPenumbraFrame* frame = this->Frame;
  this->Reports.assign(this->Lights.size(), Report());
  this->NumberOfSkipped = 0;
  // Each light's technique first: whether any of them reads the samples back decides whether
  // the pass may look at the samples to skip lights.
  bool readsSamples = false;
  for (size_t i = 0; i < this->Lights.size(); ++i)
  {
    if (!Internals::CastsLight(this->Lights[i]))
    {
      this->Reports[i].Skipped = "it casts no light (zero intensity or black)";
      ++this->NumberOfSkipped;
      continue;
    }
    vtkPenumbraShadowTechnique* chosen = this->Choose(pass, i);
    readsSamples = (chosen && chosen->ReadsSamples()) || readsSamples;
  }
  this->SkipUnreachedLights(readsSamples);

  // Each shadowed light's visibility takes a texture unit in the receivers' shaders; VTK's
  // own textures keep a few.
  GLint units = 16;
  glGetIntegerv(GL_MAX_TEXTURE_IMAGE_UNITS, &units);
  const int budget = std::max(1, static_cast<int>(units) - ReservedTextureUnits);
  int skipped = 0;
  // The lights each technique shadows, as the frame numbers its shadowed lights; in the
  // order the techniques first appear, so a frame's work is deterministic.
  std::vector<std::pair<vtkPenumbraShadowTechnique*, std::vector<int>>> groups;
  for (size_t i = 0; i < this->Lights.size(); ++i)
  {
    Report& report = this->Reports[i];
    if (!report.Technique)
    {
      continue;
    }
    if (frame->GetNumberOfShadowedLights() >= budget)
    {
      ++skipped;
      report.Technique = nullptr;
      report.Skipped = "over the texture-unit budget of this OpenGL implementation";
      continue;
    }
    const int k = frame->GetNumberOfShadowedLights();
    frame->AddShadowedLight(this->Lights[i], static_cast<int>(i));
    auto group = std::find_if(groups.begin(), groups.end(),
      [&](const auto& g) { return g.first == report.Technique.Get(); });
    if (group == groups.end())
    {
      groups.emplace_back(report.Technique.Get(), std::vector<int>());
      group = groups.end() - 1;
    }
    group->second.push_back(k);
  }
  this->NumberOfSkipped += skipped;
  if (skipped > 0 && skipped != this->LastSkipped)
  {
    vtkErrorWithObjectMacro(pass, << skipped
                                  << " lights rendered without shadows: this OpenGL "
                                     "implementation gives a shader "
                                  << units << " texture units, so at most " << budget
                                  << " lights can be shadowed");
  }
  this->LastSkipped = skipped;
  for (auto& group : groups)
  {
    frame->SetActiveLights(group.second);
    group.first->ComputeFrame(frame);
  }
  frame->ClearActiveLights();
  this->ResolveRemote(pass, frame);
  frame->Finish();
  std::vector<std::string> injected(this->Lights.size());
  bool any = false;
  for (int k = 0; k < frame->GetNumberOfShadowedLights(); ++k)
  {
    if (frame->HasVisibility(k))
    {
      const int index = frame->GetLightIndex(k);
      vtkPenumbraFrame::ShaderLookup* lookup = frame->GetShaderLookup(index);
      injected[static_cast<size_t>(index)] = lookup ? "lookup:" + lookup->GetKey() : "texture";
      any = true;
    }
    else
    {
      vtkErrorWithObjectMacro(pass,
        "Light " << frame->GetLightIndex(k) << " rendered without shadows: the technique failed");
    }
  }
  this->SetInjected(any ? injected : std::vector<std::string>());
}

void vtkPenumbraShadowPass::Internals::ResolveRemote(
  vtkPenumbraShadowPass* pass, vtkPenumbraFrame* frame)
{
  if (!this->Remote || this->RemoteResolved)
  {
    return;
  }
  this->RemoteResolved = true;
  const std::vector<vtkLight*> lights(this->Lights.begin(), this->Lights.end());
  std::vector<vtkSmartPointer<vtkFloatArray>> stacked(lights.size());
  std::vector<vtkFloatArray*> values(lights.size(), nullptr);
  vtkPenumbraViewSamples* samples = nullptr;
  for (int k = 0; frame && k < frame->GetNumberOfShadowedLights(); ++k)
  {
    const size_t index = static_cast<size_t>(frame->GetLightIndex(k));
    if (!frame->HasVisibility(k) || index >= lights.size())
    {
      continue;
    }
    if (this->ComposesAcrossProcesses(index))
    {
      continue;
    }
    if (vtkPenumbraAreaLight::SafeDownCast(frame->GetShadowedLight(k)))
    {
      // Fractions of a light cannot be combined from one bit a ray: said once per light.
      if (this->WarnedRemote.insert(lights[index]).second)
      {
        vtkWarningWithObjectMacro(pass,
          "Light "
            << index
            << " (an area or sphere light) is "
               "shadowed by this process's own casters only: the other processes' shadows are "
               "resolved for point, spot and directional lights");
      }
      continue;
    }
    samples = frame->GetSamples();
    // The layers stacked, as the samples are (vtkPenumbraFrame::GetSamples()).
    const vtkIdType n = static_cast<vtkIdType>(frame->GetWidth()) * frame->GetHeight();
    auto all = vtkSmartPointer<vtkFloatArray>::New();
    all->SetNumberOfTuples(n * frame->GetNumberOfLayers());
    for (int layer = 0; layer < frame->GetNumberOfLayers(); ++layer)
    {
      vtkFloatArray* part = frame->GetVisibility(layer, static_cast<int>(index));
      std::copy_n(part->GetPointer(0), n, all->GetPointer(layer * n));
    }
    stacked[index] = all;
    values[index] = all;
  }
  std::string error;
  if (!this->Remote->Resolve(this->Geometry, samples, lights, values, error))
  {
    vtkErrorWithObjectMacro(
      pass, "Shadows cast on other processes' pieces are left out: " << error);
    return;
  }
  for (int k = 0; frame && k < frame->GetNumberOfShadowedLights(); ++k)
  {
    const size_t index = static_cast<size_t>(frame->GetLightIndex(k));
    if (index < stacked.size() && stacked[index])
    {
      frame->SetVisibility(k, stacked[index]);
    }
  }
}
