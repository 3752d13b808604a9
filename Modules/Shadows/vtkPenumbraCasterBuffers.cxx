#include "vtkPenumbraCasterBuffers.h"

#include "vtkDoubleArray.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkShaderProgram.h"
#include "vtkUnsignedCharArray.h"

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
void ExactTriangles::Reset(const std::vector<vtkIdType>& casters)
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
  vtkIdType id, const double* vertices, penumbra_rules::ExactTriangle& scratch)
{
  const std::int32_t slot =
    static_cast<size_t>(id) < this->SlotOf.size() ? this->SlotOf[static_cast<size_t>(id)] : -1;
  if (slot >= 0)
  {
    std::atomic<unsigned char>& made = this->Made[static_cast<size_t>(slot)];
    unsigned char state = made.load(std::memory_order_acquire);
    if (state == 0 && made.compare_exchange_strong(state, 1, std::memory_order_acq_rel))
    {
      penumbra_rules::ExactTriangle& t = this->Slot(static_cast<size_t>(slot));
      const bool area = penumbra_rules::MakeExactTriangle(vertices + 9 * id, id, t);
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
  return penumbra_rules::MakeExactTriangle(vertices + 9 * id, id, scratch) ? &scratch : nullptr;
}

//------------------------------------------------------------------------------
bool CasterBuffers::Update(vtkPenumbraSceneGeometry* geometry, bool upload)
{
  if (this->Current.Changed(geometry))
  {
    const vtkIdType nTriangles = geometry->GetNumberOfTriangles();
    vtkDoubleArray* vertexArray = geometry->GetVertices();
    const double* v = nTriangles && vertexArray ? vertexArray->GetPointer(0) : nullptr;
    // The lists are sized exactly (the casters first, then their positions): grown by
    // push_back they would hold up to twice their size, at 36 bytes a caster.
    this->Vertices.clear();
    this->Vertices.shrink_to_fit();
    this->TriangleIds.clear();
    this->TriangleIds.shrink_to_fit();
    // The reference's rule: casters with area (a zero-area triangle blocks no ray).
    auto listed = [&](vtkIdType t) { return this->AllSurfaces || geometry->IsOccluder(t); };
    vtkIdType count = 0;
    for (vtkIdType t = 0; v && t < nTriangles; ++t)
    {
      count += listed(t) ? 1 : 0;
    }
    std::vector<vtkIdType> casters;
    casters.reserve(static_cast<size_t>(count));
    for (vtkIdType t = 0; v && t < nTriangles; ++t)
    {
      if (listed(t))
      {
        casters.push_back(t);
      }
    }
    std::vector<float> xyz(9 * casters.size());
    double* bounds = this->Bounds;
    bounds[0] = bounds[2] = bounds[4] = std::numeric_limits<double>::max();
    bounds[1] = bounds[3] = bounds[5] = -std::numeric_limits<double>::max();
    for (size_t i = 0; i < casters.size(); ++i)
    {
      const double* p = v + 9 * casters[i];
      for (int c = 0; c < 9; ++c)
      {
        xyz[9 * i + c] = static_cast<float>(p[c]);
        bounds[2 * (c % 3)] = std::min(bounds[2 * (c % 3)], p[c]);
        bounds[2 * (c % 3) + 1] = std::max(bounds[2 * (c % 3) + 1], p[c]);
      }
    }
    this->VertexCount = static_cast<GLsizei>(xyz.size() / 3);
    this->Vertices.swap(xyz);
    this->TriangleIds.swap(casters);
    this->Exact.Reset(this->TriangleIds);
    this->Current.Remember(geometry);
    this->OnGPU = false;
  }
  if (!upload || this->OnGPU)
  {
    return false;
  }
  std::vector<std::uint32_t> ids;
  ids.reserve(this->Vertices.size() / 3);
  for (vtkIdType t : this->TriangleIds)
  {
    ids.insert(ids.end(), 3, static_cast<std::uint32_t>(t));
  }
  if (!this->VertexArray)
  {
    glGenVertexArrays(1, &this->VertexArray);
    glGenBuffers(1, &this->Positions);
    glGenBuffers(1, &this->Ids);
    glGenBuffers(1, &this->Indices);
  }
  glBindBuffer(GL_ARRAY_BUFFER, this->Positions);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(this->Vertices.size() * sizeof(float)),
    this->Vertices.empty() ? nullptr : this->Vertices.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, this->Ids);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(ids.size() * sizeof(std::uint32_t)),
    ids.empty() ? nullptr : ids.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  this->OnGPU = true;
  return true;
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
}

//------------------------------------------------------------------------------
void CasterBuffers::Release()
{
  if (this->VertexArray)
  {
    glDeleteVertexArrays(1, &this->VertexArray);
    glDeleteBuffers(1, &this->Positions);
    glDeleteBuffers(1, &this->Ids);
    glDeleteBuffers(1, &this->Indices);
  }
  this->Forget();
}

//------------------------------------------------------------------------------
void CasterBuffers::Forget()
{
  this->VertexArray = this->Positions = this->Ids = this->Indices = 0;
  this->OnGPU = false;
}
}
