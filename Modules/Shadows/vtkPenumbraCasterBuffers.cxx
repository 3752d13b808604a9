#include "vtkPenumbraCasterBuffers.h"

#include "vtkPenumbraSceneGeometry.h"
#include "vtkShaderProgram.h"

#include <algorithm>
#include <limits>

namespace penumbra_casters
{
//------------------------------------------------------------------------------
ExactTriangles::~ExactTriangles()
{
  this->Free();
}

//------------------------------------------------------------------------------
void ExactTriangles::Free()
{
  for (size_t b = 0; b < this->NumberOfBlocks; ++b)
  {
    delete[] this->Blocks[b].load(std::memory_order_relaxed);
  }
  this->Blocks.reset();
  this->NumberOfBlocks = 0;
}

//------------------------------------------------------------------------------
void ExactTriangles::Reset(const CasterIds& casters)
{
  this->SlotOf.clear();
  this->SlotOf.shrink_to_fit();
  this->Free();
  this->Made.reset();
  if (casters.empty() || casters.size() > MaxCached)
  {
    return;
  }
  this->SlotOf.assign(static_cast<size_t>(casters.back()) + 1, -1);
  for (size_t i = 0; i < casters.size(); ++i)
  {
    this->SlotOf[static_cast<size_t>(casters[i])] = static_cast<std::int32_t>(i);
  }
  this->NumberOfBlocks = (casters.size() + BlockSize - 1) / BlockSize;
  this->Blocks.reset(new std::atomic<penumbra_rules::ExactTriangle*>[this->NumberOfBlocks]);
  for (size_t b = 0; b < this->NumberOfBlocks; ++b)
  {
    this->Blocks[b].store(nullptr, std::memory_order_relaxed);
  }
  this->Made.reset(new std::atomic<unsigned char>[casters.size()]);
  for (size_t i = 0; i < casters.size(); ++i)
  {
    this->Made[i].store(0, std::memory_order_relaxed);
  }
}

//------------------------------------------------------------------------------
penumbra_rules::ExactTriangle& ExactTriangles::Slot(size_t slot)
{
  std::atomic<penumbra_rules::ExactTriangle*>& block = this->Blocks[slot / BlockSize];
  penumbra_rules::ExactTriangle* triangles = block.load(std::memory_order_acquire);
  if (!triangles)
  {
    // Two threads may allocate the same block: the first to publish it wins.
    auto* made = new penumbra_rules::ExactTriangle[BlockSize];
    if (block.compare_exchange_strong(triangles, made, std::memory_order_acq_rel))
    {
      triangles = made;
    }
    else
    {
      delete[] made;
    }
  }
  return triangles[slot % BlockSize];
}

//------------------------------------------------------------------------------
const penumbra_rules::ExactTriangle* ExactTriangles::Get(
  vtkIdType id, const penumbra::SceneTriangles& triangles, penumbra_rules::ExactTriangle& scratch)
{
  double vertices[9];
  const std::int32_t slot =
    static_cast<size_t>(id) < this->SlotOf.size() ? this->SlotOf[static_cast<size_t>(id)] : -1;
  if (slot >= 0)
  {
    std::atomic<unsigned char>& made = this->Made[static_cast<size_t>(slot)];
    unsigned char state = made.load(std::memory_order_acquire);
    if (state == 0 && made.compare_exchange_strong(state, 1, std::memory_order_acq_rel))
    {
      penumbra_rules::ExactTriangle& t = this->Slot(static_cast<size_t>(slot));
      triangles.Get(id, vertices);
      const bool area = penumbra_rules::MakeExactTriangle(vertices, id, t);
      made.store(area ? 2 : 3, std::memory_order_release);
      return area ? &t : nullptr;
    }
    if (state == 2)
    {
      return &this->Slot(static_cast<size_t>(slot));
    }
    if (state == 3)
    {
      return nullptr;
    }
  }
  triangles.Get(id, vertices);
  return penumbra_rules::MakeExactTriangle(vertices, id, scratch) ? &scratch : nullptr;
}

//------------------------------------------------------------------------------
bool CasterBuffers::Update(vtkPenumbraSceneGeometry* geometry, bool upload)
{
  if (this->Current.Changed(geometry))
  {
    const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
    const vtkIdType nTriangles = triangles.Size();
    // Sized exactly (counted first): grown by push_back the list would hold up to twice its
    // size.
    this->TriangleIds.clear();
    this->TriangleIds.shrink_to_fit();
    // The reference's rule: casters with area (a zero-area triangle blocks no ray).
    auto listed = [&](vtkIdType t) { return this->AllSurfaces || triangles.IsOccluder(t); };
    vtkIdType count = 0;
    for (vtkIdType t = 0; t < nTriangles; ++t)
    {
      count += listed(t) ? 1 : 0;
    }
    // GL draws 3 * count elements (a GLsizei) indexing the points of the props with casters
    // (32-bit elements), and the caster ids are 32-bit.
    vtkIdType casterPoints = 0;
    for (const penumbra::SceneTriangles::Block& block : triangles.GetBlocks())
    {
      casterPoints += block.List->NumberOfPoints();
    }
    if (nTriangles > static_cast<vtkIdType>(std::numeric_limits<std::uint32_t>::max()) ||
      3 * count > static_cast<vtkIdType>(std::numeric_limits<GLsizei>::max()) ||
      casterPoints > static_cast<vtkIdType>(std::numeric_limits<GLuint>::max()))
    {
      vtkGenericWarningMacro(<< "caster buffers: " << count << " casters of " << casterPoints
                             << " points exceed what one GL draw can index (2^31 / 3 casters, "
                                "2^32 points); no casters are listed, so nothing casts a shadow");
      count = 0;
    }
    CasterIds casters;
    if (count == nTriangles)
    {
      casters.SetIdentity(static_cast<size_t>(count));
    }
    else
    {
      casters.reserve(static_cast<size_t>(count));
    }
    double* bounds = this->Bounds;
    bounds[0] = bounds[2] = bounds[4] = std::numeric_limits<double>::max();
    bounds[1] = bounds[3] = bounds[5] = -std::numeric_limits<double>::max();
    // Per block: its first point in Positions, NoPoints when it has no caster (its points are
    // not uploaded: a receiver-only terrain costs the GPU nothing).
    this->PointBase.assign(triangles.GetBlocks().size(), NoPoints);
    GLuint points = 0;
    for (vtkIdType t = 0; t < nTriangles && count > 0; ++t)
    {
      if (!listed(t))
      {
        continue;
      }
      const size_t b = triangles.BlockIndex(t);
      if (this->PointBase[b] == NoPoints)
      {
        this->PointBase[b] = points;
        points += static_cast<GLuint>(triangles.GetBlocks()[b].List->NumberOfPoints());
      }
      if (count < nTriangles)
      {
        casters.push_back(static_cast<std::uint32_t>(t));
      }
      double p[9];
      triangles.Get(t, p);
      for (int c = 0; c < 9; ++c)
      {
        bounds[2 * (c % 3)] = std::min(bounds[2 * (c % 3)], p[c]);
        bounds[2 * (c % 3) + 1] = std::max(bounds[2 * (c % 3) + 1], p[c]);
      }
    }
    this->VertexCount = static_cast<GLsizei>(3 * casters.size());
    this->TriangleIds.swap(casters);
    this->Exact.Reset(this->TriangleIds);
    this->Triangles = &triangles;
    this->Current.Remember(geometry);
    this->OnGPU = false;
  }
  if (!upload || this->OnGPU)
  {
    return false;
  }
  if (!this->VertexArray)
  {
    glGenVertexArrays(1, &this->VertexArray);
    glGenBuffers(1, &this->Positions);
    glGenBuffers(1, &this->Elements);
    glGenBuffers(1, &this->Indices);
  }
  // The points of every prop that has a caster, one after the other (PointBase), then the
  // casters' corners as indices into them.
  const std::vector<penumbra::SceneTriangles::Block>& blocks = this->Triangles->GetBlocks();
  auto pointBytes = [&](size_t b)
  {
    return this->PointBase[b] == NoPoints
      ? GLsizeiptr(0)
      : static_cast<GLsizeiptr>(3 * blocks[b].List->NumberOfPoints() * sizeof(float));
  };
  GLsizeiptr allPointBytes = 0;
  for (size_t b = 0; b < blocks.size(); ++b)
  {
    allPointBytes += pointBytes(b);
  }
  glBindBuffer(GL_ARRAY_BUFFER, this->Positions);
  glBufferData(GL_ARRAY_BUFFER, allPointBytes, nullptr, GL_STATIC_DRAW);
  for (size_t b = 0; b < blocks.size(); ++b)
  {
    if (pointBytes(b) > 0)
    {
      glBufferSubData(GL_ARRAY_BUFFER,
        static_cast<GLintptr>(3 * sizeof(float) * static_cast<size_t>(this->PointBase[b])),
        pointBytes(b), blocks[b].List->Rebased.data());
    }
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  // The element buffer binding belongs to the bound vertex array: the casters' own is bound
  // while it is written, and the caller's restored after.
  GLint callerArray = 0;
  glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &callerArray);
  glBindVertexArray(this->VertexArray);
  // The element buffer is written in slices, so that no CPU copy of all of it is made.
  constexpr size_t Slice = size_t(1) << 16;
  std::vector<GLuint> slice;
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, this->Elements);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
    static_cast<GLsizeiptr>(this->VertexCount) * static_cast<GLsizeiptr>(sizeof(GLuint)), nullptr,
    GL_STATIC_DRAW);
  for (size_t first = 0; first < this->TriangleIds.size(); first += Slice)
  {
    const size_t last = std::min(this->TriangleIds.size(), first + Slice);
    slice.clear();
    for (size_t i = first; i < last; ++i)
    {
      for (int k = 0; k < 3; ++k)
      {
        slice.push_back(this->Element(i, k));
      }
    }
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLintptr>(3 * first * sizeof(GLuint)),
      static_cast<GLsizeiptr>(slice.size() * sizeof(GLuint)), slice.data());
  }
  glBindVertexArray(static_cast<GLuint>(callerArray));
  this->OnGPU = true;
  return true;
}

