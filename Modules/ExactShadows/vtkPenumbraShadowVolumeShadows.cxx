#include "vtkPenumbraShadowVolumeShadows.h"

#include "vtkCamera.h"
#include "vtkCollection.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWeakPointer.h"
#include "vtk_glew.h"

#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraShadowVolumeAdjacencyGS.h"
#include "vtkPenumbraShadowVolumeAdjacencyVS.h"
#include "vtkPenumbraShadowVolumeFS.h"
#include "vtkPenumbraShadowVolumeMaskFS.h"
#include "vtkPenumbraShadowVolumeMaskVS.h"
#include "vtkPenumbraShadowVolumeVS.h"

// GCC 12 reports a false -Wmaybe-uninitialized inside OpenMesh's property push_back.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#pragma GCC diagnostic pop

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkPenumbraShadowVolumeShadows);

using penumbra_light_views::LightSetup;

namespace
{
using penumbra::Clock;
using penumbra::ElapsedMs;
using Vec3 = glm::dvec3;

// Lexicographic order, for welding vertices in a std::map.
struct Vec3Less
{
  bool operator()(const Vec3& a, const Vec3& b) const
  {
    return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.z < b.z);
  }
};

// Below this cosine between the sample normal and the light direction a sample is traced
// (see the edge resolve): about 0.06 degrees from grazing.
constexpr double GrazingCosine = 1e-3;

enum : unsigned char
{
  Decided = 0,
  Pending = 1
};

// Caster connectivity (OpenMesh): welded vertices, closed components for
// silhouette volumes, everything else as loose triangles for per-triangle volumes.
struct Connectivity
{
  struct Component
  {
    // Closed (no boundary edge, non-zero volume): silhouette volumes of the light-facing
    // faces suffice. Open: both face sets are needed (see the volume builder).
    bool Closed = false;
    // Faces as welded vertex triples; closed components are already turned so that their
    // winding is outward (components of negative volume are reversed once here).
    std::vector<std::array<int, 3>> Faces;
    // Edges: v0 -> v1 as in face F0's winding, v1 -> v0 in F1's; indices into Faces; F1 is
    // -1 on a boundary edge.
    std::vector<std::array<int, 4>> Edges;
    // Per face, GL_TRIANGLES_ADJACENCY order: v0, opposite of (v0, v1), v1, opposite of
    // (v1, v2), v2, opposite of (v2, v0) (the GPU silhouette path).
    std::vector<std::array<int, 6>> Adjacency;
    double Bounds[6] = { VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX,
      VTK_DOUBLE_MAX, -VTK_DOUBLE_MAX };
  };
  std::vector<Vec3> Points;
  std::vector<Component> Components;
  std::vector<std::array<int, 3>> Loose;
  vtkIdType Casters = 0;
  vtkIdType Complex = 0;
  vtkIdType BoundaryEdges = 0;

  using OMesh = OpenMesh::TriMesh_ArrayKernelT<>;

  void Build(vtkPenumbraSceneGeometry* geometry, bool silhouettes)
  {
    *this = Connectivity();
    const std::vector<std::array<int, 3>> tris = this->WeldCasters(geometry);
    this->Casters = static_cast<vtkIdType>(tris.size());
    if (!silhouettes)
    {
      this->Loose = tris;
      return;
    }

    OMesh mesh;
    std::vector<OMesh::VertexHandle> handles;
    handles.reserve(this->Points.size());
    for (const Vec3& p : this->Points)
    {
      handles.push_back(mesh.add_vertex(OMesh::Point(
        static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]))));
    }
    std::vector<int> faceTri; // OpenMesh face index -> index into tris
    // OpenMesh reports every refused face on its error stream; we count them instead.
    omerr().disable();
    for (size_t i = 0; i < tris.size(); ++i)
    {
      const auto& t = tris[i];
      OMesh::FaceHandle f = mesh.add_face(handles[t[0]], handles[t[1]], handles[t[2]]);
      if (!f.is_valid())
      {
        ++this->Complex;
        this->Loose.push_back(t);
      }
      else
      {
        faceTri.resize(static_cast<size_t>(f.idx()) + 1, -1);
        faceTri[static_cast<size_t>(f.idx())] = static_cast<int>(i);
      }
    }
    omerr().enable();
    this->BuildComponents(mesh, tris, faceTri);
  }

  // The occluding, non-degenerate triangles as triples of welded points (into Points).
  std::vector<std::array<int, 3>> WeldCasters(vtkPenumbraSceneGeometry* geometry)
  {
    const vtkIdType nt = geometry->GetNumberOfTriangles();
    const double* tv = nt > 0 ? geometry->GetVertices()->GetPointer(0) : nullptr;
    // Weld exactly equal coordinates only: anything looser would move geometry and the
    // reference sees the unwelded triangles.
    std::map<Vec3, int, Vec3Less> weld;
    std::vector<std::array<int, 3>> tris;
    for (vtkIdType t = 0; t < nt; ++t)
    {
      if (!geometry->IsOccluder(t))
      {
        continue;
      }
      std::array<int, 3> idx;
      Vec3 v[3];
      for (int k = 0; k < 3; ++k)
      {
        v[k] = { tv[9 * t + 3 * k], tv[9 * t + 3 * k + 1], tv[9 * t + 3 * k + 2] };
      }
      const Vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
      if (!(glm::dot(n, n) > 0.0)) // zero-area: the reference skips them too
      {
        continue;
      }
      for (int k = 0; k < 3; ++k)
      {
        auto it = weld.emplace(v[k], static_cast<int>(this->Points.size()));
        if (it.second)
        {
          this->Points.push_back(v[k]);
        }
        idx[k] = it.first->second;
      }
      tris.push_back(idx);
    }
    return tris;
  }

  // Components of `mesh` by flood fill over shared edges.
  void BuildComponents(
    const OMesh& mesh, const std::vector<std::array<int, 3>>& tris, const std::vector<int>& faceTri)
  {
    const int nf = static_cast<int>(mesh.n_faces());
    std::vector<int> component(static_cast<size_t>(nf), -1);
    std::vector<int> stack;
    std::vector<int> local(static_cast<size_t>(nf), -1); // face -> index in its component
    for (int start = 0; start < nf; ++start)
    {
      if (component[static_cast<size_t>(start)] >= 0)
      {
        continue;
      }
      std::vector<int> faces;
      bool closed = true;
      const int id = static_cast<int>(this->Components.size());
      component[static_cast<size_t>(start)] = id;
      stack.assign(1, start);
      while (!stack.empty())
      {
        const int f = stack.back();
        stack.pop_back();
        faces.push_back(f);
        for (OMesh::HalfedgeHandle h : mesh.fh_range(mesh.face_handle(static_cast<unsigned>(f))))
        {
          const OMesh::HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
          if (mesh.is_boundary(o))
          {
            closed = false;
            ++this->BoundaryEdges;
            continue;
          }
          const int g = mesh.face_handle(o).idx();
          if (component[static_cast<size_t>(g)] < 0)
          {
            component[static_cast<size_t>(g)] = id;
            stack.push_back(g);
          }
        }
      }
      this->Components.push_back(this->MakeComponent(mesh, faces, closed, tris, faceTri, local));
    }
  }

  // One component of BuildComponents from its `faces` (OpenMesh indices); `local` maps
  // every face to its index in its component.
  Component MakeComponent(const OMesh& mesh, const std::vector<int>& faces, bool closed,
    const std::vector<std::array<int, 3>>& tris, const std::vector<int>& faceTri,
    std::vector<int>& local) const
  {
    Component c;
    c.Closed = closed;
    for (int f : faces)
    {
      local[static_cast<size_t>(f)] = static_cast<int>(c.Faces.size());
      c.Faces.push_back(tris[static_cast<size_t>(faceTri[static_cast<size_t>(f)])]);
    }
    for (int f : faces)
    {
      for (OMesh::HalfedgeHandle h : mesh.fh_range(mesh.face_handle(static_cast<unsigned>(f))))
      {
        const OMesh::HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
        const int g = mesh.is_boundary(o) ? -1 : mesh.face_handle(o).idx();
        if (g < 0 || f < g) // each edge once
        {
          c.Edges.push_back({ mesh.from_vertex_handle(h).idx(), mesh.to_vertex_handle(h).idx(),
            local[static_cast<size_t>(f)], g < 0 ? -1 : local[static_cast<size_t>(g)] });
        }
      }
    }
    for (const auto& t : c.Faces)
    {
      for (int k = 0; k < 3; ++k)
      {
        const Vec3& p = this->Points[static_cast<size_t>(t[k])];
        for (int a = 0; a < 3; ++a)
        {
          c.Bounds[2 * a] = std::min(c.Bounds[2 * a], p[a]);
          c.Bounds[2 * a + 1] = std::max(c.Bounds[2 * a + 1], p[a]);
        }
      }
    }
    if (closed)
    {
      this->Orient(c);
    }
    if (c.Closed)
    {
      AddAdjacency(c);
    }
    return c;
  }

  // Orientation: a closed mesh with inward normals has negative signed volume; turn it once
  // so that "light-facing" means the outward side (Brabec 2003, ch. 3, §3.2.5).
  void Orient(Component& c) const
  {
    double volume = 0.0;
    const Vec3& ref = this->Points[static_cast<size_t>(c.Faces[0][0])];
    for (const auto& t : c.Faces)
    {
      const Vec3 a = this->Points[static_cast<size_t>(t[0])] - ref;
      const Vec3 b = this->Points[static_cast<size_t>(t[1])] - ref;
      const Vec3 d = this->Points[static_cast<size_t>(t[2])] - ref;
      volume += glm::dot(a, glm::cross(b, d));
    }
    if (volume < 0.0)
    {
      for (auto& t : c.Faces)
      {
        std::swap(t[1], t[2]);
      }
      for (auto& e : c.Edges)
      {
        std::swap(e[0], e[1]);
      }
    }
    // Flat closed surfaces (two coincident sheets) have no inside: treat them as open.
    c.Closed = volume != 0.0;
  }

  // The GL_TRIANGLES_ADJACENCY faces of a closed component (see Component::Adjacency).
  static void AddAdjacency(Component& c)
  {
    std::map<std::pair<int, int>, int> third; // directed edge -> third vertex of its face
    for (const auto& t : c.Faces)
    {
      for (int k = 0; k < 3; ++k)
      {
        third[{ t[k], t[(k + 1) % 3] }] = t[(k + 2) % 3];
      }
    }
    for (const auto& t : c.Faces)
    {
      std::array<int, 6> a;
      for (int k = 0; k < 3; ++k)
      {
        a[static_cast<size_t>(2 * k)] = t[k];
        a[static_cast<size_t>(2 * k + 1)] = third[{ t[(k + 1) % 3], t[k] }];
      }
      c.Adjacency.push_back(a);
    }
  }
};

