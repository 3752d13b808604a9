// vtkPenumbraShadowVolumeShadows: one light's shadow volumes (Brabec 2003, ch. 3 and 8; CC
// culling, Lloyd et al. 2004) and the per-light cache of built volumes.

#include "vtkPenumbraShadowVolumeInternals.h"

#include <algorithm>
#include <cmath>

using namespace penumbra_shadow_volume;

namespace
{
// A positional light's volumes end at a finite far cap (Brabec 2003, §3.2.5 asks only for closed
// volumes): the copy of v is L + (v - L) / w, written homogeneously as (v - L + w L, w). The
// point at infinity (w = 0) serves a perspective camera, where it projects to a vanishing
// point, but under a parallel camera every point at infinity has clip w = 0 and the dark caps
// vanish, which breaks z-fail wherever the view direction lies in a volume. A sample x lies
// in the truncated volume of a caster point p exactly when |x - L| <= |p - L| / w, so
// w = (nearest caster distance) / (4 x farthest geometry distance) keeps every sample (all
// lie on the geometry) inside what it was inside; the nearest distance is bounded below per
// triangle by its plane distance and its bounding sphere. Edge-on triangles (facing 0) get
// no volume and are skipped; with none left any w would do.
double PositionalFarW(const Connectivity& mesh, const VolumeLight& light, const double bounds[6])
{
  const Vec3& L = light.Position;
  double farthest = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    const Vec3 q = { bounds[corner & 1], bounds[2 + ((corner >> 1) & 1)],
      bounds[4 + ((corner >> 2) & 1)] };
    const Vec3 d = (q - L);
    farthest = std::max(farthest, std::sqrt(glm::dot(d, d)));
  }
  double nearest = VTK_DOUBLE_MAX;
  auto visit = [&](const std::array<int, 3>& t)
  {
    const Vec3& a = mesh.Points[static_cast<size_t>(t[0])];
    const Vec3& b = mesh.Points[static_cast<size_t>(t[1])];
    const Vec3& c = mesh.Points[static_cast<size_t>(t[2])];
    const Vec3 n = glm::cross(b - a, c - a);
    const double f = glm::dot(n, L - a);
    if (!(f != 0.0))
    {
      return;
    }
    const Vec3 centre = { (a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0,
      (a[2] + b[2] + c[2]) / 3.0 };
    double radius = 0.0;
    for (const Vec3* v : { &a, &b, &c })
    {
      const Vec3 d = (*v - centre);
      radius = std::max(radius, std::sqrt(glm::dot(d, d)));
    }
    const Vec3 toLight = (L - centre);
    const double bound = std::max(
      std::fabs(f) / std::sqrt(glm::dot(n, n)), std::sqrt(glm::dot(toLight, toLight)) - radius);
    nearest = std::min(nearest, bound);
  };
  std::for_each(mesh.Loose.begin(), mesh.Loose.end(), visit);
  for (const auto& component : mesh.Components)
  {
    std::for_each(component.Faces.begin(), component.Faces.end(), visit);
  }
  const double w = nearest / (4.0 * farthest);
  return w > 0.0 && w <= 0.25 ? w : 0.25;
}

// CC shadow volumes (Lloyd et al. 2004): true when a separating plane proves that the volume of
// the light-facing oriented triangle (a, b, c) misses `box`.
bool VolumeMissesBox(const VolumeLight& light, const Vec3 v[3], const double box[6])
{
  auto minOver = [&](const Vec3& n, const Vec3& p)
  {
    double m = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      m += n[a] * ((n[a] >= 0.0 ? box[2 * a] : box[2 * a + 1]) - p[a]);
    }
    return m;
  };
  // The triangle's plane: the volume lies behind it.
  const Vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
  if (minOver(n, v[0]) > 0.0)
  {
    return true;
  }
  // Side planes through each edge and the light.
  for (int k = 0; k < 3; ++k)
  {
    const Vec3& u = v[k];
    const Vec3& w = v[(k + 1) % 3];
    const Vec3 m = glm::cross(light.Away(u), w - u);
    if (minOver(m, u) > 0.0)
    {
      return true;
    }
  }
  // Box faces.
  for (int a = 0; a < 3; ++a)
  {
    bool above = true, below = true;
    for (int k = 0; k < 3; ++k)
    {
      const double d = light.Away(v[k])[a];
      above = above && v[k][a] > box[2 * a + 1] && d >= 0.0;
      below = below && v[k][a] < box[2 * a] && d <= 0.0;
    }
    if (above || below)
    {
      return true;
    }
  }
  return false;
}

