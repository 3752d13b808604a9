// vtkPenumbraShadowVolumeShadows: the casters' connectivity (OpenMesh), welded and split into
// closed components for silhouette volumes and loose triangles for per-triangle volumes.

#include "vtkPenumbraShadowVolumeInternals.h"

#include "vtkDoubleArray.h"
#include "vtkPenumbraSceneGeometry.h"

#include <algorithm>
#include <map>

namespace
{
using penumbra_shadow_volume::Vec3;

// Lexicographic order, for welding vertices in a std::map.
struct Vec3Less
{
  bool operator()(const Vec3& a, const Vec3& b) const
  {
    return a.x != b.x ? a.x < b.x : (a.y != b.y ? a.y < b.y : a.z < b.z);
  }
};
}

namespace penumbra_shadow_volume
{
void Connectivity::Build(vtkPenumbraSceneGeometry* geometry, bool silhouettes)
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
    handles.push_back(mesh.add_vertex(
      OMesh::Point(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]))));
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
std::vector<std::array<int, 3>> Connectivity::WeldCasters(vtkPenumbraSceneGeometry* geometry)
{
  const vtkIdType nt = geometry->GetNumberOfTriangles();
  const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
  // Weld exactly equal coordinates only: anything looser would move geometry and the
  // reference sees the unwelded triangles.
  std::map<Vec3, int, Vec3Less> weld;
  std::vector<std::array<int, 3>> tris;
  for (vtkIdType t = 0; t < nt; ++t)
  {
    if (!triangles.IsOccluder(t))
    {
      continue;
    }
    std::array<int, 3> idx;
    Vec3 v[3];
    double tv[9];
    triangles.Get(t, tv);
    for (int k = 0; k < 3; ++k)
    {
      v[k] = { tv[3 * k], tv[3 * k + 1], tv[3 * k + 2] };
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
void Connectivity::BuildComponents(
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
Connectivity::Component Connectivity::MakeComponent(const OMesh& mesh,
  const std::vector<int>& faces, bool closed, const std::vector<std::array<int, 3>>& tris,
  const std::vector<int>& faceTri, std::vector<int>& local) const
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
void Connectivity::Orient(Component& c) const
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
void Connectivity::AddAdjacency(Component& c)
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
}