// The light as the volume builder needs it: a direction toward a directional light or a
// rebased position.
struct VolumeLight
{
  bool Directional = true;
  Vec3 Direction = { 0, 0, 1 };
  Vec3 Position = { 0, 0, 0 };
  double Extrusion = 1.0; // directional: prism length beyond everything

  // Outward facing test value of an oriented triangle: > 0 means it faces the light.
  double Facing(const Vec3& a, const Vec3& b, const Vec3& c) const
  {
    const Vec3 n = glm::cross(b - a, c - a);
    return this->Directional ? glm::dot(n, this->Direction) : glm::dot(n, this->Position - a);
  }
  // Direction of extrusion at v (away from the light), not normalized.
  Vec3 Away(const Vec3& v) const
  {
    return this->Directional ? -this->Direction : (v - this->Position);
  }
};

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

// Volume vertices as drawn (xyzw floats), each with its point's identity: mesh point i is
// NearId(i), its extruded copy FarId(i). Equal identities are equal floats, so the outline
// (VolumeOutline) takes its topology from the identities without welding floats.
struct VolumeStream
{
  std::vector<float> V;
  std::vector<int> Id;

  static int NearId(int i) { return 2 * i; }
  static int FarId(int i) { return 2 * i + 1; }
  void Put(double x, double y, double z, double w, int id)
  {
    this->V.insert(this->V.end(),
      { static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
        static_cast<float>(w) });
    this->Id.push_back(id);
  }
  void Append(const VolumeStream& o)
  {
    this->V.insert(this->V.end(), o.V.begin(), o.V.end());
    this->Id.insert(this->Id.end(), o.Id.begin(), o.Id.end());
  }
};

// One light's volumes as xyzw triangles (Brabec 2003, ch. 3 and 8): light caps, then sides
// and dark caps; and, for the outline (see VolumeOutline), the volumes the geometry stage
// makes for GPU-silhouette components.
struct VolumeBuilder
{
  const Connectivity& Mesh;
  const VolumeLight& Light;
  const double* Box = nullptr; // culling box of the pending samples, null: no culling
  double FarW = 0.0;           // positional lights: w of the extruded copies
  VolumeStream Caps, Sides;
  VolumeStream GPUVolumes;   // GPU components, as the geometry stage draws them
  VolumeStream GPUUncertain; // segments: prism edges of faces it may classify otherwise
  vtkIdType Culled = 0;
  vtkIdType SilhouetteEdges = 0;

  VolumeBuilder(const Connectivity& mesh, const VolumeLight& light)
    : Mesh(mesh)
    , Light(light)
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
  // (no culling there) for the outline alone.
  void Component(const Connectivity::Component& c, bool bothSets, bool gpu)
  {
    const auto& P = this->Mesh.Points;
    VolumeStream& caps = gpu ? this->GPUVolumes : this->Caps;
    VolumeStream& sides = gpu ? this->GPUVolumes : this->Sides;
    // Per face: +1 light-facing set, -1 back-facing set (turned), 0 none. Facing is one
    // decision per face, ties (edge-on) in no set (Brabec 2003, ch. 9). A culled face leaves
    // its set: the sum of the remaining volumes stays a valid count.
    std::vector<signed char> set(c.Faces.size(), 0);
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
        this->CapAndDark(caps, sides, t.data());
        any = true;
      }
      set[i] = si;
    }
    if (!any)
    {
      return;
    }
    for (const auto& e : c.Edges)
    {
      const int p0 = e[0], p1 = e[1];
      const signed char s0 = set[static_cast<size_t>(e[2])];
      const signed char s1 = e[3] >= 0 ? set[static_cast<size_t>(e[3])] : 0;
      if (s0 == s1)
      {
        continue;
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
    }
  }
};

// Where each view sample is counted. The stencil counts along the camera's pixel-centre rays
// and a pixel holds one depth, so a sample is counted at the pixel whose centre ray passes
// through it, found by projecting the sample with the camera, never from its index: a shadow
// pass may hand over several surfaces per pixel (opaque rows, then the nearest translucent
// surface's rows, stacked into one array), and any other arrangement works the same way.
// Samples that meet an occupied pixel go to the next layer of the counting image; each layer
// is one full view, drawn with its own viewport (Brabec 2003, ch. 8: the scene depth once,
// then the volumes; here once per layer). Samples off every pixel centre, or beyond
// MaxLayers, cannot be counted and are traced.
struct SampleLayout
{
  static constexpr int MaxLayers = 4;
  // Largest distance, in pixels, between a sample's projection and its pixel centre: the
  // G-buffer's samples lie on the centres up to float rounding (far below this), while the
  // rasterizer's own snapping is 1/256 pixel (see the edge resolve).
  static constexpr double CentreTolerance = 1.0 / 64.0;

  int Width = 0; // one layer (the view), in pixels
  int Height = 0;
  int Layers = 0;
  std::vector<vtkIdType> Pixel;    // per sample: its pixel in the Width x (Height Layers)
                                   // counting image, -1: not counted
  std::vector<vtkIdType> SampleAt; // per pixel of the counting image: its sample, -1: none
  std::vector<float> DepthStencil; // per pixel: float depth, uint32 (stencil in the low byte)
  vtkIdType Unplaced = 0;          // samples that see a surface but are not counted

