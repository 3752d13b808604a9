/**
 * @file    vtkPenumbraCasterBuffers.h
 * @brief   The casters of a scene geometry as the map-based techniques use them: the caster
 *          list (the reference's IsOccluder rule), their exact triangles for the CPU tests,
 *          and their GL buffers (indexed: the scene's points, three indices per caster).
 *
 * Not wrapped and not installed.
 */

#ifndef vtkPenumbraCasterBuffers_h
#define vtkPenumbraCasterBuffers_h

#include "vtkPenumbraSceneGeometry.h"   // For penumbra::CastersStamp
#include "vtkPenumbraVisibilityRules.h" // For penumbra_rules::ExactTriangle
#include "vtkType.h"
#include "vtk_glew.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

class vtkShaderProgram;

namespace penumbra_casters
{
/**
 * A list of caster triangle ids, ascending or in any order, 32 bits each (a scene of 2^32
 * triangles would need over 130 GB for its geometry alone; CasterBuffers::Update lists none
 * of a larger one, and says so). The list 0, 1, ..., n - 1 (every triangle casts, the usual
 * scene) is held as its length alone (SetIdentity).
 */
class CasterIds
{
public:
  size_t size() const { return this->Identity ? this->Count : this->Ids.size(); }
  bool empty() const { return this->size() == 0; }
  std::uint32_t operator[](size_t i) const
  {
    return this->Identity ? static_cast<std::uint32_t>(i) : this->Ids[i];
  }
  std::uint32_t back() const { return (*this)[this->size() - 1]; }
  /** The list 0, 1, ..., count - 1, without storage. */
  void SetIdentity(size_t count)
  {
    std::vector<std::uint32_t>().swap(this->Ids);
    this->Identity = true;
    this->Count = count;
  }
  void reserve(size_t n) { this->Ids.reserve(n); }
  void push_back(std::uint32_t id)
  {
    this->Materialize();
    this->Ids.push_back(id);
  }
  void clear()
  {
    this->Identity = false;
    this->Count = 0;
    this->Ids.clear();
  }
  void shrink_to_fit() { this->Ids.shrink_to_fit(); }
  void resize(size_t n)
  {
    this->Materialize();
    this->Ids.resize(n);
  }
  std::uint32_t& at(size_t i)
  {
    this->Materialize();
    return this->Ids[i];
  }
  void swap(CasterIds& o)
  {
    std::swap(this->Identity, o.Identity);
    std::swap(this->Count, o.Count);
    this->Ids.swap(o.Ids);
  }
  /** Identifies the list for caches (equal while neither is changed). */
  const void* Key() const
  {
    return this->Identity ? static_cast<const void*>(this) : this->Ids.data();
  }

private:
  void Materialize()
  {
    if (this->Identity)
    {
      this->Identity = false;
      this->Ids.resize(this->Count);
      for (size_t i = 0; i < this->Count; ++i)
      {
        this->Ids[i] = static_cast<std::uint32_t>(i);
      }
      this->Count = 0;
    }
  }

  bool Identity = false;
  size_t Count = 0;
  std::vector<std::uint32_t> Ids;
};

/**
 * The exact triangles of the casters (the reference's double-precision form,
 * penumbra_rules::MakeExactTriangle), each made the first time a test needs it and kept while
 * the caster list does not change: a caster meets many samples, views and frames. Safe to
 * use from several threads. The cache is allocated in blocks of BlockSize casters on first
 * use, so it costs memory (200 bytes a triangle) only for the casters tests reach, not for
 * the whole list. Lists of more than MaxCached casters make them per test instead.
 */
class ExactTriangles
{
public:
  static constexpr size_t MaxCached = size_t(1) << 20;
  static constexpr size_t BlockSize = 1024;

  ExactTriangles() = default;
  ~ExactTriangles();
  ExactTriangles(const ExactTriangles&) = delete;
  ExactTriangles& operator=(const ExactTriangles&) = delete;

  /** Forgets the triangles made so far; `casters` (ascending ids) is the new list. */
  void Reset(const CasterIds& casters);

  /**
   * Caster `id`'s exact triangle from the geometry's `triangles`, null when it has no area;
   * `scratch` holds it when another thread is making the cached one (or nothing is cached).
   */
  const penumbra_rules::ExactTriangle* Get(vtkIdType id, const penumbra::SceneTriangles& triangles,
    penumbra_rules::ExactTriangle& scratch);

private:
  // The cached triangle of `slot`, its block allocated on the first call for that block.
  penumbra_rules::ExactTriangle& Slot(size_t slot);
  void Free();

  std::vector<std::int32_t> SlotOf; // per triangle id: its slot, -1 when not a caster
  size_t NumberOfBlocks = 0;
  std::unique_ptr<std::atomic<penumbra_rules::ExactTriangle*>[]> Blocks; // null: not yet
  // per slot: 0 not yet, 1 being made, 2 made, 3 no area
  std::unique_ptr<std::atomic<unsigned char>[]> Made;
};

/**
 * The caster triangles (IsOccluder, the reference's rule) of a scene geometry: their ids and
 * bounds on the CPU, their float32 corners read from the geometry's own storage (Float), and
 * on request as GL buffers: the rebased float32 points of every prop that has a caster, and
 * three point indices per caster (an element buffer; the casters' own order). No copy of the
 * corners is kept on the CPU. Rebuilt only when the casters change (penumbra::CastersStamp);
 * uploaded only when asked and not yet on the GPU.
 */
struct CasterBuffers
{
  GLuint VertexArray = 0;
  GLuint Positions = 0;
  GLuint Elements = 0;
  GLuint Indices = 0;      // a technique's own element list (e.g. per view)
  GLsizei VertexCount = 0; // 3 per caster: the elements of a whole draw
  CasterIds TriangleIds;   // the casters, ascending
  double Bounds[6] = { 1, -1, 1, -1, 1, -1 };
  ExactTriangles Exact; // the casters' exact triangles, reset with the list
  // Every triangle instead of the casters only (soft shadow maps find the receivers behind
  // a silhouette with them); set before the first Update.
  bool AllSurfaces = false;

  /**
   * Brings the caster list up to date and, with `upload` (context current), the GL buffers;
   * true when it uploaded.
   */
  bool Update(vtkPenumbraSceneGeometry* geometry, bool upload = true);

  /** Caster `i`'s corners relative to the geometry's origin, rounded to float32. */
  void Float(size_t i, float v[9]) const { this->Triangles->GetFloat(this->TriangleIds[i], v); }

  /** The index in the Positions buffer of corner `k` of caster `i`. */
  GLuint Element(size_t i, int k) const;

  /**
   * Binds the caster vertex array with the positions as `program`'s `vertexRebased`
   * attribute and the casters' element buffer (context current, buffers uploaded).
   */
  void Bind(vtkShaderProgram* program);

  /** Draws every caster (bound by Bind(); context current). */
  void Draw() const;

  /** Frees the GL objects (context current) and forgets what was uploaded. */
  void Release();

  /** Forgets the GL objects without freeing them (their context is gone). */
  void Forget();

private:
  penumbra::CastersStamp Current;                      // what the CPU lists were made from
  bool OnGPU = false;                                  // the GL buffers match the CPU lists
  const penumbra::SceneTriangles* Triangles = nullptr; // the geometry's, while Current holds
  static constexpr GLuint NoPoints = ~GLuint(0);
  std::vector<GLuint> PointBase; // per block of Triangles: its first point in Positions
};
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraCasterBuffers.h
