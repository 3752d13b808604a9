/**
 * @file    vtkPenumbraSceneTriangles.h
 * @brief   How a vtkPenumbraSceneGeometry stores its triangles, and the read-only view the
 *          techniques and the tracer read them through (penumbra::SceneTriangles).
 *
 * One copy of the scene, indexed: per prop, its points in absolute world coordinates (double,
 * as extracted), three point indices per triangle, and what each triangle does. A point that
 * several triangles share (a mesh's vertex) is stored once, so a closed triangle mesh costs
 * about 12 bytes a triangle for its points instead of 72 for three corners each. The
 * per-triangle cell ids and owners are stored as an affine prefix plus an explicit tail
 * (penumbra::AffineColumn): a drawn triangle owns itself, and the triangles of a triangle mesh
 * come from consecutive cells, so neither costs anything for the common case.
 *
 * The positions every technique and the tracer use are rebased: world minus the geometry's
 * Origin, computed in double when read (SceneTriangles::Get), the same operation and so the
 * same value for every reader; their float32 rounding is kept per prop (TriangleList::Rebased)
 * for the GPU and Embree, which read it in place.
 *
 * Not wrapped; installed for the modules above Scene.
 */

#ifndef vtkPenumbraSceneTriangles_h
#define vtkPenumbraSceneTriangles_h

#include "vtkPenumbraSceneModule.h" // For export macro
#include "vtkType.h"                // For vtkIdType

