#include "vtkPenumbraShadowVolumeShadows.h"
#include "vtkPenumbraShadowVolumeInternals.h"
#include "vtkPenumbraStatistics.h"

#include "vtkCamera.h"
#include "vtkCollection.h"
#include "vtkFloatArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <cmath>
#include <string>

vtkStandardNewMacro(vtkPenumbraShadowVolumeShadows);

using penumbra_light_views::LightSetup;
using namespace penumbra_shadow_volume;

namespace
{
// True unless the segment from `eye` to the light provably stays clear (by `tol`) of the
// oriented triangle: used to prove the camera is outside its volume (z-pass is then exact).
bool SegmentMayTouch(const VolumeLight& light, const Vec3& eye, const Vec3 v[3], double tol)
{
  const Vec3 far = light.Directional ? Vec3{ eye[0] + light.Extrusion * light.Direction[0],
    eye[1] + light.Extrusion * light.Direction[1], eye[2] + light.Extrusion * light.Direction[2] }
                                     : light.Position;
  Vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
  const double len = std::sqrt(glm::dot(n, n));
  if (!(len > 0.0))
  {
    return true;
  }
  n /= len;
  const double d0 = glm::dot(n, eye - v[0]);
  const double d1 = glm::dot(n, far - v[0]);
  if ((d0 > tol && d1 > tol) || (d0 < -tol && d1 < -tol))
  {
    return false;
  }
  if (std::fabs(d0 - d1) <= tol)
  {
    return true; // nearly in the plane: not provable cheaply
  }
  const double t = std::min(1.0, std::max(0.0, d0 / (d0 - d1)));
  const Vec3 x = { eye[0] + t * (far[0] - eye[0]), eye[1] + t * (far[1] - eye[1]),
    eye[2] + t * (far[2] - eye[2]) };
  for (int k = 0; k < 3; ++k)
  {
    const Vec3 e = (v[(k + 1) % 3] - v[k]);
    const double el = std::sqrt(glm::dot(e, e));
    if (el > 0.0 && glm::dot(glm::cross(e, x - v[k]), n) / el < -tol)
    {
      return false;
    }
  }
  return true;
}
}

// ---- Input checks (shared with the other map-based techniques), per light: a light that
// cannot be shadowed here (an area light, say) fails alone.
void vtkPenumbraShadowVolumeShadows::Internals::ReadJobs(vtkPenumbraShadowVolumeShadows& self,
  Group& g, vtkLight* const* lights, vtkFloatArray* const* visibilities, int count)
{
  g.Jobs.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i)
  {
    Job job;
    std::string inputError;
    if (!job.In.Read(g.Renderer, g.Geometry, g.Samples, lights[i], visibilities[i], inputError))
    {
      vtkErrorWithObjectMacro(&self, << "shadow volumes: " << inputError);
      if (visibilities[i])
      {
        visibilities[i]->SetNumberOfTuples(0);
      }
      continue;
    }
    job.Light = lights[i];
    job.Visibility = visibilities[i];
    g.Jobs.push_back(std::move(job));
  }
}

// What every job shares (needs at least one job). Null, or why the group fails.
const char* vtkPenumbraShadowVolumeShadows::Internals::ReadShared(Group& g)
{
  g.In = &g.Jobs.front().In;
  g.Window = g.In->Window;
  g.N = g.In->NumberOfSamples;
  g.Width = g.Samples->GetWidth();
  g.Height = g.Samples->GetHeight();
  if (static_cast<vtkIdType>(g.Width) * g.Height != g.N)
  {
    return "view samples are not a width x height image";
  }
  g.Camera = g.Renderer->GetActiveCamera();
  if (!g.Camera)
  {
    return "the renderer has no camera";
  }
  return nullptr;
}

