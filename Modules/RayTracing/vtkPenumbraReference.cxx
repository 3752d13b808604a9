#include "vtkPenumbraReference.h"

#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkSMPTools.h"
#include "vtkTypeUInt32Array.h"
#include "vtkUnsignedCharArray.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <limits>
#include <mutex>
#include <set>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraReference);
vtkCxxSetObjectMacro(vtkPenumbraReference, Geometry, vtkPenumbraSceneGeometry);

namespace
{
constexpr int MaxConvergedSamplesPerAxis = 256;

using penumbra::Clock;
using penumbra::ElapsedMs;

// One Embree geometry: a prop's occluders, read in place from the scene geometry's storage
// (its float32 points, and its corners when every triangle of the prop is an occluder).
struct Mesh
{
  size_t Block = 0;                   // the prop's block in the geometry's SceneTriangles
  std::vector<std::uint32_t> Local;   // per primitive its local triangle; empty: the same
  std::vector<std::uint32_t> Indices; // the occluders' corners, when not every triangle is one

  // The owner triangle (global) of primitive `prim`, -1 for none. The block is looked up in
  // the geometry's current view: the lists move (not their arrays) at every Update().
  vtkIdType Owner(const penumbra::SceneTriangles& triangles, unsigned int prim) const
  {
    const penumbra::SceneTriangles::Block& block = triangles.GetBlocks()[this->Block];
    return penumbra::SceneTriangles::GetOwnerLocal(
      block, this->Local.empty() ? prim : this->Local[prim]);
  }
};

// Per-ray state the filter reads: Embree hands our context pointer back to the filter, so
// the extra members must follow the RTCIntersectContext it starts with.
struct RayContext
{
  RTCIntersectContext Embree;
  const Mesh* Meshes;                        // per Embree geometry id
  const penumbra::SceneTriangles* Triangles; // the geometry's
  vtkIdType OwnTriangle;                     // the sample's triangle, -1 unknown
  float TieLimit;
  bool SawTie;
};

// Decides which candidate hits block. The casters the receiver's own triangle owns never do
// (penumbra_rules::IsOwnCaster: no acne bias needed for them); a hit in the tie band is
// remembered and skipped, so a blocker farther away can still decide the ray and only a ray
// with nothing else in the way reports a tie.
void OcclusionFilter(const RTCFilterFunctionNArguments* args)
{
  auto* ctx = reinterpret_cast<RayContext*>(args->context);
  for (unsigned int i = 0; i < args->N; ++i)
  {
    if (args->valid[i] != -1)
    {
      continue;
    }
    const Mesh& mesh = ctx->Meshes[RTCHitN_geomID(args->hit, args->N, i)];
    if (penumbra_rules::IsOwnCaster(
          mesh.Owner(*ctx->Triangles, RTCHitN_primID(args->hit, args->N, i)), ctx->OwnTriangle))
    {
      args->valid[i] = 0;
      continue;
    }
    // Embree stores the candidate's distance in tfar while the filter runs.
    if (RTCRayN_tfar(args->ray, args->N, i) < ctx->TieLimit)
    {
      ctx->SawTie = true;
      args->valid[i] = 0;
    }
  }
}

void EmbreeError(void* userPtr, RTCError code, const char* message)
{
  auto* text = static_cast<std::string*>(userPtr);
  *text = "Embree error " + std::to_string(static_cast<int>(code)) + ": " +
    (message ? message : "(no message)");
}

enum class LightKind
{
  Directional,
  Point,
  Spot,
  Area
};

}

// A light reduced to what the rays need (world frame; Run() rebases a copy).
struct vtkPenumbraReference::LightRays
{
  LightKind Kind = LightKind::Point;
  bool Off = false;
  double Direction[3] = { 0, 0, 0 }; // directional: unit vector toward the light
  double Position[3] = { 0, 0, 0 };  // point/spot: light position
  double Axis[3] = { 0, 0, 0 };      // spot: unit axis pointing away from the light
  double CosCone = -1.0;             // spot: cosine of the cone half-angle
  std::vector<double> Points;        // area: 3 per light sample
};

namespace penumbra_embree
{
// One reference's Embree objects.
struct Objects
{
  RTCDevice Device = nullptr;
  RTCScene Scene = nullptr;

  Objects();
  ~Objects();
  Objects(const Objects&) = delete;
  Objects& operator=(const Objects&) = delete;
  void Release();
};

// Embree's objects must be released while libembree's own state (its mutexes, its task
// scheduler) still exists. At exit it may not: ParaView keeps its views in a static of
// libvtkRemotingCore, destroyed after every library loaded later (libembree among them) and
// after the task scheduler's exit handlers; an Embree release then aborts
// ("pthread_mutex_lock failed") or hangs. So every live reference is registered here, and an
// exit handler registered right after the first device is created (after whatever state that
// creation set up, so it runs before that state is torn down) releases all their objects; a
// reference destroyed later has nothing left to release.
struct Registry
{
  std::mutex Mutex;
  std::set<Objects*> Live;
  bool Shutdown = false;

