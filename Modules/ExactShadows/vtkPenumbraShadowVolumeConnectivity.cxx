// vtkPenumbraShadowVolumeShadows: the casters' connectivity (OpenMesh), welded and split into
// closed components for silhouette volumes and loose triangles for per-triangle volumes.

#include "vtkPenumbraShadowVolumeInternals.h"

#include "vtkPenumbraSceneGeometry.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace
{
// The scene's points by global number (block b's points follow the earlier blocks'), in the
// geometry's rebased frame, as the reference sees them.
struct ScenePoints
{
  const penumbra::SceneTriangles& Triangles;
  std::vector<std::uint32_t> Base; // per block, its first global number; then the total

  explicit ScenePoints(const penumbra::SceneTriangles& triangles)
    : Triangles(triangles)
    , Base(triangles.GetBlocks().size() + 1, 0)
  {
    const auto& blocks = triangles.GetBlocks();
    for (size_t b = 0; b < blocks.size(); ++b)
    {
      this->Base[b + 1] =
        this->Base[b] + static_cast<std::uint32_t>(blocks[b].List->NumberOfPoints());
    }
  }
  void Rebased(std::uint32_t g, double p[3]) const
  {
    const size_t b = static_cast<size_t>(std::upper_bound(this->Base.begin(), this->Base.end(), g) -
                       this->Base.begin()) -
      1;
    const double* w =
      &this->Triangles.GetBlocks()[b].List->Points[3 * static_cast<size_t>(g - this->Base[b])];
    const double* origin = this->Triangles.GetOrigin();
    for (int c = 0; c < 3; ++c)
    {
      p[c] = w[c] - origin[c];
    }
  }
};
}