  // Pixel of every sample that sees a surface, from `projection` (world -> clip, rebased:
  // the geometry's frame) on a width x height view.
  void Place(const penumbra_light_views::FrameInputs& in, const double projection[4][4], int width,
    int height)
  {
    const vtkIdType n = in.NumberOfSamples;
    const vtkIdType perLayer = static_cast<vtkIdType>(width) * height;
    this->Width = width;
    this->Height = height;
    this->Layers = 0;
    this->Unplaced = 0;
    this->Pixel.assign(static_cast<size_t>(n), -1);
    this->SampleAt.clear();
    for (vtkIdType s = 0; s < n; ++s)
    {
      if (in.Props[s] < 0)
      {
        continue;
      }
      double clip[4];
      for (int r = 0; r < 4; ++r)
      {
        clip[r] = projection[r][3];
        for (int c = 0; c < 3; ++c)
        {
          clip[r] +=
            projection[r][c] * (static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c]);
        }
      }
      const double fx = 0.5 * (clip[0] / clip[3] + 1.0) * width;
      const double fy = 0.5 * (clip[1] / clip[3] + 1.0) * height;
      const double x = std::floor(fx), y = std::floor(fy);
      if (!(clip[3] > 0.0 && x >= 0.0 && y >= 0.0 && x < width && y < height &&
            std::fabs(fx - x - 0.5) <= CentreTolerance &&
            std::fabs(fy - y - 0.5) <= CentreTolerance))
      {
        ++this->Unplaced;
        continue;
      }
      vtkIdType pixel = static_cast<vtkIdType>(y) * width + static_cast<vtkIdType>(x);
      int layer = 0;
      while (layer < this->Layers && this->SampleAt[static_cast<size_t>(pixel)] >= 0)
      {
        ++layer;
        pixel += perLayer;
      }
      if (layer == MaxLayers)
      {
        ++this->Unplaced;
        continue;
      }
      if (layer == this->Layers)
      {
        ++this->Layers;
        this->SampleAt.resize(static_cast<size_t>(perLayer * this->Layers), -1);
      }
      this->SampleAt[static_cast<size_t>(pixel)] = s;
      this->Pixel[static_cast<size_t>(s)] = pixel;
    }
    this->Layers = std::max(this->Layers, 1);
    this->SampleAt.resize(static_cast<size_t>(perLayer * this->Layers), -1);
  }

  // Per counted sample: the depth (`rows`, rebased, reversed) of the point where its pixel-
  // centre ray (`unproject`: NDC -> world) meets the sample's own triangle, so that the own
  // cap is rasterized at (nearly) the same depth.
  void ComputeDepths(const penumbra_light_views::FrameInputs& in, const double rows[4][4],
    const double unproject[4][4], const double origin[3], double scale)
  {
    this->DepthStencil.assign(2 * this->SampleAt.size(), 0.0f);
    const double* tv = in.TriangleVertices;
    const vtkIdType perLayer = static_cast<vtkIdType>(this->Width) * this->Height;
    for (size_t pixel = 0; pixel < this->SampleAt.size(); ++pixel)
    {
      const vtkIdType s = this->SampleAt[pixel];
      if (s < 0)
      {
        continue;
      }
      double p[3];
      for (int c = 0; c < 3; ++c)
      {
        p[c] = static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c];
      }
      const vtkIdType t = in.Triangles[s];
      if (t >= 0 && t < in.NumberOfTriangles)
      {
        const double* a = tv + 9 * t;
        const Vec3 va = { a[0], a[1], a[2] };
        const Vec3 nrm = glm::cross(Vec3(a[3], a[4], a[5]) - va, Vec3(a[6], a[7], a[8]) - va);
        // Pixel-centre ray in world coordinates, rebased.
        const vtkIdType inLayer = static_cast<vtkIdType>(pixel) % perLayer;
        const double x = static_cast<double>(inLayer % this->Width);
        const double y = static_cast<double>(inLayer / this->Width);
        const double ndc[2] = { (x + 0.5) * 2.0 / this->Width - 1.0,
          (y + 0.5) * 2.0 / this->Height - 1.0 };
        double ends[2][3];
        for (int e = 0; e < 2; ++e)
        {
          const double q[4] = { ndc[0], ndc[1], e == 0 ? -1.0 : 1.0, 1.0 };
          double h[4];
          for (int r = 0; r < 4; ++r)
          {
            h[r] = unproject[r][0] * q[0] + unproject[r][1] * q[1] + unproject[r][2] * q[2] +
              unproject[r][3] * q[3];
          }
          for (int c = 0; c < 3; ++c)
          {
            ends[e][c] = h[c] / h[3] - origin[c];
          }
        }
        const Vec3 from = { ends[0][0], ends[0][1], ends[0][2] };
        const Vec3 dir = Vec3(ends[1][0], ends[1][1], ends[1][2]) - from;
        const double denom = glm::dot(nrm, dir);
        if (std::fabs(denom) > 1e-12 * std::sqrt(glm::dot(nrm, nrm) * glm::dot(dir, dir)))
        {
          const double u = glm::dot(nrm, va - from) / denom;
          const Vec3 q = { from[0] + u * dir[0], from[1] + u * dir[1], from[2] + u * dir[2] };
          // Only when the intersection stays near the sample (it is the same surface point
          // up to the G-buffer's float rounding).
          const Vec3 d = q - Vec3(p[0], p[1], p[2]);
          if (glm::dot(d, d) <= 1e-6 * scale * scale)
          {
            p[0] = q.x;
            p[1] = q.y;
            p[2] = q.z;
          }
        }
      }
      double clip[4];
      for (int r = 0; r < 4; ++r)
      {
        clip[r] = rows[r][0] * p[0] + rows[r][1] * p[1] + rows[r][2] * p[2] + rows[r][3];
      }
      this->DepthStencil[2 * pixel] =
        static_cast<float>(std::min(1.0, std::max(0.0, clip[2] / clip[3])));
    }
  }
};

// The volumes' outline as the camera sees it: the volume edges near which the stencil count
// can be wrong. The rasterizer decides a triangle's coverage of a pixel centre on a snapped
// sub-pixel grid (1/256 pixel on llvmpipe), so a centre closer than that to a projected
// triangle edge may be counted on the wrong side of it. Where an edge is shared by two volume
// faces that both face the camera (or both face away) with opposite windings, the two
// triangles lie on either side of the same snapped edge and the rasterizer covers every
// centre with exactly one of them: the count is the same as the exact one. Every other edge
// (a front-facing and a back-facing face meeting: the volume's silhouette from the eye,
// including cap edges; faces seen edge-on; unpaired edges) can change the count across it.
// A shadow narrower than a pixel lies entirely within snapping distance of such edges, so it
// cannot be trusted to the neighbour test (Brabec 2003, ch. 3 and 9 for the silhouette
// notions; here they are applied to the volume itself, from the eye).
struct VolumeOutline
{
  // Pixel centres closer than this (pixels, in x and in y) to an outline edge are traced. It
  // covers the rasterizer's snapping (1/512 pixel of rounding) and the difference between
  // the GPU's float32 vertex transform and the double one here with a wide margin.
  static constexpr double Reach = 1.0 / 32.0;

  std::vector<std::array<double, 4>> Points; // volume vertices, rebased, homogeneous
  std::vector<std::array<int, 3>> Faces;     // volume triangles as drawn (their winding)
  std::vector<std::array<int, 2>> Edges;     // undirected, first < second
  std::vector<int> EdgeStart;                // edge e's incidences: [EdgeStart[e], [e + 1])
  std::vector<int> Incidences;               // 2 face + 1 when the face runs first -> second
  std::vector<std::array<int, 2>> Forced;    // segments always on the outline
  // Per frame.
  std::vector<std::array<double, 3>> Projected; // clip x, y, w of each point
  std::vector<signed char> FaceSide;            // sign of the homogeneous screen area

  void Clear() { *this = VolumeOutline(); }

  // From volume triangles (as drawn: light caps first does not matter) and segments that
  // are always on the outline, with their points' identities (VolumeStream) over a mesh of
  // `meshPoints` points. Points are numbered in order of first use.
  void Build(const VolumeStream& triangles, const VolumeStream& forced, size_t meshPoints)
  {
    this->Clear();
    std::vector<int> number(2 * meshPoints, -1);
    auto point = [&](const VolumeStream& from, size_t vertex)
    {
      int& n = number[static_cast<size_t>(from.Id[vertex])];
      if (n < 0)
      {
        n = static_cast<int>(this->Points.size());
        const float* v = from.V.data() + 4 * vertex;
        this->Points.push_back({ v[0], v[1], v[2], v[3] });
      }
      return n;
    };
    const size_t nt = triangles.Id.size() / 3;
    this->Faces.resize(nt);
    for (size_t t = 0; t < nt; ++t)
    {
      for (int k = 0; k < 3; ++k)
      {
        this->Faces[t][static_cast<size_t>(k)] = point(triangles, 3 * t + static_cast<size_t>(k));
      }
    }
    // The face edges (first, second, incidence) in lexicographic order: bucketed by their
    // first point (a counting sort), then each small bucket sorted.
    std::vector<int> bucket(this->Points.size() + 1, 0);
    for (const auto& f : this->Faces)
    {
      for (int k = 0; k < 3; ++k)
      {
        ++bucket[static_cast<size_t>(std::min(f[static_cast<size_t>(k)], f[(k + 1) % 3])) + 1];
      }
    }
    std::partial_sum(bucket.begin(), bucket.end(), bucket.begin());
    std::vector<std::array<int, 3>> entries(3 * nt);
    std::vector<int> next(bucket.begin(), bucket.end() - 1);
    for (size_t t = 0; t < nt; ++t)
    {
      const auto& f = this->Faces[t];
      for (int k = 0; k < 3; ++k)
      {
        const int a = f[static_cast<size_t>(k)], b = f[static_cast<size_t>((k + 1) % 3)];
        entries[static_cast<size_t>(next[static_cast<size_t>(std::min(a, b))]++)] = {
          std::min(a, b), std::max(a, b), 2 * static_cast<int>(t) + (a < b)
        };
      }
    }
    for (size_t p = 0; p + 1 < bucket.size(); ++p)
    {
      std::sort(entries.begin() + bucket[p], entries.begin() + bucket[p + 1]);
    }
    for (size_t i = 0; i < entries.size(); ++i)
    {
      if (i == 0 || entries[i][0] != entries[i - 1][0] || entries[i][1] != entries[i - 1][1])
      {
        this->Edges.push_back({ entries[i][0], entries[i][1] });
        this->EdgeStart.push_back(static_cast<int>(i));
      }
      this->Incidences.push_back(entries[i][2]);
    }
    this->EdgeStart.push_back(static_cast<int>(entries.size()));
    for (size_t i = 0; i + 1 < forced.Id.size(); i += 2)
    {
      this->Forced.push_back({ point(forced, i), point(forced, i + 1) });
    }
  }