  // Never destroyed: references can be destroyed by other libraries' statics, after this
  // library's would be gone.
  static Registry& Get()
  {
    static Registry* registry = new Registry;
    return *registry;
  }

  // Call after a device was created.
  static void ReleaseAtExit()
  {
    static std::once_flag once;
    std::call_once(once, [] { std::atexit(&Registry::ReleaseAll); });
  }

  static void ReleaseAll()
  {
    Registry& registry = Get();
    std::lock_guard<std::mutex> lock(registry.Mutex);
    registry.Shutdown = true;
    for (Objects* live : registry.Live)
    {
      live->Release();
    }
  }
};

Objects::Objects()
{
  Registry& registry = Registry::Get();
  std::lock_guard<std::mutex> lock(registry.Mutex);
  registry.Live.insert(this);
}

Objects::~Objects()
{
  Registry& registry = Registry::Get();
  std::lock_guard<std::mutex> lock(registry.Mutex);
  registry.Live.erase(this);
  this->Release();
}

void Objects::Release()
{
  if (this->Scene)
  {
    rtcReleaseScene(this->Scene);
    this->Scene = nullptr;
  }
  if (this->Device)
  {
    rtcReleaseDevice(this->Device);
    this->Device = nullptr;
  }
}
}

struct vtkPenumbraReference::Internals : penumbra_embree::Objects
{
  std::string DeviceError;
  std::string Error;

  // What the current scene was built from.
  penumbra::CastersStamp Built; // what the Embree scene was built from

  std::vector<Mesh> Meshes;                            // per Embree geometry id
  vtkIdType Primitives = 0;                            // occluders in the scene
  const penumbra::SceneTriangles* Triangles = nullptr; // the geometry's, while Built holds
  double Diagonal = 1.0;

  bool Compact = false;            // the current scene indexes the shared points (CompactAbove)
  vtkIdType BuiltCompactAbove = 0; // the CompactAbove the current scene was built with
  // SetOccluderSubset's ids (ascending) while one is set, and whether the current scene was
  // built from them.
  bool Subset = false;
  std::vector<vtkIdType> SubsetIds;
  bool SubsetBuilt = false;
  std::string SubsetError; // a refused subset: every query fails with it until the next one

  bool AddMesh(const penumbra::SceneTriangles& triangles,
    const penumbra::SceneTriangles::Block& block, vtkIdType occluders, RTCBuildQuality quality);

  // `visit(local)` for every occluder of `block` the scene holds: all of them, or those of
  // the subset.
  template <class Visit>
  void ForEachKept(const penumbra::SceneTriangles::Block& block, Visit visit) const
  {
    const vtkIdType n = block.List->Size();
    if (!this->Subset)
    {
      for (vtkIdType t = 0; t < n; ++t)
      {
        if (this->Triangles->IsOccluderLocal(block, t))
        {
          visit(t);
        }
      }
      return;
    }
    auto it = std::lower_bound(this->SubsetIds.begin(), this->SubsetIds.end(), block.First);
    for (; it != this->SubsetIds.end() && *it < block.First + n; ++it)
    {
      if (this->Triangles->IsOccluderLocal(block, *it - block.First))
      {
        visit(*it - block.First);
      }
    }
  }

  vtkNew<vtkUnsignedCharArray> Ties;

  // One view sample's shadow rays: origin, scale-relative epsilons and own triangle.
  struct SampleRay
  {
    float Origin[3];
    float TNear, TieLimit;
    vtkIdType Own;
  };

  SampleRay MakeRay(const double p[3], vtkIdType tri, double epsilon, double tieFactor) const
  {
    SampleRay ray;
    for (int c = 0; c < 3; ++c)
    {
      ray.Origin[c] = static_cast<float>(p[c]);
    }
    const penumbra_rules::RayBand band =
      penumbra_rules::SampleBand(p, this->Diagonal, epsilon, tieFactor);
    ray.TNear = static_cast<float>(band.TNear);
    ray.TieLimit = static_cast<float>(band.TieLimit);
    ray.Own = tri >= 0 ? tri : -1;
    return ray;
  }

  // Traces from the sample along `toLight` (not normalized, its length is the distance for
  // positional targets); returns true when the light point is visible. `rays` counts the
  // rays actually traced.
  bool Visible(const SampleRay& ray, const double toLight[3], bool bounded, double epsilon,
    bool& tie, vtkIdType& rays) const
  {
    tie = false;
    double d[3] = { toLight[0], toLight[1], toLight[2] };
    const double distance = vtkMath::Normalize(d);
    if (this->Primitives == 0 || !(distance > 0.0))
    {
      return true;
    }
    const float dir[3] = { static_cast<float>(d[0]), static_cast<float>(d[1]),
      static_cast<float>(d[2]) };
    const float tfar = bounded ? static_cast<float>(distance * (1.0 - epsilon))
                               : std::numeric_limits<float>::infinity();
    if (!(tfar > ray.TNear))
    {
      return true;
    }
    ++rays;
    return !this->Occluded(ray.Origin, dir, ray.TNear, tfar, ray.Own, ray.TieLimit, tie);
  }