// ---- Connectivity, once per geometry change, and its statistics; then the scene scale.
void vtkPenumbraShadowVolumeShadows::Internals::UpdateConnectivity(
  vtkPenumbraShadowVolumeShadows& self, Group& g)
{
  vtkPenumbraSceneGeometry* geometry = g.Geometry;
  const auto connectivityStart = Clock::now();
  {
    if (this->MeshBuilt.Changed(geometry) || this->BuiltWithSilhouettes != self.Silhouettes ||
      this->BuiltWithAdjacency != self.GPUSilhouettes)
    {
      this->Mesh.Build(geometry, self.Silhouettes, self.GPUSilhouettes);
      this->MeshBuilt.Remember(geometry);
      geometry->GetOrigin(this->Origin);
      this->BuiltWithSilhouettes = self.Silhouettes;
      this->BuiltWithAdjacency = self.GPUSilhouettes;
      this->ClearVolumes(); // their GL buffers are deleted once the context is current
      this->PointsUploaded = false;
      ++self.NumberOfConnectivityBuilds;
      self.ConnectivityTimeMs = ElapsedMs(connectivityStart);
    }
  }
  const Connectivity& mesh = this->Mesh;
  self.NumberOfCasterTriangles = mesh.Casters;
  self.NumberOfComplexFaces = mesh.Complex;
  self.NumberOfBoundaryEdges = mesh.BoundaryEdges;
  self.NumberOfClosedComponents = static_cast<vtkIdType>(std::count_if(mesh.Components.begin(),
    mesh.Components.end(), [](const Connectivity::Component& c) { return c.Closed; }));
  self.NumberOfOpenComponents =
    static_cast<vtkIdType>(mesh.Components.size()) - self.NumberOfClosedComponents;
  self.NumberOfPerTriangleVolumes = static_cast<vtkIdType>(mesh.Loose.size());

  // Scene scale from the geometry alone (every sample lies on it), so that the extrusion
  // length and with it the cached volumes do not depend on the camera.
  double all[6];
  geometry->GetBounds(all);
  for (int c = 0; c < 3 && vtkMath::AreBoundsInitialized(all); ++c)
  {
    const double lo = all[2 * c] - this->Origin[c], hi = all[2 * c + 1] - this->Origin[c];
    g.Scale = std::max({ g.Scale, std::fabs(lo), std::fabs(hi), hi - lo });
    g.RebasedBounds[2 * c] = lo;
    g.RebasedBounds[2 * c + 1] = hi;
  }
}

// ---- Per light: facing, spot cone, lights that are off, background (the reference's
// rules); then its volumes, once per light / connectivity / sample box / option change.
void vtkPenumbraShadowVolumeShadows::Internals::PrepareLights(
  vtkPenumbraShadowVolumeShadows& self, Group& g)
{
  ++this->Clock;
  for (Job& job : g.Jobs)
  {
    if (this->PrepareLight(self, g, job))
    {
      job.Channel = g.Counted++;
    }
  }
}

// One light of PrepareLights. False: every sample decided, nothing to count.
bool vtkPenumbraShadowVolumeShadows::Internals::PrepareLight(
  vtkPenumbraShadowVolumeShadows& self, const Group& g, Job& job)
{
  const penumbra_light_views::FrameInputs& in = *g.In;
  const vtkIdType n = g.N;
  const LightSetup& setup = job.In.Light;
  vtkFloatArray* visibility = job.Visibility;
  visibility->SetNumberOfComponents(1);
  visibility->SetNumberOfTuples(n);
  float* vis = n ? visibility->GetPointer(0) : nullptr;
  job.Vis = vis;
  job.State.assign(static_cast<size_t>(n), Decided);
  const penumbra_light_views::FacingCounts facing =
    penumbra_light_views::ClassifyFacing(setup, n, in.Positions, in.Normals, in.Props, in.Shift,
      this->Mesh.Casters > 0, vis, job.State.data(), Pending, Decided);
  self.NumberOfCountedSamples += facing.Pending;
  if (facing.Pending == 0)
  {
    visibility->Modified();
    return false;
  }

  double box[6];
  PendingBox(in, job.State, g.Scale, box);

  VolumeLight& vl = job.VL;
  vl.Directional = setup.Type == LightSetup::Kind::Directional;
  vl.Direction = Vec3(setup.Direction[0], setup.Direction[1], setup.Direction[2]);
  vl.Position = Vec3(setup.Position[0], setup.Position[1], setup.Position[2]);
  // A prism longer than four times the whole scene's extent reaches past every sample.
  vl.Extrusion = 4.0 * g.Scale + 1.0;

  job.Volumes = this->FindVolumes(self, g, vl, box);
  const VolumeSet& vs = *job.Volumes;
  self.NumberOfSilhouetteEdges = vs.SilhouetteEdges < 0 || self.NumberOfSilhouetteEdges < 0
    ? -1
    : self.NumberOfSilhouetteEdges + vs.SilhouetteEdges;
  self.NumberOfCulledVolumes += vs.Culled;
  self.NumberOfVolumeTriangles += 2 * vs.CapFaces + vs.StreamVertices() / 3;
  return true;
}

