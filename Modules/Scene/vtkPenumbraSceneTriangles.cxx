#include "vtkPenumbraSceneTriangles.h"

#include <glm/geometric.hpp>

#include <limits>
#include <stdexcept>

namespace penumbra
{
//------------------------------------------------------------------------------
void AffineColumn::Fill(vtkIdType first, vtkIdType value)
{
  const vtkIdType n = this->Size();
  if (first >= n)
  {
    return;
  }
  if (first < this->PrefixSize)
  {
    // The prefix ends at `first`: its remaining entries move into the tail.
    std::vector<vtkIdType> tail(static_cast<size_t>(n - first), value);
    this->PrefixSize = first;
    this->Tail.swap(tail);
    return;
  }
  std::fill(this->Tail.begin() + (first - this->PrefixSize), this->Tail.end(), value);
}

//------------------------------------------------------------------------------
void AffineColumn::Append(const AffineColumn& other, vtkIdType shift)
{
  const vtkIdType n = other.Size();
  for (vtkIdType t = 0; t < n; ++t)
  {
    const vtkIdType v = other[t];
    this->Append(v >= 0 ? v + shift : v);
  }
}

//------------------------------------------------------------------------------
bool AffineColumn::operator==(const AffineColumn& o) const
{
  const vtkIdType n = this->Size();
  if (n != o.Size())
  {
    return false;
  }
  if (this->PrefixSize == o.PrefixSize && this->Base == o.Base)
  {
    return this->Tail == o.Tail;
  }
  for (vtkIdType t = 0; t < n; ++t)
  {
    if ((*this)[t] != o[t])
    {
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool IsDegenerate(const double* a, const double* b, const double* c)
{
  const glm::dvec3 pa(a[0], a[1], a[2]), pb(b[0], b[1], b[2]), pc(c[0], c[1], c[2]);
  const glm::dvec3 e1 = pb - pa, e2 = pc - pa, e3 = pc - pb;
  const double longest = std::max({ glm::dot(e1, e1), glm::dot(e2, e2), glm::dot(e3, e3) });
  return longest == 0.0 || glm::length(glm::cross(e1, e2)) <= 1e-12 * longest;
}

//------------------------------------------------------------------------------
std::uint32_t TriangleList::AddPoint(const double p[3])
{
  const size_t index = this->Points.size() / 3;
  // Point indices are 32-bit: 4 billion points in one prop is far beyond what a process
  // holds (96 GB of coordinates), so this is a guard, not a limit users meet.
  if (index >= std::numeric_limits<std::uint32_t>::max())
  {
    throw std::length_error("more than 2^32 - 1 points in one prop");
  }
  this->Points.insert(this->Points.end(), p, p + 3);
  return static_cast<std::uint32_t>(index);
}

//------------------------------------------------------------------------------
std::uint32_t TriangleList::AddPoint(const glm::dvec3& p)
{
  const double q[3] = { p.x, p.y, p.z };
  return this->AddPoint(q);
}

//------------------------------------------------------------------------------
void TriangleList::AddIndexed(std::uint32_t a, std::uint32_t b, std::uint32_t c, vtkIdType cell,
  vtkIdType owner, unsigned char role)
{
  this->Corners.push_back(a);
  this->Corners.push_back(b);
  this->Corners.push_back(c);
  this->CellIds.Append(cell);
  this->Owners.Append(owner);
  this->Roles.push_back(role);
  const double* pa = &this->Points[3 * static_cast<size_t>(a)];
  const double* pb = &this->Points[3 * static_cast<size_t>(b)];
  const double* pc = &this->Points[3 * static_cast<size_t>(c)];
  if (IsDegenerate(pa, pb, pc))
  {
    ++this->Degenerate;
  }
}

//------------------------------------------------------------------------------
void TriangleList::Add(const double* a, const double* b, const double* c, vtkIdType cell,
  vtkIdType owner, unsigned char role)
{
  const std::uint32_t ia = this->AddPoint(a);
  const std::uint32_t ib = this->AddPoint(b);
  const std::uint32_t ic = this->AddPoint(c);
  this->AddIndexed(ia, ib, ic, cell, owner, role);
}

//------------------------------------------------------------------------------
void TriangleList::Add(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
  vtkIdType cell, vtkIdType owner, unsigned char role)
{
  const double pa[3] = { a.x, a.y, a.z }, pb[3] = { b.x, b.y, b.z }, pc[3] = { c.x, c.y, c.z };
  this->Add(pa, pb, pc, cell, owner, role);
}

//------------------------------------------------------------------------------
void TriangleList::Reserve(vtkIdType triangles, vtkIdType points)
{
  const size_t n = static_cast<size_t>(triangles);
  if (n > this->Roles.capacity())
  {
    // Geometric growth, as push_back would, without the copies of every step.
    const size_t grown = std::max(n, this->Roles.capacity() + this->Roles.capacity() / 2);
    this->Corners.reserve(3 * grown);
    this->Roles.reserve(grown);
  }
  const size_t p = 3 * static_cast<size_t>(points);
  if (p > this->Points.capacity())
  {
    this->Points.reserve(std::max(p, this->Points.capacity() + this->Points.capacity() / 2));
  }
}

//------------------------------------------------------------------------------
void TriangleList::Append(const TriangleList& other, vtkIdType ownerShift)
{
  const std::uint32_t base = static_cast<std::uint32_t>(this->NumberOfPoints());
  if (static_cast<vtkIdType>(base) + other.NumberOfPoints() >=
    static_cast<vtkIdType>(std::numeric_limits<std::uint32_t>::max()))
  {
    throw std::length_error("more than 2^32 - 1 points in one prop");
  }
  this->Points.insert(this->Points.end(), other.Points.begin(), other.Points.end());
  this->Corners.reserve(this->Corners.size() + other.Corners.size());
  for (std::uint32_t c : other.Corners)
  {
    this->Corners.push_back(c + base);
  }
  this->CellIds.Append(other.CellIds, 0);
  this->Owners.Append(other.Owners, ownerShift);
  this->Roles.insert(this->Roles.end(), other.Roles.begin(), other.Roles.end());
  this->Degenerate += other.Degenerate;
}

//------------------------------------------------------------------------------
void TriangleList::ShrinkToFit()
{
  this->Points.shrink_to_fit();
  this->Corners.shrink_to_fit();
  this->Roles.shrink_to_fit();
}

//------------------------------------------------------------------------------
void TriangleList::Clear()
{
  this->Points.clear();
  this->Corners.clear();
  this->CellIds.Clear();
  this->Owners.Clear();
  this->Roles.clear();
  this->Rebased.clear();
  this->Degenerate = 0;
}

//------------------------------------------------------------------------------
bool TriangleList::operator==(const TriangleList& o) const
{
  if (this->Size() != o.Size() || this->Roles != o.Roles || !(this->CellIds == o.CellIds) ||
    !(this->Owners == o.Owners))
  {
    return false;
  }
  if (this->Points == o.Points && this->Corners == o.Corners)
  {
    return true;
  }
  // The same corners indexed differently are the same triangles.
  for (vtkIdType t = 0; t < this->Size(); ++t)
  {
    for (int k = 0; k < 3; ++k)
    {
      if (!std::equal(this->Point(t, k), this->Point(t, k) + 3, o.Point(t, k)))
      {
        return false;
      }
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void TriangleList::Rebase(const double origin[3])
{
  const size_t n = this->Points.size();
  this->Rebased.resize(n + 1);
  for (size_t i = 0; i < n; ++i)
  {
    this->Rebased[i] = static_cast<float>(this->Points[i] - origin[i % 3]);
  }
  this->Rebased[n] = 0.0f;
  this->Rebased.shrink_to_fit();
}

//------------------------------------------------------------------------------
size_t TriangleList::HeapBytes() const
{
  return this->Points.capacity() * sizeof(double) +
    this->Corners.capacity() * sizeof(std::uint32_t) + this->CellIds.HeapBytes() +
    this->Owners.HeapBytes() + this->Roles.capacity() + this->Rebased.capacity() * sizeof(float);
}

//------------------------------------------------------------------------------
void SceneTriangles::Reset(const double origin[3], std::vector<Block> blocks)
{
  std::copy(origin, origin + 3, this->Origin);
  this->Blocks.swap(blocks);
  this->Firsts.clear();
  this->Count = 0;
  for (const Block& b : this->Blocks)
  {
    this->Firsts.push_back(b.First);
    this->Count = b.First + b.List->Size();
  }
}
}