  bool Occluded(const float origin[3], const float direction[3], float tnear, float tfar,
    vtkIdType own, float tieLimit, bool& tie) const
  {
    RTCRay ray;
    ray.org_x = origin[0];
    ray.org_y = origin[1];
    ray.org_z = origin[2];
    ray.tnear = tnear;
    ray.dir_x = direction[0];
    ray.dir_y = direction[1];
    ray.dir_z = direction[2];
    ray.time = 0.0f;
    ray.tfar = tfar;
    ray.mask = 0xFFFFFFFFu;
    ray.id = 0;
    ray.flags = 0;
    RayContext ctx;
    rtcInitIntersectContext(&ctx.Embree);
    ctx.Embree.filter = OcclusionFilter;
    ctx.Meshes = this->Meshes.data();
    ctx.Triangles = this->Triangles;
    ctx.OwnTriangle = own;
    ctx.TieLimit = tieLimit;
    ctx.SawTie = false;
    rtcOccluded1(this->Scene, &ctx.Embree, &ray);
    const bool occluded = ray.tfar == -std::numeric_limits<float>::infinity();
    tie = !occluded && ctx.SawTie;
    return occluded;
  }

  // Moves a copy of the light into the geometry's rebased frame.
  static LightRays RebaseLight(const LightRays& light, const double geometryOrigin[3])
  {
    LightRays local = light;
    if (local.Kind == LightKind::Point || local.Kind == LightKind::Spot)
    {
      for (int c = 0; c < 3; ++c)
      {
        local.Position[c] -= geometryOrigin[c];
      }
    }
    const size_t nLight = local.Points.size() / 3;
    for (size_t j = 0; j < nLight; ++j)
    {
      for (int c = 0; c < 3; ++c)
      {
        local.Points[3 * j + c] -= geometryOrigin[c];
      }
    }
    return local;
  }

  // Area light: traces to every light point above the sample's tangent plane, sets the bits
  // of the visible ones in `bitRow` (if any) and returns the lit fraction.
  float TraceAreaSample(const SampleRay& ray, const LightRays& light, const double p[3],
    const double normal[3], double epsilon, vtkTypeUInt32* bitRow, bool& anyTie,
    vtkIdType& rays) const
  {
    const size_t nLight = light.Points.size() / 3;
    int lit = 0;
    anyTie = false;
    for (size_t j = 0; j < nLight; ++j)
    {
      const double toLight[3] = { light.Points[3 * j] - p[0], light.Points[3 * j + 1] - p[1],
        light.Points[3 * j + 2] - p[2] };
      if (!(vtkMath::Dot(normal, toLight) > 0.0))
      {
        continue; // on or below the tangent plane: counts as occluded
      }
      bool tie = false;
      if (this->Visible(ray, toLight, true, epsilon, tie, rays))
      {
        ++lit;
        if (bitRow)
        {
          bitRow[j / 32] |= 1u << (j % 32);
        }
      }
      anyTie = anyTie || tie;
    }
    return static_cast<float>(lit) / static_cast<float>(nLight);
  }

  // Directional, point and spot lights: 1 when the sample faces the light, lies inside a
  // spot's cone and sees the light, 0 otherwise.
  float TraceHardSample(const SampleRay& ray, const LightRays& light, const double p[3],
    const double normal[3], double epsilon, bool& tie, vtkIdType& rays) const
  {
    double toLight[3];
    bool bounded = true;
    if (light.Kind == LightKind::Directional)
    {
      for (int c = 0; c < 3; ++c)
      {
        toLight[c] = light.Direction[c];
      }
      bounded = false;
    }
    else
    {
      for (int c = 0; c < 3; ++c)
      {
        toLight[c] = light.Position[c] - p[c];
      }
    }
    float value = 0.0f;
    tie = false;
    if (vtkMath::Dot(normal, toLight) > 0.0)
    {
      bool inside = true;
      if (light.Kind == LightKind::Spot)
      {
        double fromLight[3] = { -toLight[0], -toLight[1], -toLight[2] };
        inside = vtkMath::Normalize(fromLight) > 0.0 &&
          vtkMath::Dot(fromLight, light.Axis) >= light.CosCone;
      }
      if (inside)
      {
        value = this->Visible(ray, toLight, bounded, epsilon, tie, rays) ? 1.0f : 0.0f;
      }
    }
    return value;
  }
};

//------------------------------------------------------------------------------
vtkPenumbraReference::vtkPenumbraReference()
  : Geometry(nullptr)
  , RelativeEpsilon(penumbra_rules::DefaultRelativeEpsilon)
  , TieFactor(penumbra_rules::DefaultTieFactor)
  , NumberOfTies(0)
  , NumberOfRays(0)
  , LastTimeMs(0.0)
  , LastBuildTimeMs(0.0)
  , NumberOfBuilds(0)
  , Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkPenumbraReference::~vtkPenumbraReference()
{
  this->SetGeometry(nullptr);
}