#include <glm/vec3.hpp> // glm::dvec3: the double-precision vector of every Penumbra module

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace penumbra
{
/**
 * A column of per-triangle integers: value(t) = Base + t for the first PrefixSize entries,
 * then the explicit Tail. Appending the next value of the affine run extends the prefix; any
 * other value starts (or extends) the tail.
 */
class VTKPENUMBRASCENE_EXPORT AffineColumn
{
public:
  vtkIdType Size() const { return this->PrefixSize + static_cast<vtkIdType>(this->Tail.size()); }
  vtkIdType operator[](vtkIdType t) const
  {
    return t < this->PrefixSize ? this->Base + t
                                : this->Tail[static_cast<size_t>(t - this->PrefixSize)];
  }
  void Append(vtkIdType value)
  {
    if (this->Tail.empty() && (this->PrefixSize == 0 || value == this->Base + this->PrefixSize))
    {
      this->Base = this->PrefixSize == 0 ? value : this->Base;
      ++this->PrefixSize;
      return;
    }
    this->Tail.push_back(value);
  }
  /** Sets the entries from `first` on to `value` (the tail then holds them). */
  void Fill(vtkIdType first, vtkIdType value);
  /** Appends `other`'s entries, each non-negative one shifted by `shift`. */
  void Append(const AffineColumn& other, vtkIdType shift);
  void Reserve(vtkIdType count) { this->Tail.reserve(static_cast<size_t>(count)); }
  void Clear()
  {
    this->Base = this->PrefixSize = 0;
    this->Tail.clear();
  }
  bool operator==(const AffineColumn& o) const;
  /** Bytes held beyond the object itself. */
  size_t HeapBytes() const { return this->Tail.capacity() * sizeof(vtkIdType); }

private:
  vtkIdType Base = 0;
  vtkIdType PrefixSize = 0;
  std::vector<vtkIdType> Tail;
};

/**
 * One prop's triangles as extracted and stored: the drawn triangles first (in the order a
 * G-buffer's primitive ids count them), then the caster-only ones. Owners are local indices of
 * the drawn triangle each triangle must never shadow (itself for a drawn triangle), -1 for
 * shapes that belong to no drawn triangle (tubes, point solids). Roles: bits of
 * vtkPenumbraSceneGeometry::TriangleFlags, before the prop's shadow keys.
 */
struct VTKPENUMBRASCENE_EXPORT TriangleList
{
  std::vector<double> Points;         // absolute world coordinates, 3 per point
  std::vector<std::uint32_t> Corners; // 3 point indices per triangle
  AffineColumn CellIds;
  AffineColumn Owners;
  std::vector<unsigned char> Roles;
  vtkIdType Degenerate = 0; // triangles with zero area (IsDegenerate) among them

  // Derived when published, not part of the content: float(Points - origin), 3 per point and
  // 4 bytes of padding (Embree reads 16 bytes at its last vertex).
  std::vector<float> Rebased;

  vtkIdType Size() const { return static_cast<vtkIdType>(this->Roles.size()); }
  vtkIdType NumberOfPoints() const { return static_cast<vtkIdType>(this->Points.size() / 3); }
  const double* Point(vtkIdType t, int corner) const
  {
    return &this
              ->Points[3 * static_cast<size_t>(this->Corners[3 * static_cast<size_t>(t) + corner])];
  }

  /** Appends a point; returns its index. */
  std::uint32_t AddPoint(const double p[3]);
  std::uint32_t AddPoint(const glm::dvec3& p);
  /** A triangle of three points already added. */
  void AddIndexed(std::uint32_t a, std::uint32_t b, std::uint32_t c, vtkIdType cell,
    vtkIdType owner, unsigned char role);
  /** A triangle of three new points. */
  void Add(const double* a, const double* b, const double* c, vtkIdType cell, vtkIdType owner,
    unsigned char role);
  void Add(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, vtkIdType cell,
    vtkIdType owner, unsigned char role);
  /** Makes room for `triangles` and `points` in all, so appending does not reallocate. */
  void Reserve(vtkIdType triangles, vtkIdType points);
  /** Appends `other`; its non-negative owners are shifted by `ownerShift`. */
  void Append(const TriangleList& other, vtkIdType ownerShift);
  /** Gives back the unused capacity (after the extraction, before it is kept). */
  void ShrinkToFit();
  void Clear();
  /** Same content (points, corners, cell ids, owners, roles); Rebased is not compared. */
  bool operator==(const TriangleList& o) const;
  /** Rebased from the points (float(point - origin) per coordinate). */
  void Rebase(const double origin[3]);
  /** Bytes held beyond the object itself. */
  size_t HeapBytes() const;
};

/// Zero area up to rounding: the sine of the largest angle between two edges is below 1e-12.
VTKPENUMBRASCENE_EXPORT bool IsDegenerate(const double* a, const double* b, const double* c);

/**
 * Whether the triangle with these rebased corners can block light: a non-zero, finite area
 * (zero-area triangles cover no solid angle). With the casting flag, the one occluder rule of
 * every technique and the reference (vtkPenumbraSceneGeometry::IsOccluder).
 */
inline bool HasArea(const double v[9])
{
  const double e1[3] = { v[3] - v[0], v[4] - v[1], v[5] - v[2] };
  const double e2[3] = { v[6] - v[0], v[7] - v[1], v[8] - v[2] };
  const double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
    e1[0] * e2[1] - e1[1] * e2[0] };
  const double a2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
  return a2 > 0.0 && std::isfinite(a2);
}

/**
 * The published triangles of a vtkPenumbraSceneGeometry (GetTriangles()): the props' lists one
 * after the other, triangle t of the scene being triangle t - First of the block that holds
 * it. Valid until the geometry's next Update(). Every accessor takes global triangle indices.
 */
class VTKPENUMBRASCENE_EXPORT SceneTriangles
{
public:
  struct Block
  {
    vtkIdType First = 0;                // global index of the list's first triangle
    const TriangleList* List = nullptr; // the prop's triangles
    unsigned char Flags = 0;            // the prop's shadow keys (masks the roles)
  };

  vtkIdType Size() const { return this->Count; }
  const double* GetOrigin() const { return this->Origin; }
  const std::vector<Block>& GetBlocks() const { return this->Blocks; }