// One light's volumes as xyzw triangles (Brabec 2003, ch. 3 and 8): light caps, then sides
// and dark caps; and, for the outline (see VolumeOutline), the volumes the geometry stage
// makes for GPU-silhouette components.
struct VolumeBuilder
{
  const Connectivity& Mesh;
  const VolumeLight& Light;
  const double* Box = nullptr; // culling box of the pending samples, null: no culling
  double FarW = 0.0;           // positional lights: w of the extruded copies
  VolumeStream& Caps;          // explicit light caps (drawn with the cap offset)
  VolumeStream& Sides;         // explicit dark caps and sides
  VolumeStream GPUVolumes;     // GPU components, as the geometry stage draws them
  VolumeStream GPUUncertain;   // segments: prism edges of faces it may classify otherwise
  vtkIdType Culled = 0;
  vtkIdType SilhouetteEdges = 0;
  vtkIdType CapFaces = 0; // faces whose caps the point table draws

  VolumeBuilder(
    const Connectivity& mesh, const VolumeLight& light, VolumeStream& caps, VolumeStream& sides)
    : Mesh(mesh)
    , Light(light)
    , Caps(caps)
    , Sides(sides)
  {
  }

  // Mesh point i itself, as a volume vertex.
  void Near(VolumeStream& out, int i) const
  {
    const Vec3& p = this->Mesh.Points[static_cast<size_t>(i)];
    out.Put(p[0], p[1], p[2], 1.0, VolumeStream::NearId(i));
  }
  // Extruded copy of mesh point i: a finite prism for directional lights, a finite frustum
  // for positional ones (PositionalFarW; the same formula as the GPU silhouette stage).
  void Far(VolumeStream& out, int i) const
  {
    const Vec3& v = this->Mesh.Points[static_cast<size_t>(i)];
    const VolumeLight& vl = this->Light;
    if (vl.Directional)
    {
      out.Put(v[0] - vl.Extrusion * vl.Direction[0], v[1] - vl.Extrusion * vl.Direction[1],
        v[2] - vl.Extrusion * vl.Direction[2], 1.0, VolumeStream::FarId(i));
    }
    else
    {
      const double w = this->FarW;
      out.Put(v[0] - vl.Position[0] + w * vl.Position[0],
        v[1] - vl.Position[1] + w * vl.Position[1], v[2] - vl.Position[2] + w * vl.Position[2], w,
        VolumeStream::FarId(i));
    }
  }
  // One side quad for edge u -> v of a light-facing oriented face (outward winding).
  void Side(VolumeStream& out, int u, int v) const
  {
    this->Near(out, u);
    this->Far(out, u);
    this->Far(out, v);
    this->Near(out, u);
    this->Far(out, v);
    this->Near(out, v);
  }
  void CapAndDark(VolumeStream& caps, VolumeStream& sides, const int t[3]) const
  {
    this->Near(caps, t[0]);
    this->Near(caps, t[1]);
    this->Near(caps, t[2]);
    this->Far(sides, t[0]);
    this->Far(sides, t[2]);
    this->Far(sides, t[1]);
  }
  // Per-triangle volume (Brabec 2003, ch. 3 brute force; correct for any input): triangle
  // `t` (mesh points) turned toward the light, its extrusion and its three sides.
  void PerTriangle(std::array<int, 3> t)
  {
    const auto& P = this->Mesh.Points;
    Vec3 v[3] = { P[static_cast<size_t>(t[0])], P[static_cast<size_t>(t[1])],
      P[static_cast<size_t>(t[2])] };
    const double f = this->Light.Facing(v[0], v[1], v[2]);
    if (!(f != 0.0)) // edge-on to the light: a flat volume, blocks nothing
    {
      return;
    }
    if (f < 0.0)
    {
      std::swap(v[1], v[2]);
      std::swap(t[1], t[2]);
    }
    if (this->Box && VolumeMissesBox(this->Light, v, this->Box))
    {
      ++this->Culled;
      return;
    }
    this->CapAndDark(this->Caps, this->Sides, t.data());
    this->Side(this->Sides, t[0], t[1]);
    this->Side(this->Sides, t[1], t[2]);
    this->Side(this->Sides, t[2], t[0]);
  }