//------------------------------------------------------------------------------
vtkUnsignedCharArray* vtkPenumbraReference::GetTies()
{
  return this->Impl->Ties;
}

//------------------------------------------------------------------------------
bool vtkPenumbraReference::GetCompact()
{
  return this->Impl->Compact;
}

//------------------------------------------------------------------------------
void vtkPenumbraReference::SetOccluderSubset(vtkIdTypeArray* triangles)
{
  Internals& impl = *this->Impl;
  const vtkIdType* ids =
    triangles && triangles->GetNumberOfTuples() > 0 ? triangles->GetPointer(0) : nullptr;
  size_t count = triangles ? static_cast<size_t>(triangles->GetNumberOfValues()) : 0;
  // Ids out of order would make the scene miss occluders silently: the next query fails.
  impl.SubsetError.clear();
  if (triangles &&
    (triangles->GetNumberOfComponents() != 1 || (count > 0 && ids[0] < 0) ||
      std::adjacent_find(ids, ids + count, std::greater_equal<vtkIdType>()) != ids + count))
  {
    impl.SubsetError = "SetOccluderSubset: the triangle ids must be one component, ascending, "
                       "without repeats and not negative";
    triangles = nullptr;
    ids = nullptr;
    count = 0;
  }
  const bool same = triangles ? impl.Subset && impl.SubsetIds.size() == count &&
      std::equal(impl.SubsetIds.begin(), impl.SubsetIds.end(), ids)
                              : !impl.Subset;
  if (same)
  {
    return;
  }
  impl.Subset = triangles != nullptr;
  impl.SubsetIds.assign(ids, ids + count);
  impl.SubsetBuilt = false;
}

//------------------------------------------------------------------------------
vtkIdType vtkPenumbraReference::GetNumberOfCasterTriangles()
{
  return this->Impl->Primitives;
}

//------------------------------------------------------------------------------
const char* vtkPenumbraReference::GetErrorMessage()
{
  return this->Impl->Error.c_str();
}

