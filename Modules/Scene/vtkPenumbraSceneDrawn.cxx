#include "vtkPenumbraSceneDrawn.h"

#include "vtkPenumbraSceneCutouts.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>

namespace penumbra_scene
{
//------------------------------------------------------------------------------
void TransformPoint(const double m[16], const double p[3], double out[3])
{
  const double w = m[12] * p[0] + m[13] * p[1] + m[14] * p[2] + m[15];
  for (int r = 0; r < 3; ++r)
  {
    out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
  }
  // Affine matrices (the usual case) have w == 1 exactly; dividing then changes nothing.
  if (w != 1.0)
  {
    out[0] /= w;
    out[1] /= w;
    out[2] /= w;
  }
}

namespace
{
bool SamePoint(vtkPoints* pts, vtkIdType a, vtkIdType b)
{
  if (a == b)
  {
    return true;
  }
  double pa[3], pb[3];
  pts->GetPoint(a, pa);
  pts->GetPoint(b, pb);
  return pa[0] == pb[0] && pa[1] == pb[1] && pa[2] == pb[2];
}

// One polydata's extraction: the phases of AppendDrawnPolyData.
class Extractor
{
public:
  Extractor(vtkPolyData* poly, const double m[16], vtkIdType cellBase, const DrawStyle& style,
    TriangleList& drawn, TriangleList& casters, Outcome& outcome)
    : Poly(poly)
    , Matrix(m)
    , CellBase(cellBase)
    , Style(style)
    , Drawn(drawn)
    , Casters(casters)
    , Result(outcome)
  {
  }

  void Run(PrimitiveCounts* counts);

private:
  Vec3 At(vtkIdType id) const
  {
    return Vec3(this->World[3 * id], this->World[3 * id + 1], this->World[3 * id + 2]);
  }
  void Use(vtkIdType id)
  {
    if (this->Bad[static_cast<size_t>(id)] == 1)
    {
      this->Bad[static_cast<size_t>(id)] = 2;
      ++this->Result.BadPoints;
    }
  }
  // The index in Drawn's points of the polydata's point `id`, added on first use: a point the
  // mesh's triangles share is stored once.
  std::uint32_t Pooled(vtkIdType id)
  {
    std::uint32_t& index = this->PoolIndex[static_cast<size_t>(id)];
    if (index == NotPooled)
    {
      index = this->Drawn.AddPoint(&this->World[3 * id]);
    }
    return index;
  }
  void TransformPoints();
  void Surface(PrimitiveCounts* counts);
  void AddSurfaceTriangle(vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType cell);
  void CutSurfaceTriangle(vtkIdType local, vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType cell);
  bool TextureCorners(vtkIdType a, vtkIdType b, vtkIdType c, double xy[3][2]);
  void EdgeStrips(vtkIdType local, const vtkIdType tri[3], int edges, vtkIdType cell);
  void AddCasterClipped(const Vec3 v[3], vtkIdType cell, vtkIdType owner);
  using Segment = std::array<vtkIdType, 3>; // lower point, higher point, cell
  void CollectSegments(std::vector<Segment>& segments) const;
  void CollectPoints(std::vector<std::array<vtkIdType, 2>>& points) const;
  void EmitSegments(std::vector<Segment>& segments);
  void EmitPoints(std::vector<std::array<vtkIdType, 2>>& points);
  bool ColourZero(vtkIdType cell, std::initializer_list<vtkIdType> ids) const;

  vtkPolyData* Poly;
  const double* Matrix;
  vtkIdType CellBase;
  const DrawStyle& Style;
  TriangleList& Drawn;
  TriangleList& Casters;
  Outcome& Result;