// ---- z-pass needs a camera outside every volume (Brabec 2003, ch. 3, §3.2.5); prove it for
// perspective cameras from the volumes actually drawn.
void vtkPenumbraShadowVolumeShadows::Internals::ChooseMethods(
  vtkPenumbraShadowVolumeShadows& self, Group& g)
{
  for (Job& job : g.Jobs)
  {
    if (!job.Volumes)
    {
      continue;
    }
    const VolumeSet& vs = *job.Volumes;
    const VolumeLight& vl = job.VL;
    bool zpass = self.Method == METHOD_ZPASS;
    if (self.Method == METHOD_AUTO && !g.Parallel)
    {
      double eyeWorld[3];
      g.Camera->GetPosition(eyeWorld);
      const Vec3 eye = { eyeWorld[0] - this->Origin[0], eyeWorld[1] - this->Origin[1],
        eyeWorld[2] - this->Origin[2] };
      const double tol = 1e-5 * g.Scale;
      bool outside = true;
      // Every light cap as drawn (float32): the explicit ones, then the components'.
      const std::vector<float>& V = vs.LightCaps.V;
      for (size_t i = 0; i + 2 < vs.LightCaps.Size() && outside; i += 3)
      {
        Vec3 v[3];
        for (size_t k = 0; k < 3; ++k)
        {
          const float* f = V.data() + 4 * (i + k);
          v[k] = { f[0], f[1], f[2] };
        }
        outside = !SegmentMayTouch(vl, eye, v, tol);
      }
      for (size_t ci = 0; ci < vs.Sets.size() && outside; ++ci)
      {
        const std::vector<signed char>& set = vs.Sets[ci];
        for (size_t f = 0; f < set.size() && outside; ++f)
        {
          if (set[f] == 0)
          {
            continue;
          }
          const std::array<int, 3> t = VolumeSet::CapCorners(this->Mesh.Components[ci], f, set[f]);
          Vec3 v[3];
          for (int k = 0; k < 3; ++k)
          {
            float p[4];
            vs.TablePoint(this->Mesh, 2 * t[static_cast<size_t>(k)], p);
            v[k] = { p[0], p[1], p[2] };
          }
          outside = !SegmentMayTouch(vl, eye, v, tol);
        }
      }
      // GPU components: their front faces are not known here, so every face must stay clear.
      for (size_t i = 0; i + 5 < vs.AdjacencyIndices.size() && outside; i += 6)
      {
        const Vec3 v[3] = { this->Mesh.Points[vs.AdjacencyIndices[i]],
          this->Mesh.Points[vs.AdjacencyIndices[i + 2]],
          this->Mesh.Points[vs.AdjacencyIndices[i + 4]] };
        outside = !SegmentMayTouch(vl, eye, v, tol);
      }
      zpass = outside;
    }
    job.ZPass = zpass;
    self.UsedZPass = self.UsedZPass || zpass;
  }
}