  // Whether the geometry stage, deciding facing in float32 on float32 vertices, may decide
  // otherwise than `f` (double): a bound on that rounding with a margin of about 16.
  bool MayFaceOtherwise(const Vec3 v[3], double f) const
  {
    double m = 0.0;
    for (int k = 0; k < 3; ++k)
    {
      m = std::max(m, std::sqrt(glm::dot(v[k], v[k])));
    }
    const Vec3 e1 = (v[1] - v[0]), e2 = (v[2] - v[0]);
    const double l1 = std::sqrt(glm::dot(e1, e1)), l2 = std::sqrt(glm::dot(e2, e2));
    const double lm = this->Light.Directional
      ? 1.0
      : std::sqrt(glm::dot(this->Light.Position, this->Light.Position)) + m;
    return std::fabs(f) <= 1e-6 * ((l1 + l2) * m * lm + l1 * l2 * lm);
  }
  // The nine edges of a face's prism: every volume edge whose neighbourhood changes when the
  // face enters or leaves its set is one of them.
  void PutPrismEdges(VolumeStream& out, const std::array<int, 3>& t) const
  {
    for (int k = 0; k < 3; ++k)
    {
      const int a = t[static_cast<size_t>(k)], b = t[static_cast<size_t>((k + 1) % 3)];
      this->Near(out, a);
      this->Near(out, b);
      this->Far(out, a);
      this->Far(out, b);
      this->Near(out, a);
      this->Far(out, a);
    }
  }

  // Silhouette volumes of a component (Brabec 2003, ch. 3 and 8; CPU silhouettes). The
  // stencil count of a set of per-triangle volumes is the number of its triangles the segment
  // to the light crosses; where two triangles of the set share an edge with opposite windings
  // (both turned toward the light), their side quads cancel, so only the set's caps and the
  // sides on its border edges need drawing. Closed components with the light outside: the
  // light-facing set alone is crossed whenever the mesh is. Open components, or a positional
  // light inside the component's box (maybe inside the mesh, where light-facing caps do not
  // close): the light-facing set plus the back-facing set turned toward the light, i.e. every
  // triangle, as per-triangle volumes would, but with sides only on silhouette and boundary
  // edges. `gpu`: the component is drawn by the geometry stage; its volumes go to GPUVolumes
  // (no culling there) for the outline alone. Otherwise the faces' sets go to `sets` (their
  // caps are drawn from the point table) and the sides to Sides.
  void Component(
    const Connectivity::Component& c, bool bothSets, bool gpu, std::vector<signed char>& sets)
  {
    const auto& P = this->Mesh.Points;
    VolumeStream& sides = gpu ? this->GPUVolumes : this->Sides;
    // Per face: +1 light-facing set, -1 back-facing set (turned), 0 none. Facing is one
    // decision per face, ties (edge-on) in no set (Brabec 2003, ch. 9). A culled face leaves
    // its set: the sum of the remaining volumes stays a valid count.
    std::vector<signed char> gpuSet;
    std::vector<signed char>& set = gpu ? gpuSet : sets;
    set.assign(c.Faces.size(), 0);
    bool any = false;
    for (size_t i = 0; i < c.Faces.size(); ++i)
    {
      std::array<int, 3> t = c.Faces[i];
      Vec3 v[3] = { P[static_cast<size_t>(t[0])], P[static_cast<size_t>(t[1])],
        P[static_cast<size_t>(t[2])] };
      const double f = this->Light.Facing(v[0], v[1], v[2]);
      if (gpu && this->MayFaceOtherwise(v, f))
      {
        this->PutPrismEdges(this->GPUUncertain, t);
      }
      signed char si = f > 0.0 ? 1 : (bothSets && f < 0.0 ? -1 : 0);
      if (si < 0)
      {
        std::swap(v[1], v[2]);
        std::swap(t[1], t[2]);
      }
      if (si != 0 && !gpu && this->Box && VolumeMissesBox(this->Light, v, this->Box))
      {
        ++this->Culled;
        si = 0;
      }
      if (si != 0)
      {
        if (gpu)
        {
          this->CapAndDark(this->GPUVolumes, this->GPUVolumes, t.data());
        }
        else
        {
          ++this->CapFaces;
        }
        any = true;
      }
      set[i] = si;
    }
    if (!any)
    {
      return;
    }
    c.ForEachEdge(
      [&](const std::array<int, 4>& e)
      {
        const int p0 = e[0], p1 = e[1];
        const signed char s0 = set[static_cast<size_t>(e[2])];
        const signed char s1 = e[3] >= 0 ? set[static_cast<size_t>(e[3])] : 0;
        if (s0 == s1)
        {
          return;
        }
        this->SilhouetteEdges += gpu ? 0 : 1;
        // Keep the winding of the face as turned toward the light (Brabec 2003, ch. 3): F0
        // runs v0 -> v1, F1 v1 -> v0, each reversed when turned.
        if (s0 != 0)
        {
          s0 > 0 ? this->Side(sides, p0, p1) : this->Side(sides, p1, p0);
        }
        if (s1 != 0)
        {
          s1 > 0 ? this->Side(sides, p1, p0) : this->Side(sides, p0, p1);
        }
      });
  }
};
}