//------------------------------------------------------------------------------
GLuint CasterBuffers::Element(size_t i, int k) const
{
  const vtkIdType t = this->TriangleIds[i];
  const size_t b = this->Triangles->BlockIndex(t);
  const penumbra::SceneTriangles::Block& block = this->Triangles->GetBlocks()[b];
  return this->PointBase[b] + block.List->Corners[3 * static_cast<size_t>(t - block.First) + k];
}

//------------------------------------------------------------------------------
void CasterBuffers::Bind(vtkShaderProgram* program)
{
  glBindVertexArray(this->VertexArray);
  const GLint posLoc = glGetAttribLocation(program->GetHandle(), "vertexRebased");
  if (posLoc >= 0)
  {
    glBindBuffer(GL_ARRAY_BUFFER, this->Positions);
    glEnableVertexAttribArray(static_cast<GLuint>(posLoc));
    glVertexAttribPointer(static_cast<GLuint>(posLoc), 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
  }
  // The element buffer binding is part of the vertex array's state.
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, this->Elements);
}

//------------------------------------------------------------------------------
void CasterBuffers::Draw() const
{
  glDrawElements(GL_TRIANGLES, this->VertexCount, GL_UNSIGNED_INT, nullptr);
}

//------------------------------------------------------------------------------
void CasterBuffers::Release()
{
  if (this->VertexArray)
  {
    glDeleteVertexArrays(1, &this->VertexArray);
    glDeleteBuffers(1, &this->Positions);
    glDeleteBuffers(1, &this->Elements);
    glDeleteBuffers(1, &this->Indices);
  }
  this->Forget();
}

//------------------------------------------------------------------------------
void CasterBuffers::Forget()
{
  this->VertexArray = this->Positions = this->Elements = this->Indices = 0;
  this->OnGPU = false;
}
}