//------------------------------------------------------------------------------
vtkPenumbraShadowVolumeShadows::vtkPenumbraShadowVolumeShadows()
  : Reference(vtkPenumbraReference::New())
  , Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraShadowVolumeShadows::~vtkPenumbraShadowVolumeShadows()
{
  this->Impl->Release(nullptr);
  this->Reference->Delete();
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowVolumeShadows::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowVolumeShadows::ResetStatistics()
{
  this->ConnectivityTimeMs = this->VolumeTimeMs = this->StencilTimeMs = 0.0;
  this->SampleDepthTimeMs = this->ResolveTimeMs = 0.0;
  this->NumberOfVolumeTriangles = this->NumberOfPassedFragments = 0;
  this->NumberOfSilhouetteEdges = this->NumberOfCulledVolumes = 0;
  this->UsedZPass = false;
  this->NumberOfFillFragments = this->MeasureFill ? 0 : -1;
  this->NumberOfCountedSamples = 0;
  this->NumberOfResolvedSamples = 0;
  this->NumberOfMasks = 0;
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowVolumeShadows::ComputeVisibility(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  this->ResetStatistics();
  const int done = this->ComputeGroup(renderer, geometry, samples, &light, &visibility, 1);
  this->LastTimeMs = ElapsedMs(start);
  return done == 1 ? 1 : 0;
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowVolumeShadows::ComputeVisibilities(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLightCollection* lights,
  vtkCollection* visibilities)
{
  const auto start = Clock::now();
  this->ResetStatistics();
  if (!lights || !visibilities || lights->GetNumberOfItems() != visibilities->GetNumberOfItems())
  {
    vtkErrorMacro("ComputeVisibilities needs one visibility array per light");
    return 0;
  }
  std::vector<vtkLight*> all;
  std::vector<vtkFloatArray*> out;
  for (int i = 0; i < lights->GetNumberOfItems(); ++i)
  {
    auto* light = vtkLight::SafeDownCast(lights->GetItemAsObject(i));
    auto* vis = vtkFloatArray::SafeDownCast(visibilities->GetItemAsObject(i));
    if (!light || !vis)
    {
      vtkErrorMacro("ComputeVisibilities: item " << i << " is not a light and a float array");
      if (vis)
      {
        vis->SetNumberOfTuples(0);
      }
      continue;
    }
    all.push_back(light);
    out.push_back(vis);
  }
  // Brabec 2003, ch. 8: groups of LightsPerMask lights share one mask (one channel each).
  int done = 0;
  for (size_t first = 0; first < all.size(); first += static_cast<size_t>(this->LightsPerMask))
  {
    const int count =
      static_cast<int>(std::min(all.size() - first, static_cast<size_t>(this->LightsPerMask)));
    done += this->ComputeGroup(
      renderer, geometry, samples, all.data() + first, out.data() + first, count);
  }
  this->LastTimeMs = ElapsedMs(start);
  return done;
}

//------------------------------------------------------------------------------
int vtkPenumbraShadowVolumeShadows::ComputeGroup(vtkRenderer* renderer,
  vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, vtkLight* const* lights,
  vtkFloatArray* const* visibilities, int count)
{
  Internals& impl = *this->Impl;
  // A failure reports the error and leaves every output empty.
  auto fail = [&](const std::string& text)
  {
    vtkErrorMacro(<< "shadow volumes: " << text);
    for (int failed = 0; failed < count; ++failed)
    {
      if (visibilities[failed])
      {
        visibilities[failed]->SetNumberOfTuples(0);
      }
    }
    return 0;
  };
  Internals::Group group;
  group.Renderer = renderer;
  group.Geometry = geometry;
  group.Samples = samples;

  Internals::ReadJobs(*this, group, lights, visibilities, count);
  if (group.Jobs.empty())
  {
    return 0;
  }
  if (const char* error = Internals::ReadShared(group))
  {
    return fail(error);
  }
  impl.UpdateConnectivity(*this, group);
  impl.PrepareLights(*this, group);
  if (group.Counted == 0)
  {
    return static_cast<int>(group.Jobs.size());
  }
  impl.ComputeSampleDepths(*this, group);
  impl.ChooseMethods(*this, group);
  if (const char* error = impl.ReadyGL(group))
  {
    return fail(error);
  }
  if (!impl.CountInStencil(*this, group))
  {
    return fail("a DEPTH32F_STENCIL8 + RGBA8 framebuffer is not supported here");
  }
  this->StencilTimeMs += ElapsedMs(group.StencilStart);
  return impl.FinishLights(*this, group);
}

//------------------------------------------------------------------------------
double vtkPenumbraShadowVolumeShadows::GetUncertainFraction()
{
  return this->NumberOfCountedSamples > 0
    ? static_cast<double>(this->NumberOfResolvedSamples) / this->NumberOfCountedSamples
    : 0.0;
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowVolumeShadows::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "MeasureFill: " << this->MeasureFill << "\n";
  os << indent << "Method: " << this->Method << "\n";
  os << indent << "Cull: " << this->Cull << "\n";
  os << indent << "Silhouettes: " << this->Silhouettes << "\n";
  os << indent << "GPUSilhouettes: " << this->GPUSilhouettes << "\n";
  os << indent << "CapOffset: " << this->CapOffset << "\n";
  os << indent << "NumberOfCasterTriangles: " << this->NumberOfCasterTriangles << "\n";
  os << indent << "NumberOfComplexFaces: " << this->NumberOfComplexFaces << "\n";
  os << indent << "NumberOfBoundaryEdges: " << this->NumberOfBoundaryEdges << "\n";
  os << indent << "NumberOfClosedComponents: " << this->NumberOfClosedComponents << "\n";
  os << indent << "NumberOfOpenComponents: " << this->NumberOfOpenComponents << "\n";
  os << indent << "NumberOfPerTriangleVolumes: " << this->NumberOfPerTriangleVolumes << "\n";
  os << indent << "NumberOfSilhouetteEdges: " << this->NumberOfSilhouetteEdges << "\n";
  os << indent << "NumberOfVolumeTriangles: " << this->NumberOfVolumeTriangles << "\n";
  os << indent << "NumberOfCulledVolumes: " << this->NumberOfCulledVolumes << "\n";
  os << indent << "UsedZPass: " << this->UsedZPass << "\n";
  os << indent << "Resolve: " << this->Resolve << "\n";
  os << indent << "LightsPerMask: " << this->LightsPerMask << "\n";
  // Above this many casters the edge resolve traces through the possible blockers alone.
  os << indent << "ReferenceCompactAbove: " << this->Reference->GetCompactAbove() << "\n";
  os << indent << "NumberOfMasks: " << this->NumberOfMasks << "\n";
  os << indent << "NumberOfResolvedSamples: " << this->NumberOfResolvedSamples << "\n";
}

//------------------------------------------------------------------------------
void vtkPenumbraShadowVolumeShadows::GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats)
{
  this->Superclass::GetStatistics(light, stats);
  stats->Set("masks", this->NumberOfMasks);
  stats->Set("caster_triangles", static_cast<double>(this->NumberOfCasterTriangles));
  stats->Set("complex_faces", static_cast<double>(this->NumberOfComplexFaces));
  stats->Set("boundary_edges", static_cast<double>(this->NumberOfBoundaryEdges));
  stats->Set("closed_components", static_cast<double>(this->NumberOfClosedComponents));
  stats->Set("open_components", static_cast<double>(this->NumberOfOpenComponents));
  stats->Set("per_triangle_volumes", static_cast<double>(this->NumberOfPerTriangleVolumes));
  stats->Set("silhouette_edges", static_cast<double>(this->NumberOfSilhouetteEdges));
  stats->Set("volume_triangles", static_cast<double>(this->NumberOfVolumeTriangles));
  stats->Set("culled_volumes", static_cast<double>(this->NumberOfCulledVolumes));
  stats->Set("passed_fragments", static_cast<double>(this->NumberOfPassedFragments));
  if (this->NumberOfFillFragments >= 0) // measured only with MeasureFill
  {
    stats->Set("fill_fragments", static_cast<double>(this->NumberOfFillFragments));
  }
  stats->Set("resolved_samples", static_cast<double>(this->NumberOfResolvedSamples));
  stats->Set("zpass", this->UsedZPass ? 1.0 : 0.0);
  stats->Set("connectivity_builds", this->NumberOfConnectivityBuilds);
  stats->Set("volume_builds", this->NumberOfVolumeBuilds);
  stats->Set("depth_computations", this->NumberOfDepthComputations);
  stats->Set("connectivity_ms", this->ConnectivityTimeMs);
  stats->Set("volume_ms", this->VolumeTimeMs);
  stats->Set("stencil_ms", this->StencilTimeMs);
  stats->Set("sample_depth_ms", this->SampleDepthTimeMs);
  stats->Set("resolve_ms", this->ResolveTimeMs);
}