// One light's volumes into `build` (see VolumeBuilder); `box` culls (null: no culling),
// `gpu` leaves closed components to the geometry stage, `outline` also prepares the
// outline of every volume for the edge resolve.
void vtkPenumbraShadowVolumeShadows::Internals::BuildVolumes(VolumeSet& build,
  const Connectivity& mesh, const VolumeLight& vl, const double* box, const double bounds[6],
  bool gpu, bool outline)
{
  VolumeBuilder builder(mesh, vl, build.LightCaps, build.Rest);
  builder.Box = box;
  builder.FarW = vl.Directional ? 0.0 : PositionalFarW(mesh, vl, bounds);
  build.FarW = builder.FarW;
  build.Light = vl;
  for (const auto& t : mesh.Loose)
  {
    builder.PerTriangle(t);
  }
  build.Sets.assign(mesh.Components.size(), {});
  for (size_t ci = 0; ci < mesh.Components.size(); ++ci)
  {
    const Connectivity::Component& c = mesh.Components[ci];
    bool inside = !vl.Directional;
    for (int a = 0; a < 3 && inside; ++a)
    {
      inside = vl.Position[a] >= c.Bounds[2 * a] && vl.Position[a] <= c.Bounds[2 * a + 1];
    }
    const bool bothSets = !c.Closed || inside;
    if (gpu && !bothSets)
    {
      // Silhouettes, caps and sides come from the geometry stage.
      for (const auto& a : c.Adjacency)
      {
        build.AdjacencyIndices.insert(build.AdjacencyIndices.end(), a.begin(), a.end());
      }
      if (!outline)
      {
        continue;
      }
    }
    builder.Component(c, bothSets, gpu && !bothSets, build.Sets[ci]);
  }
  build.CapFaces = builder.CapFaces;
  build.SilhouetteEdges = gpu && !build.AdjacencyIndices.empty() ? -1 : builder.SilhouetteEdges;
  build.AdjacencyCount = static_cast<GLsizei>(build.AdjacencyIndices.size());
  build.Culled = builder.Culled;
  if (outline)
  {
    BuildOutline(build, mesh, builder.GPUVolumes, builder.GPUUncertain);
  }
  // The identities served the outline; the set keeps the floats it draws.
  build.LightCaps.ForgetIds();
  build.Rest.ForgetIds();
}

std::array<int, 3> vtkPenumbraShadowVolumeShadows::Internals::VolumeSet::CapCorners(
  const Connectivity::Component& c, size_t f, signed char set)
{
  std::array<int, 3> t = c.Faces[f];
  if (set < 0)
  {
    std::swap(t[1], t[2]);
  }
  return t;
}