namespace penumbra_shadow_volume
{
// The welded points are made last, from their scene numbers: OpenMesh's half-edges are freed
// by then, so the two never take memory at once.
void Connectivity::Build(vtkPenumbraSceneGeometry* geometry, bool silhouettes, bool adjacency)
{
  *this = Connectivity();
  std::vector<std::uint32_t> source; // welded point -> global scene point
  std::vector<std::array<int, 3>> tris = this->WeldCasters(geometry, source);
  this->Casters = static_cast<vtkIdType>(tris.size());
  std::vector<std::array<int, 3>> across;
  if (silhouettes)
  {
    across = this->Across(tris, source.size());
  }
  const ScenePoints scene(geometry->GetTriangles());
  this->Points.resize(source.size());
  for (size_t i = 0; i < source.size(); ++i)
  {
    scene.Rebased(source[i], &this->Points[i][0]);
  }
  std::vector<std::uint32_t>().swap(source);
  if (!silhouettes)
  {
    this->Loose.swap(tris);
    return;
  }
  this->BuildComponents(tris, across, adjacency);
}

// Per triangle of `tris`, the triangle across each of its edges (t[k] -> t[k + 1]), -1 on a
// boundary edge, Refused for the triangles OpenMesh refuses (a complex edge or vertex: they
// go to Loose). OpenMesh's half-edges (48 bytes a face) live only in here.
std::vector<std::array<int, 3>> Connectivity::Across(
  const std::vector<std::array<int, 3>>& tris, size_t points)
{
  OMesh mesh;
  // Reserved: grown by push_back, OpenMesh's arrays would hold up to twice their size (a
  // closed mesh has 3/2 edges a face).
  mesh.reserve(points, tris.size() * 3 / 2 + 3, tris.size());
  for (size_t i = 0; i < points; ++i)
  {
    mesh.add_vertex();
  }
  // OpenMesh face index -> index into tris; empty while no face was refused (the same index).
  std::vector<int> faceTri;
  std::vector<std::array<int, 3>> across(tris.size(), { Refused, Refused, Refused });
  // OpenMesh reports every refused face on its error stream; we count them instead.
  omerr().disable();
  for (size_t i = 0; i < tris.size(); ++i)
  {
    const auto& t = tris[i];
    const OMesh::FaceHandle f = mesh.add_face(
      OMesh::VertexHandle(t[0]), OMesh::VertexHandle(t[1]), OMesh::VertexHandle(t[2]));
    if (!f.is_valid())
    {
      ++this->Complex;
      this->Loose.push_back(t);
      if (faceTri.empty())
      {
        faceTri.resize(i);
        std::iota(faceTri.begin(), faceTri.end(), 0);
      }
    }
    else if (!faceTri.empty())
    {
      faceTri.push_back(static_cast<int>(i));
    }
  }
  omerr().enable();
  auto triOf = [&](int face)
  { return faceTri.empty() ? face : faceTri[static_cast<size_t>(face)]; };
  for (OMesh::FaceHandle f : mesh.faces())
  {
    const int i = triOf(f.idx());
    const std::array<int, 3>& t = tris[static_cast<size_t>(i)];
    for (OMesh::HalfedgeHandle h : mesh.fh_range(f))
    {
      const int from = mesh.from_vertex_handle(h).idx();
      const int k = from == t[0] ? 0 : (from == t[1] ? 1 : 2);
      const OMesh::HalfedgeHandle o = mesh.opposite_halfedge_handle(h);
      const bool boundary = mesh.is_boundary(o);
      this->BoundaryEdges += boundary ? 1 : 0;
      across[static_cast<size_t>(i)][static_cast<size_t>(k)] =
        boundary ? -1 : triOf(mesh.face_handle(o).idx());
    }
  }
  return across;
}

// The occluding, non-degenerate triangles as triples of welded points (numbered in the order
// the triangles' corners first use them; `source` gets each one's global scene point). Exactly
// equal coordinates (in the geometry's rebased frame, as the reference sees them) are welded,
// nothing looser: anything looser would move geometry and the reference sees the unwelded
// triangles. The scene's points are welded first (sorted by coordinates, 8 bytes a point), not
// every corner.
std::vector<std::array<int, 3>> Connectivity::WeldCasters(
  vtkPenumbraSceneGeometry* geometry, std::vector<std::uint32_t>& source)
{
  const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
  const auto& blocks = triangles.GetBlocks();
  const ScenePoints scene(triangles);
  const std::vector<std::uint32_t>& base = scene.Base;
  // The scene's occluder rule (the reference's: casting, with area), once per triangle.
  std::vector<bool> occluding(static_cast<size_t>(triangles.Size()));
  for (const penumbra::SceneTriangles::Block& block : blocks)
  {
    for (vtkIdType t = 0; t < block.List->Size(); ++t)
    {
      occluding[static_cast<size_t>(block.First + t)] = triangles.IsOccluderLocal(block, t);
    }
  }
  // canon[g]: the smallest global point with g's coordinates (g itself when unique), for the
  // points the casters use.
  constexpr std::uint32_t Unused = ~std::uint32_t(0);
  std::vector<std::uint32_t> canon(base.back(), Unused);
  for (size_t b = 0; b < blocks.size(); ++b)
  {
    const penumbra::TriangleList& list = *blocks[b].List;
    for (vtkIdType t = 0; t < list.Size(); ++t)
    {
      if (occluding[static_cast<size_t>(blocks[b].First + t)])
      {
        for (int k = 0; k < 3; ++k)
        {
          const std::uint32_t g = base[b] + list.Corners[3 * static_cast<size_t>(t) + k];
          canon[g] = g;
        }
      }
    }
  }
  {
    std::vector<std::uint32_t> used;
    for (std::uint32_t g = 0; g < canon.size(); ++g)
    {
      if (canon[g] != Unused)
      {
        used.push_back(g);
      }
    }
    auto less = [&](std::uint32_t a, std::uint32_t c)
    {
      double p[3], q[3];
      scene.Rebased(a, p);
      scene.Rebased(c, q);
      return p[0] != q[0] ? p[0] < q[0]
                          : (p[1] != q[1] ? p[1] < q[1] : (p[2] != q[2] ? p[2] < q[2] : a < c));
    };
    std::sort(used.begin(), used.end(), less);
    for (size_t i = 1; i < used.size(); ++i)
    {
      double p[3], q[3];
      scene.Rebased(used[i - 1], p);
      scene.Rebased(used[i], q);
      if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2])
      {
        canon[used[i]] = canon[used[i - 1]];
      }
    }
  }
  // Welded numbers in the order of first use, as a map over the casters' corners would give.
  std::vector<int> welded(canon.size(), -1);
  std::vector<std::array<int, 3>> tris;
  for (size_t b = 0; b < blocks.size(); ++b)
  {
    const penumbra::TriangleList& list = *blocks[b].List;
    for (vtkIdType t = 0; t < list.Size(); ++t)
    {
      if (!occluding[static_cast<size_t>(blocks[b].First + t)])
      {
        continue;
      }
      std::array<int, 3> idx;
      for (int k = 0; k < 3; ++k)
      {
        const std::uint32_t g = canon[base[b] + list.Corners[3 * static_cast<size_t>(t) + k]];
        int& w = welded[g];
        if (w < 0)
        {
          w = static_cast<int>(source.size());
          source.push_back(g);
        }
        idx[k] = w;
      }
      tris.push_back(idx);
    }
  }
  return tris;
}