  /** The index in GetBlocks() of the block holding triangle t (0 <= t < Size()). */
  size_t BlockIndex(vtkIdType t) const
  {
    if (this->Blocks.size() == 1)
    {
      return 0;
    }
    auto it = std::upper_bound(this->Firsts.begin(), this->Firsts.end(), t);
    return static_cast<size_t>(it - this->Firsts.begin()) - 1;
  }
  const Block& BlockOf(vtkIdType t) const { return this->Blocks[this->BlockIndex(t)]; }

  /** Triangle t's corners relative to Origin, in double (v0 xyz, v1 xyz, v2 xyz). */
  void Get(vtkIdType t, double v[9]) const
  {
    const Block& b = this->BlockOf(t);
    GetLocal(b, t - b.First, v);
  }
  void GetLocal(const Block& b, vtkIdType local, double v[9]) const
  {
    for (int k = 0; k < 3; ++k)
    {
      const double* p = b.List->Point(local, k);
      v[3 * k] = p[0] - this->Origin[0];
      v[3 * k + 1] = p[1] - this->Origin[1];
      v[3 * k + 2] = p[2] - this->Origin[2];
    }
  }
  /** Corner k (0..2) of triangle t relative to Origin, in double. */
  void GetCorner(vtkIdType t, int k, double p[3]) const
  {
    const Block& b = this->BlockOf(t);
    const double* w = b.List->Point(t - b.First, k);
    p[0] = w[0] - this->Origin[0];
    p[1] = w[1] - this->Origin[1];
    p[2] = w[2] - this->Origin[2];
  }
  /** Triangle t's corners relative to Origin, rounded to float32 (the GPU's and Embree's). */
  void GetFloat(vtkIdType t, float v[9]) const
  {
    const Block& b = this->BlockOf(t);
    const std::uint32_t* c = &b.List->Corners[3 * static_cast<size_t>(t - b.First)];
    for (int k = 0; k < 3; ++k)
    {
      std::copy_n(&b.List->Rebased[3 * static_cast<size_t>(c[k])], 3, v + 3 * k);
    }
  }
  /** vtkPenumbraSceneGeometry::TriangleFlags bits: the triangle's role masked by its prop. */
  unsigned char GetFlags(vtkIdType t) const
  {
    const Block& b = this->BlockOf(t);
    return static_cast<unsigned char>(b.List->Roles[static_cast<size_t>(t - b.First)] & b.Flags);
  }
  /** The global index of the drawn triangle t must never shadow, -1 for none. */
  vtkIdType GetOwner(vtkIdType t) const
  {
    const Block& b = this->BlockOf(t);
    return GetOwnerLocal(b, t - b.First);
  }
  /** GetOwner of the triangle `local` of block `b` (for loops that walk a block). */
  static vtkIdType GetOwnerLocal(const Block& b, vtkIdType local)
  {
    const vtkIdType owner = b.List->Owners[local];
    return owner >= 0 ? b.First + owner : -1;
  }
  vtkIdType GetCellId(vtkIdType t) const
  {
    const Block& b = this->BlockOf(t);
    return b.List->CellIds[t - b.First];
  }
  int GetPropIndex(vtkIdType t) const { return static_cast<int>(this->BlockIndex(t)); }
  /** Casts shadows and has area (HasArea of its rebased corners). */
  bool IsOccluder(vtkIdType t) const
  {
    const Block& b = this->BlockOf(t);
    return this->IsOccluderLocal(b, t - b.First);
  }
  /** IsOccluder of the triangle `local` of block `b` (for loops that walk a block). */
  bool IsOccluderLocal(const Block& b, vtkIdType local) const
  {
    if (!(b.List->Roles[static_cast<size_t>(local)] & b.Flags & 1))
    {
      return false;
    }
    double v[9];
    this->GetLocal(b, local, v);
    return HasArea(v);
  }

  /** Rebuilds the view (the geometry's Publish). */
  void Reset(const double origin[3], std::vector<Block> blocks);

private:
  double Origin[3] = { 0, 0, 0 };
  vtkIdType Count = 0;
  std::vector<Block> Blocks;
  std::vector<vtkIdType> Firsts; // Blocks[i].First, for the binary search
};
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraSceneTriangles.h