  // Marks in `pixels` (width x height, one view) every pixel whose centre lies within Reach
  // of an outline edge projected with `projection` (rebased world -> clip, VTK's camera).
  void Mark(
    const double projection[4][4], int width, int height, std::vector<unsigned char>& pixels)
  {
    pixels.assign(static_cast<size_t>(width) * static_cast<size_t>(height), 0);
    this->Projected.resize(this->Points.size());
    for (size_t i = 0; i < this->Points.size(); ++i)
    {
      const auto& p = this->Points[i];
      for (int r : { 0, 1, 3 })
      {
        this->Projected[i][r == 3 ? 2 : r] = projection[r][0] * p[0] + projection[r][1] * p[1] +
          projection[r][2] * p[2] + projection[r][3] * p[3];
      }
    }
    // The sign of det(x y w) of a face: its screen winding for any signs of w.
    this->FaceSide.resize(this->Faces.size());
    for (size_t t = 0; t < this->Faces.size(); ++t)
    {
      const auto& a = this->Projected[static_cast<size_t>(this->Faces[t][0])];
      const auto& b = this->Projected[static_cast<size_t>(this->Faces[t][1])];
      const auto& c = this->Projected[static_cast<size_t>(this->Faces[t][2])];
      const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
        a[2] * (b[0] * c[1] - b[1] * c[0]);
      this->FaceSide[t] = det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
    }
    for (size_t e = 0; e < this->Edges.size(); ++e)
    {
      // Faces on the left of first -> second minus those on the right, per winding: the
      // count is continuous across the edge only if both balance (and no face is edge-on).
      int front = 0, back = 0;
      bool onEdge = false;
      for (int i = this->EdgeStart[e]; i < this->EdgeStart[e + 1]; ++i)
      {
        const int side =
          this->FaceSide[static_cast<size_t>(this->Incidences[static_cast<size_t>(i)] / 2)];
        const int forward = this->Incidences[static_cast<size_t>(i)] % 2 ? 1 : -1;
        onEdge = onEdge || side == 0;
        (side > 0 ? front : back) += forward;
      }
      if (onEdge || front != 0 || back != 0)
      {
        this->MarkSegment(this->Edges[e][0], this->Edges[e][1], width, height, pixels);
      }
    }
    for (const auto& f : this->Forced)
    {
      this->MarkSegment(f[0], f[1], width, height, pixels);
    }
  }

  // The segment between two points, clipped in homogeneous coordinates to the view widened
  // by two pixels (which also keeps w > 0), then every pixel centre within Reach of it.
  void MarkSegment(int i0, int i1, int width, int height, std::vector<unsigned char>& pixels) const
  {
    const auto& p = this->Projected[static_cast<size_t>(i0)];
    const auto& q = this->Projected[static_cast<size_t>(i1)];
    double t0 = 0.0, t1 = 1.0;
    const double kx = 1.0 + 4.0 / width, ky = 1.0 + 4.0 / height;
    // Planes k w + x >= 0, k w - x >= 0, the same for y.
    const double planes[4][2] = { { kx, 1.0 }, { kx, -1.0 }, { ky, 1.0 }, { ky, -1.0 } };
    for (int k = 0; k < 4; ++k)
    {
      const int axis = k / 2;
      const double d0 = planes[k][0] * p[2] + planes[k][1] * p[static_cast<size_t>(axis)];
      const double d1 = planes[k][0] * q[2] + planes[k][1] * q[static_cast<size_t>(axis)];
      if (d0 < 0.0 && d1 < 0.0)
      {
        return;
      }
      if (d0 < 0.0)
      {
        t0 = std::max(t0, d0 / (d0 - d1));
      }
      else if (d1 < 0.0)
      {
        t1 = std::min(t1, d0 / (d0 - d1));
      }
    }
    if (!(t0 <= t1))
    {
      return;
    }
    double end[2][2];
    for (int e = 0; e < 2; ++e)
    {
      const double t = e == 0 ? t0 : t1;
      const double w = p[2] + t * (q[2] - p[2]);
      if (!(w > 0.0))
      {
        return; // through the eye: nothing of it is on the view
      }
      end[e][0] = 0.5 * ((p[0] + t * (q[0] - p[0])) / w + 1.0) * width;
      end[e][1] = 0.5 * ((p[1] + t * (q[1] - p[1])) / w + 1.0) * height;
    }
    const double r = Reach;
    const double ylo = std::min(end[0][1], end[1][1]), yhi = std::max(end[0][1], end[1][1]);
    const int rowFirst = std::max(0, static_cast<int>(std::ceil(ylo - r - 0.5)));
    const int rowLast = std::min(height - 1, static_cast<int>(std::floor(yhi + r - 0.5)));
    const double dy = end[1][1] - end[0][1];
    for (int y = rowFirst; y <= rowLast; ++y)
    {
      // The part of the segment within Reach of the row's centre line, in x.
      double ta = 0.0, tb = 1.0;
      if (std::fabs(dy) > 1e-12)
      {
        ta = (y + 0.5 - r - end[0][1]) / dy;
        tb = (y + 0.5 + r - end[0][1]) / dy;
        if (ta > tb)
        {
          std::swap(ta, tb);
        }
        ta = std::max(ta, 0.0);
        tb = std::min(tb, 1.0);
        if (ta > tb)
        {
          continue;
        }
      }
      const double xa = end[0][0] + ta * (end[1][0] - end[0][0]);
      const double xb = end[0][0] + tb * (end[1][0] - end[0][0]);
      const int first = std::max(0, static_cast<int>(std::ceil(std::min(xa, xb) - r - 0.5)));
      const int last =
        std::min(width - 1, static_cast<int>(std::floor(std::max(xa, xb) + r - 0.5)));
      for (int x = first; x <= last; ++x)
      {
        pixels[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = 1;
      }
    }
  }
};

// Which pending samples (`state`) to trace: those the stencil could not count (see
// SampleLayout) and, with the edge resolve (`outline` given: one view's pixels within reach of
// the volumes' outline, see VolumeOutline), those whose answer may hang on the rasterizer's
// rounding: on the outline, next to a neighbour with another result or next to a pixel that
// is not counted (background, facing away: outlines and terminators), or grazed by the
// light. The outline alone covers every snapping error; the neighbour test stays for the
// depth side of the count (a receiver meeting a volume face within float depth rounding).
// Returns the number of samples marked in `mask`.
vtkIdType MarkTraced(const SampleLayout& layout, const penumbra_light_views::FrameInputs& in,
  const VolumeLight& light, const std::vector<unsigned char>& state, const float* vis,
  const unsigned char* outline, unsigned char* mask)
{
  const vtkIdType perLayer = static_cast<vtkIdType>(layout.Width) * layout.Height;
  vtkIdType traced = 0;
  for (vtkIdType s = 0; s < in.NumberOfSamples; ++s)
  {
    mask[s] = 0;
    if (state[static_cast<size_t>(s)] != Pending)
    {
      continue;
    }
    const vtkIdType pixel = layout.Pixel[static_cast<size_t>(s)];
    const bool resolve = outline != nullptr;
    bool edge = pixel < 0 || (resolve && outline[pixel % perLayer]);
    const vtkIdType layerStart = pixel - pixel % perLayer;
    const int x = static_cast<int>(pixel % perLayer % layout.Width);
    const int y = static_cast<int>(pixel % perLayer / layout.Width);
    for (int dy = -1; dy <= 1 && resolve && !edge; ++dy)
    {
      for (int dx = -1; dx <= 1 && !edge; ++dx)
      {
        const int nx = x + dx, ny = y + dy;
        if (nx < 0 || ny < 0 || nx >= layout.Width || ny >= layout.Height)
        {
          continue;
        }
        const vtkIdType t = layout.SampleAt[static_cast<size_t>(
          layerStart + static_cast<vtkIdType>(ny) * layout.Width + nx)];
        // A background neighbour: an outline. A facing-away one: the light's terminator,
        // where the sample's own caster has a silhouette edge and its side quads start.
        edge = t < 0 || state[static_cast<size_t>(t)] != Pending || vis[t] != vis[s];
      }
    }
    if (resolve && !edge)
    {
      // A light grazing the surface (the N.L ~ 0 case): the shadow boundary then slides
      // along the surface with every rounding of the sample (the G-buffer's float position
      // vs. the exact plane the stencil tests), so only a ray decides it as the reference
      // does.
      const float* nn = in.Normals + 3 * s;
      double l[3];
      for (int c = 0; c < 3; ++c)
      {
        l[c] = light.Directional
          ? light.Direction[c]
          : light.Position[c] - (static_cast<double>(in.Positions[3 * s + c]) + in.Shift[c]);
      }
      const double len = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
      const double cosine = (nn[0] * l[0] + nn[1] * l[1] + nn[2] * l[2]) / len;
      edge = !(cosine > GrazingCosine);
    }
    mask[s] = edge ? 1 : 0;
    traced += edge;
  }
  return traced;
}
}

struct vtkPenumbraShadowVolumeShadows::Internals
{
  vtkWeakPointer<vtkOpenGLRenderWindow> Window;
  GLuint Framebuffer = 0;
  GLuint DepthStencil = 0;
  GLuint MaskTexture = 0; // RGBA8: one light per channel, 0 = shadow (Brabec 2003, ch. 8)
  GLuint VertexArray = 0;
  GLuint Query = 0;
  GLuint PointArray = 0; // GPU silhouettes: VAO of the welded points
  GLuint PointBuffer = 0;
  bool PointsUploaded = false;
  int Width = 0;
  int Height = 0;

  // Connectivity cache.
  Connectivity Mesh;
  bool HaveMesh = false;
  vtkPenumbraSceneGeometry* Geometry = nullptr;
  vtkMTimeType GeometryTime = 0;
  vtkMTimeType FlagsTime = 0;
  double Origin[3] = { 0, 0, 0 };
  bool BuiltWithSilhouettes = true;