namespace
{
bool Finite3(const double v[3])
{
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// The view sample arrays of a Compute call, checked before any output is touched.
struct SampleInput
{
  vtkIdType Count = 0;
  const float* Positions = nullptr;
  const float* Normals = nullptr;
  const int* Props = nullptr;
  const vtkIdType* Triangles = nullptr;
  double Shift[3] = { 0, 0, 0 }; // samples origin - geometry origin
};

// Returns an empty string when the samples are usable.
std::string CheckSamples(vtkPenumbraViewSamples* samples, SampleInput& in)
{
  if (!samples)
  {
    return "no view samples (null vtkPenumbraViewSamples)";
  }
  const std::string problem = samples->CheckArrays();
  if (!problem.empty())
  {
    return problem;
  }
  const vtkIdType n = samples->GetNumberOfSamples();
  vtkFloatArray* pos = samples->GetPositions();
  vtkFloatArray* nrm = samples->GetNormals();
  vtkIntArray* props = samples->GetPropIndices();
  vtkIdTypeArray* tris = samples->GetTriangleIds();
  double origin[3];
  samples->GetOrigin(origin);
  in.Count = n;
  in.Positions = n ? pos->GetPointer(0) : nullptr;
  in.Normals = n ? nrm->GetPointer(0) : nullptr;
  in.Props = n ? props->GetPointer(0) : nullptr;
  in.Triangles = n ? tris->GetPointer(0) : nullptr;
  for (int c = 0; c < 3; ++c)
  {
    in.Shift[c] = origin[c];
  }
  return std::string();
}
}

//------------------------------------------------------------------------------
// One place for every failure: the message is kept for GetErrorMessage() and reported.
int vtkPenumbraReference::Fail(const std::string& text)
{
  this->Impl->Error = text;
  PENUMBRA_FAIL(this->Impl->Error);
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::ComputeVisibility(
  vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility)
{
  return this->ComputeHardVisibility(samples, light, visibility, nullptr);
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::ComputeVisibility(vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility, vtkUnsignedCharArray* mask)
{
  this->Impl->Error.clear();
  if (!mask)
  {
    return this->Fail("no sample mask (null vtkUnsignedCharArray)");
  }
  if (!samples || !visibility)
  {
    return this->Fail("no view samples or no visibility array");
  }
  const vtkIdType n = samples->GetNumberOfSamples();
  if (mask->GetNumberOfTuples() != n || mask->GetNumberOfComponents() != 1 ||
    visibility->GetNumberOfTuples() != n || visibility->GetNumberOfComponents() != 1)
  {
    return this->Fail("the sample mask and the visibility array must have one "
                      "component and one tuple per view sample");
  }
  return this->ComputeHardVisibility(samples, light, visibility, mask);
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::ComputeHardVisibility(vtkPenumbraViewSamples* samples, vtkLight* light,
  vtkFloatArray* visibility, vtkUnsignedCharArray* mask)
{
  const auto start = Clock::now();
  this->Impl->Error.clear();
  if (!light)
  {
    return this->Fail("no light (null vtkLight)");
  }
  if (!visibility)
  {
    return this->Fail("no output array for the visibility (null vtkFloatArray)");
  }
  LightRays rays;
  if (auto* area = vtkPenumbraAreaLight::SafeDownCast(light))
  {
    const std::string problem = area->GetValidityMessage();
    if (!problem.empty())
    {
      return this->Fail("invalid area light: " + problem);
    }
    const int n = area->GetNumberOfSamples();
    rays.Kind = LightKind::Area;
    rays.Points.resize(3 * static_cast<size_t>(n));
    for (int j = 0; j < n; ++j)
    {
      area->GetSamplePosition(j, &rays.Points[3 * static_cast<size_t>(j)]);
    }
  }
  else
  {
    double position[3], focal[3];
    light->GetTransformedPosition(position);
    light->GetTransformedFocalPoint(focal);
    if (!Finite3(position) || !Finite3(focal))
    {
      return this->Fail("light position or focal point is not finite");
    }
    if (!light->GetPositional())
    {
      rays.Kind = LightKind::Directional;
      for (int c = 0; c < 3; ++c)
      {
        rays.Direction[c] = position[c] - focal[c];
      }
      if (!(vtkMath::Normalize(rays.Direction) > 0.0))
      {
        return this->Fail("directional light has no direction (position equals focal point)");
      }
    }
    else
    {
      for (int c = 0; c < 3; ++c)
      {
        rays.Position[c] = position[c];
      }
      const double cone = light->GetConeAngle();
      rays.Kind = cone < 90.0 ? LightKind::Spot : LightKind::Point;
      if (rays.Kind == LightKind::Spot)
      {
        for (int c = 0; c < 3; ++c)
        {
          rays.Axis[c] = focal[c] - position[c];
        }
        if (!(vtkMath::Normalize(rays.Axis) > 0.0))
        {
          return this->Fail("spot light has no axis (position equals focal point)");
        }
        rays.CosCone = std::cos(vtkMath::RadiansFromDegrees(cone));
      }
    }
  }
  rays.Off = !penumbra_rules::LightEmits(light);
  const int ok = this->Run(samples, rays, visibility, nullptr,
    mask && mask->GetNumberOfTuples() ? mask->GetPointer(0) : nullptr);
  if (ok)
  {
    this->LastTimeMs = ElapsedMs(start);
  }
  return ok;
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::ComputeAreaMasks(
  vtkPenumbraViewSamples* samples, vtkPenumbraAreaLight* light, vtkTypeUInt32Array* masks)
{
  const auto start = Clock::now();
  this->Impl->Error.clear();
  if (!light)
  {
    return this->Fail("no area light (null vtkPenumbraAreaLight)");
  }
  if (!masks)
  {
    return this->Fail("no output array for the masks (null vtkTypeUInt32Array)");
  }
  const std::string problem = light->GetValidityMessage();
  if (!problem.empty())
  {
    return this->Fail("invalid area light: " + problem);
  }
  LightRays rays;
  rays.Kind = LightKind::Area;
  const int n = light->GetNumberOfSamples();
  rays.Points.resize(3 * static_cast<size_t>(n));
  for (int j = 0; j < n; ++j)
  {
    light->GetSamplePosition(j, &rays.Points[3 * static_cast<size_t>(j)]);
  }
  rays.Off = !penumbra_rules::LightEmits(light);
  const int ok = this->Run(samples, rays, nullptr, masks);
  if (ok)
  {
    this->LastTimeMs = ElapsedMs(start);
  }
  return ok;
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::TraceAreaRays(vtkPenumbraViewSamples* samples,
  vtkPenumbraAreaLight* light, vtkIdType count, const vtkIdType* sampleIds, const int* lightSamples,
  unsigned char* visible)
{
  const auto start = Clock::now();
  Internals& impl = *this->Impl;
  impl.Error.clear();
  if (!light || count < 0 || (count > 0 && (!sampleIds || !lightSamples || !visible)))
  {
    return this->Fail("TraceAreaRays needs an area light and count >= 0 input and output "
                      "entries");
  }
  const std::string problem = light->GetValidityMessage();
  if (!problem.empty())
  {
    return this->Fail("invalid area light: " + problem);
  }
  SampleInput in;
  const std::string sampleProblem = CheckSamples(samples, in);
  if (!sampleProblem.empty())
  {
    return this->Fail(sampleProblem);
  }
  if (!this->Geometry)
  {
    return this->Fail("no scene geometry: call SetGeometry() first");
  }
  if (!this->EnsureScene())
  {
    return 0;
  }
  const int nLight = light->GetNumberOfSamples();
  for (vtkIdType i = 0; i < count; ++i)
  {
    if (sampleIds[i] < 0 || sampleIds[i] >= in.Count || lightSamples[i] < 0 ||
      lightSamples[i] >= nLight)
    {
      return this->Fail("TraceAreaRays: entry " + std::to_string(i) +
        " names a view sample or light sample out of range");
    }
  }
  // Run()'s frame and rules, one (view sample, light sample) pair at a time.
  double geometryOrigin[3];
  this->Geometry->GetOrigin(geometryOrigin);
  std::vector<double> points(3 * static_cast<size_t>(nLight));
  for (int j = 0; j < nLight; ++j)
  {
    light->GetSamplePosition(j, &points[3 * static_cast<size_t>(j)]);
    for (int c = 0; c < 3; ++c)
    {
      points[3 * static_cast<size_t>(j) + c] -= geometryOrigin[c];
    }
  }
  for (int c = 0; c < 3; ++c)
  {
    in.Shift[c] -= geometryOrigin[c];
  }
  const bool off = !penumbra_rules::LightEmits(light);
  const double epsilon = this->RelativeEpsilon;
  const double tieFactor = this->TieFactor;
  std::atomic<vtkIdType> rayCount(0);
  vtkSMPTools::For(0, count,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType localRays = 0;
      for (vtkIdType i = begin; i < end; ++i)
      {
        const vtkIdType s = sampleIds[i];
        // Background first: its position and normal are not even read.
        double p[3], normal[3];
        const bool surface = in.Props[s] >= 0;
        for (int c = 0; surface && c < 3; ++c)
        {
          p[c] = static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c];
          normal[c] = in.Normals[3 * s + c];
        }
        if (!surface || !Finite3(p) || !Finite3(normal))
        {
          visible[i] = 0;
          continue;
        }
        if (off)
        {
          visible[i] = 1;
          continue;
        }
        const double* q = &points[3 * static_cast<size_t>(lightSamples[i])];
        const double toLight[3] = { q[0] - p[0], q[1] - p[1], q[2] - p[2] };
        if (!(vtkMath::Dot(normal, toLight) > 0.0))
        {
          visible[i] = 0;
          continue;
        }
        const Internals::SampleRay ray = impl.MakeRay(p, in.Triangles[s], epsilon, tieFactor);
        bool tie = false;
        visible[i] = impl.Visible(ray, toLight, true, epsilon, tie, localRays) ? 1 : 0;
      }
      rayCount += localRays;
    });
  this->NumberOfRays = rayCount.load();
  this->LastTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::ComputeConvergedVisibility(vtkPenumbraViewSamples* samples,
  vtkPenumbraAreaLight* light, int samplesPerAxis, vtkFloatArray* visibility)
{
  const auto start = Clock::now();
  this->Impl->Error.clear();
  if (!light)
  {
    return this->Fail("no area light (null vtkPenumbraAreaLight)");
  }
  if (!visibility)
  {
    return this->Fail("no output array for the visibility (null vtkFloatArray)");
  }
  if (samplesPerAxis < 1 || samplesPerAxis > MaxConvergedSamplesPerAxis)
  {
    return this->Fail("samples per axis must be in [1, " +
      std::to_string(MaxConvergedSamplesPerAxis) + "], got " + std::to_string(samplesPerAxis));
  }
  const std::string problem = light->GetValidityMessage();
  if (!problem.empty())
  {
    return this->Fail("invalid area light: " + problem);
  }
  // vtkPenumbraAreaLight's own rule and expressions, so that the light's own k reproduces
  // its positions bit for bit.
  vtkNew<vtkDoubleArray> positions;
  light->GetSamplePositions(samplesPerAxis, positions);
  const vtkIdType n = positions->GetNumberOfTuples();
  LightRays rays;
  rays.Kind = LightKind::Area;
  rays.Points.assign(positions->GetPointer(0), positions->GetPointer(0) + 3 * n);
  rays.Off = !penumbra_rules::LightEmits(light);
  const int ok = this->Run(samples, rays, visibility, nullptr);
  if (ok)
  {
    this->LastTimeMs = ElapsedMs(start);
  }
  return ok;
}

//------------------------------------------------------------------------------
// One prop's occluders as an Embree geometry whose id is its index in Meshes: casters only;
// zero-area triangles cover no solid angle and are skipped. False with DeviceError set when
// Embree refused.
bool vtkPenumbraReference::Internals::AddMesh(const penumbra::SceneTriangles& triangles,
  const penumbra::SceneTriangles::Block& block, vtkIdType occluders, RTCBuildQuality quality)
{
  Internals& impl = *this;
  const penumbra::TriangleList& list = *block.List;
  const vtkIdType n = list.Size();
  Mesh mesh;
  mesh.Block = static_cast<size_t>(&block - triangles.GetBlocks().data());
  if (occluders == 0)
  {
    return true;
  }
  // When every triangle is kept (the usual prop) Embree reads the prop's corners; otherwise
  // the kept occluders' corners are listed.
  if (occluders < n)
  {
    mesh.Local.reserve(static_cast<size_t>(occluders));
    mesh.Indices.reserve(3 * static_cast<size_t>(occluders));
    impl.ForEachKept(block,
      [&](vtkIdType t)
      {
        mesh.Local.push_back(static_cast<std::uint32_t>(t));
        mesh.Indices.insert(mesh.Indices.end(), &list.Corners[3 * static_cast<size_t>(t)],
          &list.Corners[3 * static_cast<size_t>(t)] + 3);
      });
  }
  const size_t count = mesh.Local.empty() ? static_cast<size_t>(n) : mesh.Local.size();
  RTCGeometry geometry = rtcNewGeometry(impl.Device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
    list.Rebased.data(), 0, 3 * sizeof(float), static_cast<size_t>(list.NumberOfPoints()));
  rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
    mesh.Indices.empty() ? list.Corners.data() : mesh.Indices.data(), 0, 3 * sizeof(std::uint32_t),
    count);
  rtcSetGeometryBuildQuality(geometry, quality);
  rtcCommitGeometry(geometry);
  rtcAttachGeometryByID(impl.Scene, geometry, static_cast<unsigned int>(impl.Meshes.size()));
  rtcReleaseGeometry(geometry);
  if (!impl.DeviceError.empty())
  {
    return false;
  }
  impl.Primitives += static_cast<vtkIdType>(count);
  impl.Meshes.push_back(std::move(mesh));
  return true;
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::EnsureScene()
{
  Internals& impl = *this->Impl;
  vtkPenumbraSceneGeometry* geometry = this->Geometry;
  if (!impl.SubsetError.empty())
  {
    return this->Fail(impl.SubsetError);
  }
  if (impl.Scene && !impl.Built.Changed(geometry) && impl.BuiltCompactAbove == this->CompactAbove &&
    impl.SubsetBuilt)
  {
    return 1;
  }
  const auto start = Clock::now();

  if (!impl.Device)
  {
    if (penumbra_embree::Registry::Get().Shutdown)
    {
      return this->Fail("the process is exiting: Embree has been released");
    }
    impl.Device = rtcNewDevice(nullptr);
    if (!impl.Device)
    {
      return this->Fail("cannot create an Embree device");
    }
    penumbra_embree::Registry::ReleaseAtExit();
    rtcSetDeviceErrorFunction(impl.Device, EmbreeError, &impl.DeviceError);
  }
  if (impl.Scene)
  {
    rtcReleaseScene(impl.Scene);
    impl.Scene = nullptr;
  }
  impl.Built.Forget();
  impl.DeviceError.clear();
  impl.Meshes.clear();
  impl.Primitives = 0;

  impl.Scene = rtcNewScene(impl.Device);
  if (!impl.Scene)
  {
    return this->Fail("cannot create an Embree scene: " + impl.DeviceError);
  }
  const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
  impl.Triangles = &triangles;
  std::vector<vtkIdType> occluders;
  vtkIdType total = 0;
  for (const penumbra::SceneTriangles::Block& block : triangles.GetBlocks())
  {
    vtkIdType count = 0;
    impl.ForEachKept(block, [&](vtkIdType) { ++count; });
    occluders.push_back(count);
    total += count;
  }
  // Large scenes compact (see CompactAbove): the leaves index the shared float32 points
  // (Triangle4i) instead of holding copies (Triangle4v with spatial splits), the same robust
  // ray/triangle test on the same corners.
  impl.Compact = total > this->CompactAbove;
  impl.BuiltCompactAbove = this->CompactAbove;
  rtcSetSceneFlags(impl.Scene,
    static_cast<RTCSceneFlags>(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION |
      (impl.Compact ? RTC_SCENE_FLAG_COMPACT : 0)));
  const RTCBuildQuality quality = impl.Compact ? RTC_BUILD_QUALITY_MEDIUM : RTC_BUILD_QUALITY_HIGH;
  rtcSetSceneBuildQuality(impl.Scene, quality);
  for (size_t b = 0; b < occluders.size(); ++b)
  {
    if (!impl.AddMesh(triangles, triangles.GetBlocks()[b], occluders[b], quality))
    {
      return this->Fail("cannot make an Embree geometry: " + impl.DeviceError);
    }
  }
  rtcCommitScene(impl.Scene);
  if (!impl.DeviceError.empty())
  {
    return this->Fail("building the Embree scene failed: " + impl.DeviceError);
  }

  impl.Diagonal = penumbra_rules::SceneDiagonal(geometry);

  impl.Built.Remember(geometry);
  impl.SubsetBuilt = true;
  ++this->NumberOfBuilds;
  this->LastBuildTimeMs = ElapsedMs(start);
  return 1;
}

//------------------------------------------------------------------------------
int vtkPenumbraReference::Run(vtkPenumbraViewSamples* samples, const LightRays& light,
  vtkFloatArray* visibility, vtkTypeUInt32Array* masks, const unsigned char* subset)
{
  Internals& impl = *this->Impl;
  SampleInput in;
  const std::string problem = CheckSamples(samples, in);
  if (!problem.empty())
  {
    return this->Fail(problem);
  }
  if (!this->Geometry)
  {
    return this->Fail("no scene geometry: call SetGeometry() first");
  }
  if (!this->EnsureScene())
  {
    return 0;
  }

  // Everything below happens in the geometry's rebased frame, differences taken in double.
  double geometryOrigin[3];
  this->Geometry->GetOrigin(geometryOrigin);
  for (int c = 0; c < 3; ++c)
  {
    in.Shift[c] -= geometryOrigin[c];
  }
  const LightRays local = Internals::RebaseLight(light, geometryOrigin);
  const size_t nLight = local.Points.size() / 3;

  // ---- The outputs, sized and cleared.
  const vtkIdType n = in.Count;
  const int words = static_cast<int>((nLight + 31) / 32);
  float* vis = nullptr;
  if (visibility)
  {
    visibility->SetNumberOfComponents(1);
    visibility->SetNumberOfTuples(n);
    vis = n ? visibility->GetPointer(0) : nullptr;
  }
  vtkTypeUInt32* bits = nullptr;
  if (masks)
  {
    masks->SetNumberOfComponents(std::max(words, 1));
    masks->SetNumberOfTuples(n);
    bits = n ? masks->GetPointer(0) : nullptr;
    if (bits)
    {
      std::fill(bits, bits + static_cast<size_t>(n) * std::max(words, 1), 0u);
    }
  }
  impl.Ties->SetNumberOfComponents(1);
  impl.Ties->SetNumberOfTuples(n);
  unsigned char* ties = n ? impl.Ties->GetPointer(0) : nullptr;

  // ---- One pass over the samples: background, light off, area or hard light.
  const double epsilon = this->RelativeEpsilon;
  const double tieFactor = this->TieFactor;
  std::atomic<vtkIdType> rayCount(0);
  std::atomic<vtkIdType> tieCount(0);

  vtkSMPTools::For(0, n,
    [&](vtkIdType begin, vtkIdType end)
    {
      vtkIdType localRays = 0;
      vtkIdType localTies = 0;
      for (vtkIdType s = begin; s < end; ++s)
      {
        ties[s] = 0;
        if (subset && !subset[s])
        {
          continue; // not ours to decide: the caller's value stays
        }
        // Background first: its position and normal are not even read.
        double p[3], normal[3];
        const bool surface = in.Props[s] >= 0;
        for (int c = 0; surface && c < 3; ++c)
        {
          p[c] = static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c];
          normal[c] = in.Normals[3 * s + c];
        }
        if (!surface || !Finite3(p) || !Finite3(normal))
        {
          if (vis)
          {
            vis[s] = -1.0f;
          }
          continue;
        }
        vtkTypeUInt32* bitRow = bits ? bits + static_cast<size_t>(s) * words : nullptr;
        if (local.Off)
        {
          if (vis)
          {
            vis[s] = 1.0f;
          }
          if (bitRow)
          {
            for (size_t j = 0; j < nLight; ++j)
            {
              bitRow[j / 32] |= 1u << (j % 32);
            }
          }
          continue;
        }
        const Internals::SampleRay ray = impl.MakeRay(p, in.Triangles[s], epsilon, tieFactor);
        bool tie = false;
        const float value = local.Kind == LightKind::Area
          ? impl.TraceAreaSample(ray, local, p, normal, epsilon, bitRow, tie, localRays)
          : impl.TraceHardSample(ray, local, p, normal, epsilon, tie, localRays);
        if (vis)
        {
          vis[s] = value;
        }
        if (tie)
        {
          ties[s] = 1;
          ++localTies;
        }
      }
      rayCount += localRays;
      tieCount += localTies;
    });

  this->NumberOfRays = rayCount.load();
  this->NumberOfTies = tieCount.load();
  if (visibility)
  {
    visibility->Modified();
  }
  if (masks)
  {
    masks->Modified();
  }
  impl.Ties->Modified();
  return 1;
}

//------------------------------------------------------------------------------
void vtkPenumbraReference::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Geometry: " << this->Geometry << "\n";
  os << indent << "RelativeEpsilon: " << this->RelativeEpsilon << "\n";
  os << indent << "TieFactor: " << this->TieFactor << "\n";
  os << indent << "CompactAbove: " << this->CompactAbove << "\n";
  os << indent << "Compact: " << (this->Impl->Compact ? "yes" : "no") << "\n";
  os << indent << "NumberOfBuilds: " << this->NumberOfBuilds << "\n";
  os << indent << "NumberOfCasterTriangles: " << this->GetNumberOfCasterTriangles() << "\n";
  os << indent << "OccluderSubset: ";
  if (this->Impl->Subset)
  {
    os << this->Impl->SubsetIds.size() << " triangles\n";
  }
  else
  {
    os << "(none: every occluder)\n";
  }
  os << indent << "NumberOfRays: " << this->NumberOfRays << "\n";
  os << indent << "NumberOfTies: " << this->NumberOfTies << "\n";
  os << indent << "LastTimeMs: " << this->LastTimeMs << "\n";
  os << indent << "LastBuildTimeMs: " << this->LastBuildTimeMs << "\n";
}