// Components of `tris` by flood fill over shared edges (`across`), each with its faces in the
// order of `tris` and the faces across their edges as indices into its own faces.
void Connectivity::BuildComponents(const std::vector<std::array<int, 3>>& tris,
  const std::vector<std::array<int, 3>>& across, bool adjacency)
{
  const size_t n = tris.size();
  std::vector<int> component(n, -1);
  std::vector<char> closed;
  std::vector<int> stack;
  for (size_t start = 0; start < n; ++start)
  {
    if (component[start] >= 0 || across[start][0] == Refused)
    {
      continue;
    }
    const int id = static_cast<int>(closed.size());
    closed.push_back(1);
    component[start] = id;
    stack.assign(1, static_cast<int>(start));
    while (!stack.empty())
    {
      const int f = stack.back();
      stack.pop_back();
      for (int g : across[static_cast<size_t>(f)])
      {
        if (g < 0)
        {
          closed.back() = 0;
        }
        else if (component[static_cast<size_t>(g)] < 0)
        {
          component[static_cast<size_t>(g)] = id;
          stack.push_back(g);
        }
      }
    }
  }
  std::vector<int>().swap(stack);
  this->Components.resize(closed.size());
  std::vector<int> local(n, -1); // triangle -> index in its component
  for (size_t i = 0; i < n; ++i)
  {
    if (component[i] >= 0)
    {
      Component& c = this->Components[static_cast<size_t>(component[i])];
      local[i] = static_cast<int>(c.Faces.size());
      c.Faces.push_back(tris[i]);
    }
  }
  for (size_t ci = 0; ci < closed.size(); ++ci)
  {
    this->Components[ci].Neighbors.reserve(this->Components[ci].Faces.size());
  }
  for (size_t i = 0; i < n; ++i)
  {
    if (component[i] >= 0)
    {
      std::array<int, 3> a = across[i];
      for (int& g : a)
      {
        g = g < 0 ? -1 : local[static_cast<size_t>(g)];
      }
      this->Components[static_cast<size_t>(component[i])].Neighbors.push_back(a);
    }
  }
  for (size_t ci = 0; ci < closed.size(); ++ci)
  {
    this->FinishComponent(this->Components[ci], closed[ci] != 0, adjacency);
  }
}

// A component's bounds and orientation (closed ones), and its adjacency if asked for.
void Connectivity::FinishComponent(Component& c, bool closed, bool adjacency) const
{
  c.Closed = closed;
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
  if (adjacency && c.Closed)
  {
    AddAdjacency(c);
  }
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
    // t0, t2, t1: its edges are the old third, second and first, reversed.
    for (auto& t : c.Faces)
    {
      std::swap(t[1], t[2]);
    }
    for (auto& a : c.Neighbors)
    {
      std::swap(a[0], a[2]);
    }
  }
  // Flat closed surfaces (two coincident sheets) have no inside: treat them as open.
  c.Closed = volume != 0.0;
}

// The GL_TRIANGLES_ADJACENCY faces of a closed component (see Component::Adjacency): across
// each edge, the third point of the face on its other side.
void Connectivity::AddAdjacency(Component& c)
{
  c.Adjacency.resize(c.Faces.size());
  for (size_t f = 0; f < c.Faces.size(); ++f)
  {
    const std::array<int, 3>& t = c.Faces[f];
    for (size_t k = 0; k < 3; ++k)
    {
      const int a = t[k], b = t[(k + 1) % 3];
      int opposite = a;
      for (int v : c.Faces[static_cast<size_t>(c.Neighbors[f][k])])
      {
        if (v != a && v != b)
        {
          opposite = v;
          break;
        }
      }
      c.Adjacency[f][2 * k] = a;
      c.Adjacency[f][2 * k + 1] = opposite;
    }
  }
}

}