  // Volume cache, one entry per light (several lights render every frame): rebuilt when the
  // light, the connectivity, the sample box (with culling) or the options change. Each set
  // keeps its own GL buffers, so lights that do not move upload nothing.
  struct VolumeSet
  {
    std::vector<double> Key;
    double Box[6] = { 0, 0, 0, 0, 0, 0 }; // with Cull: the box it was culled to (CullMargin)
    std::uint64_t Stamp = 0;              // last use: the least recently used set is evicted
    std::vector<float> Vertices;          // xyzw, caps first
    GLsizei CapVertices = 0;
    GLsizei AllVertices = 0;
    std::vector<GLuint> AdjacencyIndices; // GPU silhouettes
    GLsizei AdjacencyCount = 0;
    vtkIdType SilhouetteEdges = 0;
    vtkIdType Culled = 0;
    double FarW = 0.0;          // positional lights: w of the extruded copies (PositionalFarW)
    GLuint Buffer = 0;          // vertices, uploaded on first use
    GLuint AdjacencyBuffer = 0; // adjacency indices, uploaded on first use
    // With the edge resolve: the volumes' edges, for the outline from the camera.
    VolumeOutline Outline;
  };
  // More sets than lights per mask: a group never evicts a set it is using.
  static constexpr size_t MaxVolumeSets = 8;
  std::vector<std::unique_ptr<VolumeSet>> Volumes;
  std::uint64_t Clock = 0;
  std::vector<GLuint> Garbage; // buffers of evicted sets, deleted when the context is current

  // Per-frame camera data shared by every light (see ComputeGroup).
  std::vector<double> DepthKey;
  double Rows[4][4] = {};
  double Projection[4][4] = {};             // world -> clip as VTK draws it, rebased (x, y, w rows)
  std::vector<unsigned char> OutlinePixels; // one light's outline (VolumeOutline::Mark)
  bool DepthUploaded = false;
  SampleLayout Layout; // where each sample is counted, and the depths
  std::vector<unsigned char> MaskPixels;
  vtkNew<vtkUnsignedCharArray> Mask;

  // One light's volumes into `build` (see VolumeBuilder); `box` culls (null: no culling),
  // `gpu` leaves closed components to the geometry stage, `outline` also prepares the
  // outline of every volume for the edge resolve.
  static void BuildVolumes(VolumeSet& build, const Connectivity& mesh, const VolumeLight& vl,
    const double* box, const double bounds[6], bool gpu, bool outline)
  {
    VolumeBuilder builder(mesh, vl);
    builder.Box = box;
    builder.FarW = vl.Directional ? 0.0 : PositionalFarW(mesh, vl, bounds);
    build.FarW = builder.FarW;
    for (const auto& t : mesh.Loose)
    {
      builder.PerTriangle(t);
    }
    for (const auto& c : mesh.Components)
    {
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
      builder.Component(c, bothSets, gpu && !bothSets);
    }
    build.CapVertices = static_cast<GLsizei>(builder.Caps.V.size() / 4);
    build.AllVertices = static_cast<GLsizei>((builder.Caps.V.size() + builder.Sides.V.size()) / 4);
    if (outline)
    {
      // Every volume triangle the outline is made of: the geometry stage's, then the drawn.
      builder.GPUVolumes.Append(builder.Caps);
      builder.GPUVolumes.Append(builder.Sides);
      build.Outline.Build(builder.GPUVolumes, builder.GPUUncertain, mesh.Points.size());
    }
    build.Vertices.swap(builder.Caps.V);
    build.Vertices.insert(build.Vertices.end(), builder.Sides.V.begin(), builder.Sides.V.end());
    build.SilhouetteEdges = gpu && !build.AdjacencyIndices.empty() ? -1 : builder.SilhouetteEdges;
    build.AdjacencyCount = static_cast<GLsizei>(build.AdjacencyIndices.size());
    build.Culled = builder.Culled;
  }

  void Evict(size_t i)
  {
    for (GLuint b : { this->Volumes[i]->Buffer, this->Volumes[i]->AdjacencyBuffer })
    {
      if (b)
      {
        this->Garbage.push_back(b);
      }
    }
    this->Volumes.erase(this->Volumes.begin() + static_cast<std::ptrdiff_t>(i));
  }

  void ClearVolumes()
  {
    while (!this->Volumes.empty())
    {
      this->Evict(this->Volumes.size() - 1);
    }
  }

  void Release(vtkWindow* window)
  {
    if (this->Window && (!window || window == this->Window))
    {
      this->Window->MakeCurrent();
      this->ClearVolumes();
      this->CollectGarbage();
      if (this->Framebuffer)
      {
        glDeleteFramebuffers(1, &this->Framebuffer);
        glDeleteTextures(1, &this->DepthStencil);
        glDeleteTextures(1, &this->MaskTexture);
        glDeleteVertexArrays(1, &this->VertexArray);
        glDeleteQueries(1, &this->Query);
        glDeleteVertexArrays(1, &this->PointArray);
        glDeleteBuffers(1, &this->PointBuffer);
      }
    }
    for (auto& set : this->Volumes)
    {
      set->Buffer = set->AdjacencyBuffer = 0; // their context is gone
    }
    this->Garbage.clear();
    this->Framebuffer = this->DepthStencil = this->MaskTexture = this->VertexArray = 0;
    this->Query = this->PointArray = this->PointBuffer = 0;
    this->PointsUploaded = false;
    this->Width = this->Height = 0;
    this->DepthUploaded = false;
    this->Window = nullptr;
  }

  void CollectGarbage()
  {
    if (!this->Garbage.empty())
    {
      glDeleteBuffers(static_cast<GLsizei>(this->Garbage.size()), this->Garbage.data());
      this->Garbage.clear();
    }
  }

  // The counting framebuffer: DEPTH32F_STENCIL8 and the RGBA8 mask. False when incomplete.
  // Bound through vtkOpenGLState: the caller's PopFramebufferBindings() restores from its
  // cache, so a binding made behind its back would leave the wrong framebuffer bound.
  bool Allocate(int w, int h, vtkOpenGLState* ostate)
  {
    if (this->Framebuffer && this->Width == w && this->Height == h)
    {
      return true;
    }
    if (!this->Framebuffer)
    {
      glGenFramebuffers(1, &this->Framebuffer);
      glGenTextures(1, &this->DepthStencil);
      glGenTextures(1, &this->MaskTexture);
      glGenVertexArrays(1, &this->VertexArray);
      glGenQueries(1, &this->Query);
      glGenVertexArrays(1, &this->PointArray);
      glGenBuffers(1, &this->PointBuffer);
    }
    glBindTexture(GL_TEXTURE_2D, this->DepthStencil);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH32F_STENCIL8, w, h, 0, GL_DEPTH_STENCIL,
      GL_FLOAT_32_UNSIGNED_INT_24_8_REV, nullptr);
    glBindTexture(GL_TEXTURE_2D, this->MaskTexture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    this->DepthUploaded = false;
    glBindTexture(GL_TEXTURE_2D, 0);
    ostate->vtkglBindFramebuffer(GL_FRAMEBUFFER, this->Framebuffer);
    glFramebufferTexture2D(
      GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, this->DepthStencil, 0);
    glFramebufferTexture2D(
      GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, this->MaskTexture, 0);
    ostate->vtkglDrawBuffer(GL_COLOR_ATTACHMENT0);
    ostate->vtkglReadBuffer(GL_COLOR_ATTACHMENT0);
    const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    this->Width = w;
    this->Height = h;
    return complete;
  }

  // ---- One ComputeGroup call, in named phases (ComputeGroup runs them in order).
  // One light of the group.
  struct Job
  {
    vtkLight* Light = nullptr;
    vtkFloatArray* Visibility = nullptr;
    float* Vis = nullptr;
    penumbra_light_views::FrameInputs In;
    std::vector<unsigned char> State;
    VolumeLight VL;
    VolumeSet* Volumes = nullptr; // null: nothing to count (no pending sample)
    bool ZPass = false;
    int Channel = -1; // its channel in the mask
  };

  // What the phases of one call share.
  struct Group
  {
    vtkRenderer* Renderer = nullptr;
    vtkPenumbraSceneGeometry* Geometry = nullptr;
    vtkPenumbraViewSamples* Samples = nullptr;
    std::vector<Job> Jobs;
    // What depends on the samples, the geometry and the window only (ReadShared): the same
    // for every job, so the first job's.
    const penumbra_light_views::FrameInputs* In = nullptr;
    vtkOpenGLRenderWindow* Window = nullptr;
    vtkIdType N = 0;
    int Width = 0;
    int Height = 0;
    vtkCamera* Camera = nullptr;
    double Scale = 1.0; // scene scale (UpdateConnectivity)
    double RebasedBounds[6] = { 0, 0, 0, 0, 0, 0 };
    int Counted = 0; // lights with samples to count, one mask channel each
    bool Parallel = false;
    Clock::time_point StencilStart; // sample depths and counting (StencilTimeMs)
    vtkShaderProgram* Program = nullptr;
    vtkShaderProgram* GSProgram = nullptr; // null: no GPU silhouettes in this group
    vtkShaderProgram* MaskProgram = nullptr;
  };

