/**
 * @file    vtkPenumbraCasterBuffers.h
 * @brief   The casters of a scene geometry as the map-based techniques use them: the caster
 *          list (the reference's IsOccluder rule), their exact triangles for the CPU tests,
 *          and their GL vertex buffers.
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
  void Reset(const std::vector<vtkIdType>& casters);

  /**
   * Caster `id`'s exact triangle from the geometry's `vertices` (9 per triangle), null when
   * it has no area; `scratch` holds it when another thread is making the cached one (or
   * nothing is cached).
   */
  const penumbra_rules::ExactTriangle* Get(
    vtkIdType id, const double* vertices, penumbra_rules::ExactTriangle& scratch);

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
 * bounds on the CPU, and on request as GL vertex buffers (positions, 3 floats rebased, and
 * triangle ids, one uint per vertex). Rebuilt only when the casters change
 * (penumbra::CastersStamp); uploaded only when asked and not yet on the GPU.
 */
struct CasterBuffers
{
  GLuint VertexArray = 0;
  GLuint Positions = 0;
  GLuint Ids = 0;
  GLuint Indices = 0;
  GLsizei VertexCount = 0;            // 3 per caster
  std::vector<float> Vertices;        // CPU copy of Positions
  std::vector<vtkIdType> TriangleIds; // the casters, ascending
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

  /**
   * Binds the caster vertex array with the positions as `program`'s `vertexRebased`
   * attribute (context current, buffers uploaded).
   */
  void Bind(vtkShaderProgram* program);

  /** Frees the GL objects (context current) and forgets what was uploaded. */
  void Release();

  /** Forgets the GL objects without freeing them (their context is gone). */
  void Forget();

private:
  penumbra::CastersStamp Current; // what the CPU lists were made from
  bool OnGPU = false;             // the GL buffers match the CPU lists
};
}

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraCasterBuffers.h