void vtkPenumbraShadowVolumeShadows::Internals::Evict(size_t i)
{
  const VolumeSet& set = *this->Volumes[i];
  for (GLuint b : { set.FarBuffer, set.CapBuffer, set.StreamBuffer, set.AdjacencyBuffer })
  {
    if (b)
    {
      this->Garbage.push_back(b);
    }
  }
  this->Volumes.erase(this->Volumes.begin() + static_cast<std::ptrdiff_t>(i));
}

void vtkPenumbraShadowVolumeShadows::Internals::ClearVolumes()
{
  while (!this->Volumes.empty())
  {
    this->Evict(this->Volumes.size() - 1);
  }
}

// Box of the pending samples in the geometry's frame (culling, extrusion length), grown
// by the float rounding of the samples (they are float32).
void vtkPenumbraShadowVolumeShadows::Internals::PendingBox(
  const penumbra_light_views::FrameInputs& in, const std::vector<unsigned char>& state,
  double scale, double box[6])
{
  const double* shift = in.Shift;
  for (int c = 0; c < 3; ++c)
  {
    box[2 * c] = VTK_DOUBLE_MAX;
    box[2 * c + 1] = -VTK_DOUBLE_MAX;
  }
  for (vtkIdType s = 0; s < in.NumberOfSamples; ++s)
  {
    if (state[static_cast<size_t>(s)] == Pending)
    {
      for (int c = 0; c < 3; ++c)
      {
        const double p = static_cast<double>(in.Positions[3 * s + c]) + shift[c];
        box[2 * c] = std::min(box[2 * c], p);
        box[2 * c + 1] = std::max(box[2 * c + 1], p);
      }
    }
  }
  for (int c = 0; c < 3; ++c)
  {
    box[2 * c] -= 1e-5 * scale;
    box[2 * c + 1] += 1e-5 * scale;
  }
}

// The volume cache: a set of `vl` whose culling box holds the pending `box`, built when
// missing (evicting the least recently used set when full), stamped as used now.
vtkPenumbraShadowVolumeShadows::Internals::VolumeSet*
vtkPenumbraShadowVolumeShadows::Internals::FindVolumes(
  vtkPenumbraShadowVolumeShadows& self, const Group& g, const VolumeLight& vl, const double box[6])
{
  const auto volumeStart = Clock::now();
  std::vector<double> key = vl.Key();
  key.insert(key.end(),
    { self.Cull ? 1.0 : 0.0, self.GPUSilhouettes ? 1.0 : 0.0, self.Resolve ? 1.0 : 0.0 });
  auto serves = [&](const std::unique_ptr<VolumeSet>& v)
  {
    return v->Key == key &&
      (!self.Cull || penumbra_light_views::KeptBox::Serves(v->Box, box, CullMargin));
  };
  auto found = std::find_if(this->Volumes.begin(), this->Volumes.end(), serves);
  if (found == this->Volumes.end())
  {
    if (this->Volumes.size() >= MaxVolumeSets)
    {
      // The least recently used set; the sets of this group are the newest, so stay.
      auto oldest = std::min_element(this->Volumes.begin(), this->Volumes.end(),
        [](const std::unique_ptr<VolumeSet>& a, const std::unique_ptr<VolumeSet>& b)
        { return a->Stamp < b->Stamp; });
      this->Evict(static_cast<size_t>(oldest - this->Volumes.begin()));
    }
    this->Volumes.push_back(std::unique_ptr<VolumeSet>(new VolumeSet));
    found = this->Volumes.end() - 1;
    VolumeSet& build = **found;
    build.Key = key;
    penumbra_light_views::KeptBox::Grow(box, CullMargin, build.Box);
    ++self.NumberOfVolumeBuilds;
    BuildVolumes(build, this->Mesh, vl, self.Cull ? build.Box : nullptr, g.RebasedBounds,
      self.GPUSilhouettes, self.Resolve);
    self.VolumeTimeMs += ElapsedMs(volumeStart);
  }
  (*found)->Stamp = this->Clock;
  return found->get();
}