  // ---- Input checks (shared with the other map-based techniques), per light: a light that
  // cannot be shadowed here (an area light, say) fails alone.
  static void ReadJobs(vtkPenumbraShadowVolumeShadows& self, Group& g, vtkLight* const* lights,
    vtkFloatArray* const* visibilities, int count)
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
  static const char* ReadShared(Group& g)
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
  void UpdateConnectivity(vtkPenumbraShadowVolumeShadows& self, Group& g)
  {
    vtkPenumbraSceneGeometry* geometry = g.Geometry;
    const auto connectivityStart = Clock::now();
    {
      double origin[3];
      geometry->GetOrigin(origin);
      if (!this->HaveMesh || this->Geometry != geometry ||
        this->GeometryTime != geometry->GetGeometryTime() ||
        this->FlagsTime != geometry->GetFlagsTime() ||
        !std::equal(origin, origin + 3, this->Origin) ||
        this->BuiltWithSilhouettes != self.Silhouettes)
      {
        this->Mesh.Build(geometry, self.Silhouettes);
        this->HaveMesh = true;
        this->Geometry = geometry;
        this->GeometryTime = geometry->GetGeometryTime();
        this->FlagsTime = geometry->GetFlagsTime();
        std::copy(origin, origin + 3, this->Origin);
        this->BuiltWithSilhouettes = self.Silhouettes;
        this->Volumes.clear();
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
  void PrepareLights(vtkPenumbraShadowVolumeShadows& self, Group& g)
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
  bool PrepareLight(vtkPenumbraShadowVolumeShadows& self, const Group& g, Job& job)
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
    self.NumberOfVolumeTriangles += vs.AllVertices / 3;
    return true;
  }

  // Box of the pending samples in the geometry's frame (culling, extrusion length), grown
  // by the float rounding of the samples (they are float32).
  static void PendingBox(const penumbra_light_views::FrameInputs& in,
    const std::vector<unsigned char>& state, double scale, double box[6])
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

  // A set of volumes is culled to the pending box grown by a fifth of its largest side
  // (penumbra_light_views::KeptBox): culling keeps every volume that reaches that box, so the
  // set serves every later pending box inside it with the same counts, and outlives the
  // small camera moves of an interaction instead of being rebuilt every frame.
  static constexpr double CullMargin = 0.2;

  // The volume cache: a set of `vl` whose culling box holds the pending `box`, built when
  // missing (evicting the least recently used set when full), stamped as used now.
  VolumeSet* FindVolumes(vtkPenumbraShadowVolumeShadows& self, const Group& g,
    const VolumeLight& vl, const double box[6])
  {
    const auto volumeStart = Clock::now();
    std::vector<double> key = { vl.Directional ? 1.0 : 0.0, vl.Direction[0], vl.Direction[1],
      vl.Direction[2], vl.Position[0], vl.Position[1], vl.Position[2], vl.Extrusion,
      self.Cull ? 1.0 : 0.0, self.GPUSilhouettes ? 1.0 : 0.0, self.Resolve ? 1.0 : 0.0 };
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

  // ---- Sample depths. The camera matrix and the sample depths depend on the samples and the
  // camera only: one computation and one upload per frame serve every light (Brabec 2003,
  // ch. 8: the scene depth once, then per light a cleared stencil and its volumes).
  void ComputeSampleDepths(vtkPenumbraShadowVolumeShadows& self, Group& g)
  {
    g.StencilStart = Clock::now();
    vtkCamera* camera = g.Camera;
    vtkPenumbraViewSamples* samples = g.Samples;
    vtkPenumbraSceneGeometry* geometry = g.Geometry;
    const int width = g.Width;
    g.Parallel = camera->GetParallelProjection() != 0;
    // The view's aspect is the renderer's: the samples may hold several surfaces per pixel
    // (see SampleLayout), so their own height says nothing about it. Samples the pass did not
    // make (a renderer without a window) are taken as one image of the view.
    const double aspect = g.Renderer->GetRenderWindow() && g.Renderer->GetTiledAspectRatio() > 0.0
      ? g.Renderer->GetTiledAspectRatio()
      : static_cast<double>(width) / std::max(g.Height, 1);
    const int viewHeight = std::max(1, static_cast<int>(std::lround(width / aspect)));
    auto address = [](const void* p)
    { return static_cast<double>(reinterpret_cast<std::uintptr_t>(p)); };
    const std::vector<double> depthKey = { address(samples),
      static_cast<double>(samples->GetMTime()),
      static_cast<double>(samples->GetPositions()->GetMTime()),
      static_cast<double>(samples->GetPropIndices()->GetMTime()),
      static_cast<double>(samples->GetTriangleIds()->GetMTime()),
      static_cast<double>(camera->GetMTime()), address(geometry),
      static_cast<double>(geometry->GetGeometryTime()), this->Origin[0], this->Origin[1],
      this->Origin[2], static_cast<double>(width), static_cast<double>(viewHeight),
      static_cast<double>(g.N) };
    if (depthKey != this->DepthKey)
    {
      this->DepthKey = depthKey;
      this->DepthUploaded = false;
      ++self.NumberOfDepthComputations;
      double unproject[4][4];
      double projection[4][4]; // world -> clip as VTK draws it, rebased
      this->CameraRows(camera, aspect, g.Parallel, *g.In, unproject, projection);
      this->Layout.Place(*g.In, projection, width, viewHeight);
      this->Layout.ComputeDepths(*g.In, this->Rows, unproject, this->Origin, g.Scale);
    }

    self.SampleDepthTimeMs += ElapsedMs(g.StencilStart);
  }

  // Camera: VTK's world -> clip for this image into `projection` (and Projection) and its
  // inverse into `unproject`, rebased; Rows the same with a reversed float depth fitted to the
  // samples.
  void CameraRows(vtkCamera* camera, double aspect, bool parallel,
    const penumbra_light_views::FrameInputs& in, double unproject[4][4], double projection[4][4])
  {
    double(&rows)[4][4] = this->Rows;
    const double* shift = in.Shift;
    const vtkIdType n = in.NumberOfSamples;
    vtkMatrix4x4* m = camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1);
    vtkNew<vtkMatrix4x4> inverse;
    vtkMatrix4x4::Invert(m, inverse);
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        unproject[r][c] = inverse->GetElement(r, c);
      }
    }
    vtkMatrix4x4* view = camera->GetViewTransformMatrix();
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        rows[r][c] = m->GetElement(r, c);
      }
    }
    // Rebase: x_world = x_rebased + origin.
    for (int r = 0; r < 4; ++r)
    {
      rows[r][3] +=
        rows[r][0] * this->Origin[0] + rows[r][1] * this->Origin[1] + rows[r][2] * this->Origin[2];
    }
    std::copy(&rows[0][0], &rows[0][0] + 16, &projection[0][0]);
    std::copy(&rows[0][0], &rows[0][0] + 16, &this->Projection[0][0]);
    // Eye depth (positive in front) as a row of the rebased frame.
    double eye[4];
    for (int c = 0; c < 4; ++c)
    {
      eye[c] = -view->GetElement(2, c);
    }
    eye[3] += eye[0] * this->Origin[0] + eye[1] * this->Origin[1] + eye[2] * this->Origin[2];
    double nearest = VTK_DOUBLE_MAX, farthest = 0.0;
    for (vtkIdType s = 0; s < n; ++s)
    {
      if (in.Props[s] >= 0)
      {
        double z = eye[3];
        for (int c = 0; c < 3; ++c)
        {
          z += eye[c] * (static_cast<double>(in.Positions[3 * s + c]) + shift[c]);
        }
        nearest = std::min(nearest, z);
        farthest = std::max(farthest, z);
      }
    }
    if (!parallel)
    {
      // d = nearPlane / eye depth (w row unchanged): 1 at half the nearest sample, 0 at
      // infinity; depth clamp keeps what lies closer.
      const double nearPlane = std::max(0.5 * nearest, 1e-9 * (1.0 + std::fabs(farthest)));
      // z_clip = nearPlane * w_vertex: a point at infinity (w = 0) gets depth 0.
      rows[2][0] = rows[2][1] = rows[2][2] = 0.0;
      rows[2][3] = nearPlane;
    }
    else
    {
      const double margin = 0.25 * (farthest - nearest) + 1e-6 * (1.0 + std::fabs(farthest));
      const double zn = nearest - margin, zf = farthest + margin;
      // d = (zf - eye depth) / (zf - zn).
      for (int c = 0; c < 4; ++c)
      {
        rows[2][c] = (c == 3 ? zf : 0.0) - eye[c];
        rows[2][c] /= (zf - zn);
      }
    }
  }

  // ---- z-pass needs a camera outside every volume (Brabec 2003, ch. 3, §3.2.5); prove it for
  // perspective cameras from the volumes actually drawn.
  void ChooseMethods(vtkPenumbraShadowVolumeShadows& self, Group& g)
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
        const std::vector<float>& V = vs.Vertices;
        for (GLsizei i = 0; i + 2 < vs.CapVertices && outside; i += 3)
        {
          Vec3 v[3];
          for (int k = 0; k < 3; ++k)
          {
            const float* f = V.data() + 4 * static_cast<size_t>(i + k);
            v[k] = { f[0], f[1], f[2] };
          }
          outside = !SegmentMayTouch(vl, eye, v, tol);
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

  // ---- GL: the context, the features the counting needs and its shaders. Null, or why the
  // group fails.
  const char* ReadyGL(Group& g)
  {
    vtkOpenGLRenderWindow* win = g.Window;
    win->MakeCurrent();
    if (this->Window && this->Window != win)
    {
      this->Release(nullptr);
    }
    this->Window = win;
    if (!HasDepthClamp())
    {
      return "depth clamping (OpenGL 3.2 or ARB_depth_clamp) is required";
    }
    if (!glClipControl)
    {
      return "glClipControl (OpenGL 4.5 or ARB_clip_control) is required for the "
             "reversed float depth";
    }
    g.Program = ReadyProgram(win, vtkPenumbraShadowVolumeVS, vtkPenumbraShadowVolumeFS, "");
    if (!g.Program)
    {
      return "the shadow volume shaders do not compile or link";
    }
    if (std::any_of(g.Jobs.begin(), g.Jobs.end(),
          [](const Job& j) { return j.Volumes && j.Volumes->AdjacencyCount > 0; }))
    {
      g.GSProgram = ReadyProgram(win, vtkPenumbraShadowVolumeAdjacencyVS, vtkPenumbraShadowVolumeFS,
        vtkPenumbraShadowVolumeAdjacencyGS);
      if (!g.GSProgram)
      {
        return "GPU silhouettes need a geometry shader with triangles_adjacency input, "
               "which does not compile or link here; use CPU silhouettes";
      }
    }
    g.MaskProgram =
      ReadyProgram(win, vtkPenumbraShadowVolumeMaskVS, vtkPenumbraShadowVolumeMaskFS, "");
    if (!g.MaskProgram)
    {
      return "the shadow mask shaders do not compile or link";
    }
    this->CollectGarbage();
    return nullptr;
  }

  // The program of these shaders, compiled and linked; null if it is not.
  static vtkShaderProgram* ReadyProgram(
    vtkOpenGLRenderWindow* win, const char* vs, const char* fs, const char* gs)
  {
    vtkShaderProgram* program = win->GetShaderCache()->ReadyShaderProgram(vs, fs, gs);
    return program && program->GetCompiled() ? program : nullptr;
  }

  // Depth clamping (GL 3.2 core, or ARB_depth_clamp) keeps the volumes' far parts.
  static bool HasDepthClamp()
  {
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    bool clamp = major * 10 + minor >= 32;
    GLint extensions = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &extensions);
    for (GLint i = 0; i < extensions && !clamp; ++i)
    {
      const GLubyte* name = glGetStringi(GL_EXTENSIONS, static_cast<GLuint>(i));
      clamp = name && std::strcmp(reinterpret_cast<const char*>(name), "GL_ARB_depth_clamp") == 0;
    }
    return clamp;
  }

  // ---- Brabec 2003, ch. 8: the scene depth once, then per light a cleared stencil, its
  // volumes and a copy of "count != 0" into its channel of one RGBA mask; one read-back per
  // mask. False when the counting framebuffer is incomplete.
  bool CountInStencil(vtkPenumbraShadowVolumeShadows& self, const Group& g)
  {
    vtkOpenGLState* ostate = g.Window->GetState();
    ostate->PushFramebufferBindings();
    bool complete;
    {
      vtkOpenGLState::ScopedglEnableDisable blend(ostate, GL_BLEND);
      vtkOpenGLState::ScopedglEnableDisable depthTest(ostate, GL_DEPTH_TEST);
      vtkOpenGLState::ScopedglEnableDisable scissor(ostate, GL_SCISSOR_TEST);
      vtkOpenGLState::ScopedglEnableDisable cull(ostate, GL_CULL_FACE);
      vtkOpenGLState::ScopedglEnableDisable stencilTest(ostate, GL_STENCIL_TEST);
      vtkOpenGLState::ScopedglViewport viewport(ostate);
      vtkOpenGLState::ScopedglDepthFunc depthFunc(ostate);
      vtkOpenGLState::ScopedglDepthMask depthMask(ostate);
      vtkOpenGLState::ScopedglColorMask colorMask(ostate);
      const SampleLayout& layout = this->Layout;
      const int channels = g.Counted == 1 ? 1 : 4;
      this->MaskPixels.resize(static_cast<size_t>(channels) * layout.SampleAt.size());
      complete = this->Allocate(layout.Width, layout.Height, ostate);
      if (complete)
      {
        this->CountLayers(self, g, ostate);
      }
    }
    ostate->PopFramebufferBindings();
    return complete;
  }

  // CountInStencil in its complete framebuffer, inside its state savers: every layer.
  void CountLayers(vtkPenumbraShadowVolumeShadows& self, const Group& g, vtkOpenGLState* ostate)
  {
    const SampleLayout& layout = this->Layout;
    ostate->vtkglBindFramebuffer(GL_FRAMEBUFFER, this->Framebuffer);
    ostate->vtkglStencilMask(0xff);

    ostate->vtkglDisable(GL_BLEND);
    ostate->vtkglDisable(GL_SCISSOR_TEST);
    ostate->vtkglDisable(GL_CULL_FACE);
    ostate->vtkglEnable(GL_STENCIL_TEST);
    ostate->vtkglViewport(0, 0, layout.Width, layout.Height);
    ostate->vtkglDepthMask(GL_FALSE);
    const GLboolean hadClamp = glIsEnabled(GL_DEPTH_CLAMP);
    glEnable(GL_DEPTH_CLAMP);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);

    float matrix[16];
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        matrix[4 * c + r] = static_cast<float>(this->Rows[r][c]);
      }
    }
    const GLint loc = glGetAttribLocation(g.Program->GetHandle(), "vertexRebased");
    const GLint pointLoc =
      g.GSProgram ? glGetAttribLocation(g.GSProgram->GetHandle(), "vertexRebased") : -1;
    if (g.GSProgram && !this->PointsUploaded)
    {
      this->UploadPoints(pointLoc);
    }

    // One pass per layer of samples (see SampleLayout), each in the same view-sized
    // framebuffer.
    for (int layer = 0; layer < layout.Layers; ++layer)
    {
      this->CountLayer(self, g, ostate, layer, matrix, loc);
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindVertexArray(0);

    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    if (!hadClamp)
    {
      glDisable(GL_DEPTH_CLAMP);
    }
    ostate->vtkglStencilOpSeparate(GL_FRONT_AND_BACK, GL_KEEP, GL_KEEP, GL_KEEP);
    ostate->vtkglStencilFunc(GL_ALWAYS, 0, 0xff);

    ++self.NumberOfMasks;
  }

  // GPU silhouettes: the welded points, once per connectivity.
  void UploadPoints(GLint pointLoc)
  {
    std::vector<float> points;
    points.reserve(3 * this->Mesh.Points.size());
    for (const Vec3& p : this->Mesh.Points)
    {
      points.insert(points.end(),
        { static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]) });
    }
    glBindVertexArray(this->PointArray);
    glBindBuffer(GL_ARRAY_BUFFER, this->PointBuffer);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(points.size() * sizeof(float)),
      points.empty() ? nullptr : points.data(), GL_STATIC_DRAW);
    if (pointLoc >= 0)
    {
      glEnableVertexAttribArray(static_cast<GLuint>(pointLoc));
      glVertexAttribPointer(static_cast<GLuint>(pointLoc), 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
    this->PointsUploaded = true;
  }

  // ---- One layer of samples: its depth, every counted light into its channel, one read-back
  // for the whole group (the red channel alone for a single light).
  void CountLayer(vtkPenumbraShadowVolumeShadows& self, const Group& g, vtkOpenGLState* ostate,
    int layer, float matrix[16], GLint loc)
  {
    const SampleLayout& layout = this->Layout;
    const size_t perLayer = static_cast<size_t>(layout.Width) * static_cast<size_t>(layout.Height);
    const int channels = g.Counted == 1 ? 1 : 4;
    bool stencilClear = false;
    if (!this->DepthUploaded || layout.Layers > 1)
    {
      // This layer's depth and a zero stencil in one upload.
      glBindTexture(GL_TEXTURE_2D, this->DepthStencil);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, layout.Width, layout.Height, GL_DEPTH_STENCIL,
        GL_FLOAT_32_UNSIGNED_INT_24_8_REV,
        layout.DepthStencil.data() + 2 * perLayer * static_cast<size_t>(layer));
      glBindTexture(GL_TEXTURE_2D, 0);
      this->DepthUploaded = layout.Layers == 1; // one layer: kept for the next call
      stencilClear = true;
    }
    // Every channel starts lit.
    ostate->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const GLfloat lit[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
    glClearBufferfv(GL_COLOR, 0, lit);
    for (const Job& job : g.Jobs)
    {
      if (!job.Volumes)
      {
        continue;
      }
      if (stencilClear)
      {
        stencilClear = false; // the upload left it zero
      }
      else
      {
        const GLint zero = 0;
        glClearBufferiv(GL_STENCIL, 0, &zero);
      }
      this->CountLight(self, g, ostate, job, matrix, loc);
    }
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, layout.Width, layout.Height, channels == 1 ? GL_RED : GL_RGBA,
      GL_UNSIGNED_BYTE,
      this->MaskPixels.data() +
        static_cast<size_t>(channels) * perLayer * static_cast<size_t>(layer));
  }

  // One light on a cleared stencil: its volumes counted (z-pass or Carmack's reverse), then
  // "count != 0" into its channel.
  void CountLight(vtkPenumbraShadowVolumeShadows& self, const Group& g, vtkOpenGLState* ostate,
    const Job& job, float matrix[16], GLint loc)
  {
    VolumeSet& vs = *job.Volumes;
    const VolumeLight& vl = job.VL;
    ostate->vtkglEnable(GL_DEPTH_TEST);
    ostate->vtkglColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    // Reversed depth: nearer is greater.
    ostate->vtkglDepthFunc(GL_GREATER);
    ostate->vtkglStencilMask(0xff);
    ostate->vtkglStencilFunc(GL_ALWAYS, 0, 0xff);
    if (job.ZPass)
    {
      // Count faces in front of the sample: entering +1, leaving -1.
      ostate->vtkglStencilOpSeparate(GL_FRONT, GL_KEEP, GL_KEEP, GL_INCR_WRAP);
      ostate->vtkglStencilOpSeparate(GL_BACK, GL_KEEP, GL_KEEP, GL_DECR_WRAP);
    }
    else
    {
      // Carmack's reverse: count faces behind the sample (depth fails).
      ostate->vtkglStencilOpSeparate(GL_FRONT, GL_KEEP, GL_DECR_WRAP, GL_KEEP);
      ostate->vtkglStencilOpSeparate(GL_BACK, GL_KEEP, GL_INCR_WRAP, GL_KEEP);
    }

    this->BindVolumeBuffers(g, vs, loc);
    glBeginQuery(GL_SAMPLES_PASSED, this->Query);
    this->DrawVolumes(g, vs, vl, matrix, static_cast<float>(1.0 - self.CapOffset));
    glEndQuery(GL_SAMPLES_PASSED);
    GLuint passed = 0;
    glGetQueryObjectuiv(this->Query, GL_QUERY_RESULT, &passed);
    self.NumberOfPassedFragments += static_cast<vtkIdType>(passed);
    if (self.MeasureFill)
    {
      // Every rasterized volume fragment, with the stencil left as counted.
      ostate->vtkglDepthFunc(GL_ALWAYS);
      ostate->vtkglStencilMask(0x00);
      glBeginQuery(GL_SAMPLES_PASSED, this->Query);
      this->DrawVolumes(g, vs, vl, matrix, 1.0f);
      glEndQuery(GL_SAMPLES_PASSED);
      GLuint fill = 0;
      glGetQueryObjectuiv(this->Query, GL_QUERY_RESULT, &fill);
      self.NumberOfFillFragments += static_cast<vtkIdType>(fill);
      ostate->vtkglStencilMask(0xff);
    }

    // Step 3 of ch. 8: 0 into this light's channel where the count is not zero (the
    // count wraps modulo 256).
    ostate->vtkglDisable(GL_DEPTH_TEST);
    ostate->vtkglStencilOpSeparate(GL_FRONT_AND_BACK, GL_KEEP, GL_KEEP, GL_KEEP);
    ostate->vtkglStencilFunc(GL_NOTEQUAL, 0, 0xff);
    ostate->vtkglColorMask(job.Channel == 0, job.Channel == 1, job.Channel == 2, job.Channel == 3);
    g.Window->GetShaderCache()->ReadyShaderProgram(g.MaskProgram);
    glBindVertexArray(this->VertexArray);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }

  // One light's buffers, uploaded once per volume build, bound for drawing.
  void BindVolumeBuffers(const Group& g, VolumeSet& vs, GLint loc)
  {
    glBindVertexArray(this->VertexArray);
    BindBuffer(GL_ARRAY_BUFFER, vs.Buffer,
      static_cast<GLsizeiptr>(vs.Vertices.size() * sizeof(float)),
      vs.Vertices.empty() ? nullptr : vs.Vertices.data());
    if (loc >= 0)
    {
      glEnableVertexAttribArray(static_cast<GLuint>(loc));
      glVertexAttribPointer(static_cast<GLuint>(loc), 4, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
    if (g.GSProgram && vs.AdjacencyCount > 0)
    {
      glBindVertexArray(this->PointArray);
      BindBuffer(GL_ELEMENT_ARRAY_BUFFER, vs.AdjacencyBuffer,
        static_cast<GLsizeiptr>(vs.AdjacencyIndices.size() * sizeof(GLuint)),
        vs.AdjacencyIndices.data());
    }
  }

  // Binds `buffer` to `target`, first creating it with `bytes` of `data` if it does not exist.
  static void BindBuffer(GLenum target, GLuint& buffer, GLsizeiptr bytes, const void* data)
  {
    if (!buffer)
    {
      glGenBuffers(1, &buffer);
      glBindBuffer(target, buffer);
      glBufferData(target, bytes, data, GL_STATIC_DRAW);
    }
    glBindBuffer(target, buffer);
  }

  // Every volume of one light once; light caps pushed back by `capScale` (1: not at all).
  void DrawVolumes(
    const Group& g, const VolumeSet& vs, const VolumeLight& vl, float matrix[16], float capScale)
  {
    g.Window->GetShaderCache()->ReadyShaderProgram(g.Program);
    g.Program->SetUniformMatrix4x4("worldToClip", matrix);
    glBindVertexArray(this->VertexArray);
    if (vs.CapVertices > 0)
    {
      g.Program->SetUniformf("capScale", capScale);
      glDrawArrays(GL_TRIANGLES, 0, vs.CapVertices);
    }
    if (vs.AllVertices > vs.CapVertices)
    {
      g.Program->SetUniformf("capScale", 1.0f);
      glDrawArrays(GL_TRIANGLES, vs.CapVertices, vs.AllVertices - vs.CapVertices);
    }
    if (g.GSProgram && vs.AdjacencyCount > 0)
    {
      const float lightUniform[4] = { static_cast<float>(
                                        vl.Directional ? vl.Direction[0] : vl.Position[0]),
        static_cast<float>(vl.Directional ? vl.Direction[1] : vl.Position[1]),
        static_cast<float>(vl.Directional ? vl.Direction[2] : vl.Position[2]),
        vl.Directional ? 0.0f : 1.0f };
      g.Window->GetShaderCache()->ReadyShaderProgram(g.GSProgram);
      g.GSProgram->SetUniformMatrix4x4("worldToClip", matrix);
      g.GSProgram->SetUniformf("capScale", capScale);
      g.GSProgram->SetUniform4f("light", lightUniform);
      g.GSProgram->SetUniformf("extrusion", static_cast<float>(vl.Extrusion));
      g.GSProgram->SetUniformf("farW", static_cast<float>(vs.FarW));
      glBindVertexArray(this->PointArray);
      glDrawElements(GL_TRIANGLES_ADJACENCY, vs.AdjacencyCount, GL_UNSIGNED_INT, nullptr);
    }
  }

  // ---- Every light: the mask read back into its visibility, then the samples the stencil
  // could not count and the edge resolve. The lights done.
  int FinishLights(vtkPenumbraShadowVolumeShadows& self, const Group& g)
  {
    int done = 0;
    for (const Job& job : g.Jobs)
    {
      ++done;
      if (!job.Volumes)
      {
        continue; // decided without counting
      }
      this->ApplyMask(g, job);
      if (!this->TraceUncertain(self, g, job))
      {
        --done;
        continue;
      }
      job.Visibility->Modified();
    }
    return done;
  }

  // Mask read-back: one light's channel into the visibility of its counted samples.
  void ApplyMask(const Group& g, const Job& job)
  {
    float* vis = job.Vis;
    const std::vector<unsigned char>& state = job.State;
    const int channels = g.Counted == 1 ? 1 : 4;
    const unsigned char* maskChannel = this->MaskPixels.data() + job.Channel;
    const SampleLayout& layout = this->Layout;
    for (vtkIdType s = 0; s < g.N; ++s)
    {
      const vtkIdType pixel = layout.Pixel[static_cast<size_t>(s)];
      if (state[static_cast<size_t>(s)] == Pending && pixel >= 0)
      {
        vis[s] = maskChannel[static_cast<size_t>(channels) * static_cast<size_t>(pixel)] == 0
          ? 0.0f
          : 1.0f;
      }
    }
  }

  // ---- Samples the stencil could not count, and the edge resolve (see MarkTraced), traced
  // exactly. False when tracing failed (the visibility is then emptied).
  bool TraceUncertain(vtkPenumbraShadowVolumeShadows& self, const Group& g, const Job& job)
  {
    const SampleLayout& layout = this->Layout;
    if (!self.Resolve && layout.Unplaced <= 0)
    {
      return true;
    }
    const vtkIdType n = g.N;
    const auto resolveStart = Clock::now();
    this->Mask->SetNumberOfComponents(1);
    this->Mask->SetNumberOfTuples(n);
    if (self.Resolve)
    {
      job.Volumes->Outline.Mark(this->Projection, layout.Width, layout.Height, this->OutlinePixels);
    }
    const vtkIdType traced = MarkTraced(layout, *g.In, job.VL, job.State, job.Vis,
      self.Resolve ? this->OutlinePixels.data() : nullptr, n ? this->Mask->GetPointer(0) : nullptr);
    if (traced > 0)
    {
      self.Reference->SetGeometry(g.Geometry);
      if (!self.Reference->ComputeVisibility(g.Samples, job.Light, job.Visibility, this->Mask))
      {
        vtkErrorWithObjectMacro(&self, << "shadow volumes: tracing the edge samples failed: "
                                       << self.Reference->GetErrorMessage());
        job.Visibility->SetNumberOfTuples(0);
        return false;
      }
    }
    self.NumberOfResolvedSamples += traced;
    self.ResolveTimeMs += ElapsedMs(resolveStart);
    return true;
  }
};

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
  os << indent << "NumberOfMasks: " << this->NumberOfMasks << "\n";
  os << indent << "NumberOfResolvedSamples: " << this->NumberOfResolvedSamples << "\n";
}