  std::vector<double> World;
  std::vector<char> Bad; // 1: non-finite, 2: non-finite and counted
  static constexpr std::uint32_t NotPooled = ~std::uint32_t(0);
  std::vector<std::uint32_t> PoolIndex; // per point: its index in Drawn's points, or NotPooled
  ScalarAlpha Alpha;
  vtkDataArray* TCoords = nullptr;
  vtkUnsignedCharArray* EdgeFlags = nullptr;
  vtkIdType FirstLine = 0, FirstPoly = 0, FirstStrip = 0; // local cell ids
  std::vector<BaryPolygon> Pieces;
  BaryPolygon Scratch;
};

//------------------------------------------------------------------------------
void Extractor::TransformPoints()
{
  vtkPoints* pts = this->Poly->GetPoints();
  const vtkIdType n = pts ? pts->GetNumberOfPoints() : 0;
  this->World.resize(3 * static_cast<size_t>(n));
  this->Bad.assign(static_cast<size_t>(n), 0);
  this->PoolIndex.assign(static_cast<size_t>(n), NotPooled);
  for (vtkIdType i = 0; i < n; ++i)
  {
    double p[3];
    pts->GetPoint(i, p);
    double* w = &this->World[3 * i];
    TransformPoint(this->Matrix, p, w);
    this->Bad[static_cast<size_t>(i)] =
      std::isfinite(w[0]) && std::isfinite(w[1]) && std::isfinite(w[2]) ? 0 : 1;
  }
}

//------------------------------------------------------------------------------
bool Extractor::ColourZero(vtkIdType cell, std::initializer_list<vtkIdType> ids) const
{
  if (!this->Alpha.Any())
  {
    return false;
  }
  if (this->Alpha.Cells)
  {
    return static_cast<size_t>(cell) < this->Alpha.Zero.size() &&
      this->Alpha.Zero[static_cast<size_t>(cell)];
  }
  for (vtkIdType id : ids)
  {
    if (!this->Alpha.Zero[static_cast<size_t>(id)])
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool Extractor::TextureCorners(vtkIdType a, vtkIdType b, vtkIdType c, double xy[3][2])
{
  // vtkOpenGLPolyDataMapper::ReplaceShaderTCoord: 1D coordinates are (s, 0); a texture
  // transform maps (s, t, 0, 1) and divides by w, per vertex, and the result is interpolated.
  const int comps = this->TCoords->GetNumberOfComponents();
  const vtkIdType ids[3] = { a, b, c };
  for (int k = 0; k < 3; ++k)
  {
    double st[2] = { this->TCoords->GetComponent(ids[k], 0),
      comps > 1 ? this->TCoords->GetComponent(ids[k], 1) : 0.0 };
    if (this->Style.TextureTransform)
    {
      const double* m = this->Style.TextureMatrix;
      const double in[4] = { st[0], comps > 1 ? st[1] : 0.0, 0.0, 1.0 };
      double h[4];
      for (int r = 0; r < 4; ++r)
      {
        h[r] = m[4 * r] * in[0] + m[4 * r + 1] * in[1] + m[4 * r + 2] * in[2] + m[4 * r + 3];
      }
      st[0] = h[0] / h[3];
      st[1] = comps > 1 ? h[1] / h[3] : 0.0;
    }
    if (!std::isfinite(st[0]) || !std::isfinite(st[1]))
    {
      ++this->Result.BadTCoords;
      return false;
    }
    this->Style.Texture->ToCells(st[0], st[1], xy[k]);
  }
  return true;
}

//------------------------------------------------------------------------------
void Extractor::CutSurfaceTriangle(
  vtkIdType local, vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType cell)
{
  unsigned char& role = this->Drawn.Roles[static_cast<size_t>(local)];
  if (!(role & ROLE_CASTS))
  {
    return;
  }
  if (this->ColourZero(cell, { a, b, c }))
  {
    role &= static_cast<unsigned char>(~ROLE_CASTS);
    return;
  }
  const Vec3 v[3] = { this->At(a), this->At(b), this->At(c) };
  // Clipping planes: whole, nothing, or the planes that cross the triangle.
  std::vector<const Plane*> crossing;
  for (const Plane& p : this->Style.Clip)
  {
    double f[3];
    PlaneCorners(p, v, f);
    if (f[0] < 0.0 && f[1] < 0.0 && f[2] < 0.0)
    {
      role &= static_cast<unsigned char>(~ROLE_CASTS);
      return;
    }
    if (f[0] < 0.0 || f[1] < 0.0 || f[2] < 0.0)
    {
      crossing.push_back(&p);
    }
  }
  this->Pieces.clear();
  bool textured = false;
  double xy[3][2];
  if (this->Style.Texture && this->TCoords && this->TextureCorners(a, b, c, xy))
  {
    switch (this->Style.Texture->CutTriangle(xy, this->Pieces, this->Result.Budget))
    {
      case AlphaGrid::Cut::None:
        role &= static_cast<unsigned char>(~ROLE_CASTS);
        return;
      case AlphaGrid::Cut::Pieces:
        textured = true;
        break;
      case AlphaGrid::Cut::TooFine:
        ++this->Result.TooFine;
        break;
      case AlphaGrid::Cut::Whole:
        break;
    }
  }
  if (!textured && crossing.empty())
  {
    return; // casts whole
  }
  if (!textured)
  {
    this->Pieces.assign(1, WholeTriangle());
  }
  role &= static_cast<unsigned char>(~ROLE_CASTS);
  for (BaryPolygon& piece : this->Pieces)
  {
    for (const Plane* p : crossing)
    {
      double f[3];
      PlaneCorners(*p, v, f);
      ClipBary(piece, f, this->Scratch);
    }
    AppendBaryPolygon(v, piece, this->CellBase + cell, local, ROLE_CASTS, this->Casters);
  }
}

//------------------------------------------------------------------------------
void Extractor::AddCasterClipped(const Vec3 v[3], vtkIdType cell, vtkIdType owner)
{
  BaryPolygon piece = WholeTriangle();
  for (const Plane& p : this->Style.Clip)
  {
    double f[3];
    PlaneCorners(p, v, f);
    ClipBary(piece, f, this->Scratch);
  }
  AppendBaryPolygon(v, piece, this->CellBase + cell, owner, ROLE_CASTS, this->Casters);
}

//------------------------------------------------------------------------------
void Extractor::EdgeStrips(vtkIdType local, const vtkIdType tri[3], int edges, vtkIdType cell)
{
  // Edge k of a triangle runs from corner k to corner k + 1 (vtkPolyDataEdgesGS's order).
  const Vec3 v[3] = { this->At(tri[0]), this->At(tri[1]), this->At(tri[2]) };
  const Vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
  if (!(glm::length(n) > 0.0))
  {
    return;
  }
  const Vec3 inside = (v[0] + v[1] + v[2]) / 3.0;
  for (int k = 0; k < 3; ++k)
  {
    if (!(edges & (1 << k)))
    {
      continue;
    }
    TriangleList strip;
    AppendEdgeStrip(v[k], v[(k + 1) % 3], inside, n, 0.5 * this->Style.EdgeWidth, 0, 0, strip);
    for (vtkIdType t = 0; t < strip.Size(); ++t)
    {
      Vec3 s[3];
      for (int c = 0; c < 3; ++c)
      {
        const double* w = strip.Point(t, c);
        s[c] = Vec3(w[0], w[1], w[2]);
      }
      this->AddCasterClipped(s, cell, local);
    }
  }
}

//------------------------------------------------------------------------------
void Extractor::AddSurfaceTriangle(vtkIdType a, vtkIdType b, vtkIdType c, vtkIdType cell)
{
  for (vtkIdType id : { a, b, c })
  {
    this->Use(id);
  }
  const vtkIdType local = this->Drawn.Size();
  this->Drawn.AddIndexed(this->Pooled(a), this->Pooled(b), this->Pooled(c), this->CellBase + cell,
    local, this->Style.SurfaceRole);
  this->CutSurfaceTriangle(local, a, b, c, cell);
}

//------------------------------------------------------------------------------
void Extractor::Surface(PrimitiveCounts* counts)
{
  vtkPoints* pts = this->Poly->GetPoints();
  vtkCellArray* polys = this->Poly->GetPolys();
  vtkCellArray* strips = this->Poly->GetStrips();
  const bool edges = this->Style.EdgeVisibility && this->Style.EdgeWidth > 0.0;
  this->Result.UsesWidth = this->Result.UsesWidth || this->Style.EdgeVisibility;
  const vtkIdType triangles = polys->GetNumberOfConnectivityIds() - 2 * polys->GetNumberOfCells() +
    strips->GetNumberOfConnectivityIds() - 2 * strips->GetNumberOfCells();
  this->Drawn.Reserve(this->Drawn.Size() + triangles,
    this->Drawn.NumberOfPoints() + static_cast<vtkIdType>(this->PoolIndex.size()));
  if (edges)
  {
    this->Casters.Reserve(
      this->Casters.Size() + 2 * 3 * triangles, this->Casters.NumberOfPoints() + 4 * 3 * triangles);
  }

  // Polygons: fan (p0, p_i, p_i+1), as vtkOpenGLIndexBufferObject::AppendTriangleIndexBuffer.
  // That function leaves out fan triangles with two coincident points (equal coordinates in
  // the points' own precision), and their edges; we keep the triangles but record which GL
  // primitive is which.
  const vtkIdType polyBase = this->Drawn.Size();
  std::vector<vtkIdType> skipped;
  vtkIdType npts = 0;
  const vtkIdType* ids = nullptr;
  vtkIdType cell = this->FirstPoly;
  for (polys->InitTraversal(); polys->GetNextCell(npts, ids); ++cell)
  {
    for (vtkIdType i = 1; i + 1 < npts; ++i)
    {
      const bool skip = SamePoint(pts, ids[0], ids[i]) || SamePoint(pts, ids[0], ids[i + 1]) ||
        SamePoint(pts, ids[i], ids[i + 1]);
      if (skip)
      {
        skipped.push_back(this->Drawn.Size() - polyBase);
      }
      const vtkIdType local = this->Drawn.Size();
      this->AddSurfaceTriangle(ids[0], ids[i], ids[i + 1], cell);
      if (edges && !skip)
      {
        // The real edges of fan triangle i (vtkOpenGLIndexBufferObject's edge values: bit
        // k for edge k), masked by the edge flags of each edge's first point.
        int real = npts == 3 ? 7 : i == 1 ? 3 : i == npts - 2 ? 6 : 2;
        const vtkIdType tri[3] = { ids[0], ids[i], ids[i + 1] };
        if (this->EdgeFlags)
        {
          real &= this->EdgeFlags->GetValue(tri[0]) + 2 * this->EdgeFlags->GetValue(tri[1]) +
            4 * this->EdgeFlags->GetValue(tri[2]);
        }
        this->EdgeStrips(local, tri, real, cell);
      }
    }
  }
  const vtkIdType polyTriangles = this->Drawn.Size() - polyBase;

  // Strips: triangle j is (p_j, p_j+1+j%2, p_j+1+(j+1)%2), keeping a consistent winding,
  // as vtkOpenGLIndexBufferObject::AppendStripIndexBuffer (surface); none are skipped.
  const vtkIdType stripBase = this->Drawn.Size();
  cell = this->FirstStrip;
  for (strips->InitTraversal(); strips->GetNextCell(npts, ids); ++cell)
  {
    for (vtkIdType j = 0; j + 2 < npts; ++j)
    {
      const vtkIdType tri[3] = { ids[j], ids[j + 1 + j % 2], ids[j + 1 + (j + 1) % 2] };
      const vtkIdType local = this->Drawn.Size();
      this->AddSurfaceTriangle(tri[0], tri[1], tri[2], cell);
      if (edges)
      {
        this->EdgeStrips(local, tri, 7, cell);
      }
    }
  }

  if (counts)
  {
    counts->PolyTriangles = polyTriangles;
    counts->StripTriangles = this->Drawn.Size() - stripBase;
    counts->DrawnPolyTriangles = polyTriangles - static_cast<vtkIdType>(skipped.size());
    counts->DrawnPolyToLocal.clear();
    if (!skipped.empty())
    {
      counts->DrawnPolyToLocal.reserve(static_cast<size_t>(counts->DrawnPolyTriangles));
      size_t s = 0;
      for (vtkIdType t = 0; t < polyTriangles; ++t)
      {
        if (s < skipped.size() && skipped[s] == t)
        {
          ++s;
          continue;
        }
        counts->DrawnPolyToLocal.push_back(t);
      }
    }
  }
}

//------------------------------------------------------------------------------
void Extractor::CollectSegments(std::vector<Segment>& segments) const
{
  auto add = [&](vtkIdType a, vtkIdType b, vtkIdType cell)
  {
    if (a != b && !this->ColourZero(cell, { a, b }))
    {
      segments.push_back({ std::min(a, b), std::max(a, b), cell });
    }
  };
  const int representation = this->Style.Representation;
  vtkIdType npts = 0;
  const vtkIdType* ids = nullptr;
  vtkIdType cell = this->FirstLine;
  vtkCellArray* lines = this->Poly->GetLines();
  for (lines->InitTraversal(); lines->GetNextCell(npts, ids); ++cell)
  {
    for (vtkIdType i = 0; i + 1 < npts; ++i)
    {
      add(ids[i], ids[i + 1], cell);
    }
  }
  if (representation != 1) // VTK_WIREFRAME
  {
    return;
  }
  vtkCellArray* polys = this->Poly->GetPolys();
  cell = this->FirstPoly;
  for (polys->InitTraversal(); polys->GetNextCell(npts, ids); ++cell)
  {
    for (vtkIdType j = 0; j < npts && npts > 1; ++j)
    {
      if (!this->EdgeFlags || this->EdgeFlags->GetValue(ids[j]))
      {
        add(ids[j], ids[(j + 1) % npts], cell);
      }
    }
  }
  vtkCellArray* strips = this->Poly->GetStrips();
  cell = this->FirstStrip;
  for (strips->InitTraversal(); strips->GetNextCell(npts, ids); ++cell)
  {
    if (npts > 1)
    {
      add(ids[0], ids[1], cell);
    }
    for (vtkIdType j = 0; j + 2 < npts; ++j)
    {
      add(ids[j], ids[j + 2], cell);
      add(ids[j + 1], ids[j + 2], cell);
    }
  }
}

//------------------------------------------------------------------------------
void Extractor::CollectPoints(std::vector<std::array<vtkIdType, 2>>& points) const
{
  // Vertex cells always; every point of every cell in the points representation, or with
  // vertices shown on a surface drawn with edges (vtkOpenGLPolyDataMapper::BuildIBO).
  const bool all = this->Style.Representation == 0 ||
    (this->Style.Representation == 2 && this->Style.EdgeVisibility && this->Style.VertexVisibility);
  vtkCellArray* arrays[4] = { this->Poly->GetVerts(), this->Poly->GetLines(),
    this->Poly->GetPolys(), this->Poly->GetStrips() };
  vtkIdType cell = 0;
  for (int a = 0; a < (all ? 4 : 1); ++a)
  {
    vtkIdType npts = 0;
    const vtkIdType* ids = nullptr;
    for (arrays[a]->InitTraversal(); arrays[a]->GetNextCell(npts, ids); ++cell)
    {
      for (vtkIdType i = 0; i < npts; ++i)
      {
        if (!this->ColourZero(cell, { ids[i] }))
        {
          points.push_back({ ids[i], cell });
        }
      }
    }
  }
}

//------------------------------------------------------------------------------
void Extractor::EmitSegments(std::vector<Segment>& segments)
{
  // One tube per distinct segment, from its first cell (coincident tubes cast the same).
  std::sort(segments.begin(), segments.end());
  segments.erase(std::unique(segments.begin(), segments.end(),
                   [](const Segment& p, const Segment& q) { return p[0] == q[0] && p[1] == q[1]; }),
    segments.end());
  if (!segments.empty())
  {
    this->Result.UsesWidth = this->Result.PointsOrLines = true;
  }
  this->Casters.Reserve(this->Casters.Size() + 8 * static_cast<vtkIdType>(segments.size()),
    this->Casters.NumberOfPoints() + 6 * static_cast<vtkIdType>(segments.size()));
  for (const Segment& s : segments)
  {
    this->Use(s[0]);
    this->Use(s[1]);
    const Vec3 a = this->At(s[0]), b = this->At(s[1]);
    double t0 = 0.0, t1 = 1.0;
    if (ClipSegment(a, b, this->Style.Clip, t0, t1))
    {
      AppendTube(a + t0 * (b - a), a + t1 * (b - a), this->Style.LineWidth, this->CellBase + s[2],
        this->Casters);
    }
  }
}

//------------------------------------------------------------------------------
void Extractor::EmitPoints(std::vector<std::array<vtkIdType, 2>>& points)
{
  std::sort(points.begin(), points.end());
  points.erase(std::unique(points.begin(), points.end(),
                 [](const std::array<vtkIdType, 2>& p, const std::array<vtkIdType, 2>& q)
                 { return p[0] == q[0]; }),
    points.end());
  if (!points.empty())
  {
    this->Result.UsesWidth = this->Result.PointsOrLines = true;
  }
  this->Casters.Reserve(this->Casters.Size() + 8 * static_cast<vtkIdType>(points.size()),
    this->Casters.NumberOfPoints() + 6 * static_cast<vtkIdType>(points.size()));
  for (const auto& p : points)
  {
    this->Use(p[0]);
    const Vec3 c = this->At(p[0]);
    if (Inside(this->Style.Clip, c))
    {
      AppendPointSolid(c, this->Style.PointSize, this->CellBase + p[1], this->Casters);
    }
  }
}

//------------------------------------------------------------------------------
void Extractor::Run(PrimitiveCounts* counts)
{
  if (counts)
  {
    *counts = PrimitiveCounts();
  }
  vtkCellArray* verts = this->Poly->GetVerts();
  vtkCellArray* lines = this->Poly->GetLines();
  vtkCellArray* polys = this->Poly->GetPolys();
  this->FirstLine = verts->GetNumberOfCells();
  this->FirstPoly = this->FirstLine + lines->GetNumberOfCells();
  this->FirstStrip = this->FirstPoly + polys->GetNumberOfCells();
  if (counts)
  {
    // VTK 9.1 vtkOpenGLCellToVTKCellMap::BuildPrimitiveOffsetsIfNeeded (surface
    // representation): verts count one primitive per connectivity id, lines one per
    // connectivity id minus one per cell.
    counts->VertPrimitives = verts->GetNumberOfConnectivityIds();
    counts->LinePrimitives = lines->GetNumberOfConnectivityIds() - lines->GetNumberOfCells();
    counts->PolyConservative = polys->GetNumberOfConnectivityIds() - 2 * polys->GetNumberOfCells();
  }
  if (!this->Poly->GetPoints() || this->Poly->GetNumberOfPoints() == 0 ||
    this->Poly->GetNumberOfCells() == 0)
  {
    return;
  }
  this->TransformPoints();
  this->Alpha.Compute(this->Style.ColourMapper, this->Poly);
  const vtkIdType nPoints = this->Poly->GetNumberOfPoints();
  vtkDataArray* tcoords = this->Poly->GetPointData()->GetTCoords();
  if (tcoords && tcoords->GetNumberOfTuples() >= nPoints &&
    (tcoords->GetNumberOfComponents() == 1 || tcoords->GetNumberOfComponents() == 2))
  {
    this->TCoords = tcoords;
  }
  // vtkOpenGLPolyDataMapper::BuildIBO: one-component unsigned char edge flags only.
  vtkDataArray* flags = this->Poly->GetPointData()->GetAttribute(vtkDataSetAttributes::EDGEFLAG);
  this->EdgeFlags =
    flags && flags->GetNumberOfComponents() == 1 && flags->GetNumberOfTuples() >= nPoints
    ? vtkUnsignedCharArray::SafeDownCast(flags)
    : nullptr;

  if (this->Style.Representation == 2) // VTK_SURFACE
  {
    this->Surface(counts);
  }
  if (this->Style.Representation != 0) // VTK_POINTS draws no segments
  {
    std::vector<Segment> segments;
    this->CollectSegments(segments);
    this->EmitSegments(segments);
  }
  std::vector<std::array<vtkIdType, 2>> points;
  this->CollectPoints(points);
  this->EmitPoints(points);
}
}

//------------------------------------------------------------------------------
void AppendDrawnPolyData(vtkPolyData* poly, const double m[16], vtkIdType cellBase,
  const DrawStyle& style, TriangleList& drawn, TriangleList& casters, PrimitiveCounts* counts,
  Outcome& outcome)
{
  Extractor(poly, m, cellBase, style, drawn, casters, outcome).Run(counts);
}
}
