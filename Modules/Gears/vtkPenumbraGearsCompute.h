/**
 * @file   vtkPenumbraGearsCompute.h
 * @brief  Private to Penumbra::Gears: the GL 4.3 compute path of vtkPenumbraGearsShadows
 *         (step 4 of Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for
 *         Rendering Shadows", Computer Graphics Forum 33(6), 2014, on the GPU, SSBO cell
 *         lists).
 *
 * The CPU builds the grid and the per-cell triangle lists (Wang et al. 2014, §4, A.1-A.3) as
 * before; this helper uploads them as shader storage buffers and runs
 * glsl/vtkPenumbraGearsMaskCS.glsl, one invocation per view sample in cell order. The shader
 * decides every light sample it can with the CPU path's double-precision margins and flags the view
 * samples it cannot (a ray on a triangle edge, a light-sample ray too close to call against
 * Embree's float32 ray, a float32 rounding the CPU path takes exactly); vtkPenumbraGearsShadows
 * redoes the flagged samples on the CPU, so both paths give the reference's visibility bit for bit.
 *
 * Mesa llvmpipe ends every loop of a shader silently once the loops of one invocation group
 * have run 65535 iterations in all (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS); a sample with a
 * long cell list (a huge light over a fine mesh) would lose blockers. The shader ends with a
 * loop of a uniform 2 iterations that runs once after that point, and flags the sample.
 *
 * Needs an OpenGL 4.3 context (compute shaders, shader storage buffers; double precision is
 * core since 4.0), at least 12 storage blocks in a compute shader and at most 32 light
 * samples per row. Prepare() says why when any of it is missing.
 *
 * The context check, storage buffers and compilation are the module's shared compute device
 * (vtkPenumbraCompute.h): the program is compiled once per (k, rows, masks) and its uniform
 * locations are looked up once.
 */

#ifndef vtkPenumbraGearsCompute_h
#define vtkPenumbraGearsCompute_h

#include "vtkPenumbraCompute.h"
#include "vtkType.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

class vtkOpenGLRenderWindow;
class vtkWindow;

namespace penumbra_gears
{
/// The light's sampling in the geometry's rebased frame (LightSamples of the CPU path).
struct ComputeLight
{
  int K = 1;
  int Rows = 1;
  const double* Points = nullptr; // 3 per light sample, index j K + i
  double Centre[3] = { 0, 0, 0 };
  double U[3] = { 1, 0, 0 };
  double V[3] = { 0, 1, 0 };
  double N[3] = { 0, 0, 1 };
  double Su0 = 0, DSu = 0, Sv0 = 0, DSv = 0;
  std::uint32_t Emitting[32] = {}; // per row: the cells that hold light samples (bit i)
};

/// Per-call constants of the reference's rays.
struct ComputeConstants
{
  double Shift[3] = { 0, 0, 0 }; // samples' origin minus the geometry's origin
  double Epsilon = 0;
  double TieFactor = 1;
  double Diagonal = 1;
  double RelativeTolerance = 1e-6;
};

/// One side of the light plane: its grid lists and its work items.
struct ComputeSide
{
  double Flip = 1;
  double FarSlack = 0;
  const double* ZNear = nullptr;            // per caster, on this side
  const std::uint32_t* CellStart = nullptr; // Cells + 1 entries
  std::size_t Cells = 0;
  const std::uint32_t* CellList = nullptr;
  std::size_t ListSize = 0;
  const std::uint32_t* GlobalList = nullptr;
  std::size_t GlobalSize = 0;
  const std::uint32_t* Work = nullptr; // (sample, cell) pairs in cell order
  std::size_t WorkCount = 0;
};

/// Marks a flagged work item in Run()'s results.
constexpr std::uint32_t Flagged = 0xFFFFFFFFu;
/// Doubles per caster in SetCasters()'s array: V (9), N (3), edge normals M (9), M.V (3),
/// triangle id (1), bounding-sphere centre (3) and radius (1).
constexpr int CasterStride = 29;

class MaskCompute
{
public:
  MaskCompute() = default;
  ~MaskCompute();
  MaskCompute(const MaskCompute&) = delete;
  MaskCompute& operator=(const MaskCompute&) = delete;

  /**
   * Makes `window`'s context current, checks the GL features and compiles the program for
   * this sampling on first use. False, with the reason in `why`, when the path cannot run.
   */
  bool Prepare(vtkOpenGLRenderWindow* window, int k, int rows, bool keepMasks, std::string& why);

  /// Uploads the casters when `version` differs from the last upload's.
  bool SetCasters(const std::vector<double>& data, std::uint64_t version, std::string& why);

  /// Uploads the view samples of this call (positions, normals, own triangle ids).
  bool SetSamples(const float* positions, const float* normals, const vtkIdType* owners,
    vtkIdType count, std::string& why);

  /**
   * Runs one side. `results` receives 3 values per work item (unoccluded light samples or
   * Flagged, necessary assignments, segment tests); `masks`, when given (the program must
   * have been prepared with keepMasks), `rows` lit-mask words per work item.
   */
  bool Run(const ComputeLight& light, const ComputeConstants& constants, const ComputeSide& side,
    std::vector<std::uint32_t>& results, std::vector<std::uint32_t>* masks, std::string& why);

  /// Frees the program and buffers (the window's context is made current first).
  void Release(vtkWindow* window);

private:
  struct Program
  {
    unsigned int Id = 0;
    int Rows = 1;
    // Uniform locations, looked up once after linking.
    int Centre = -1, AxisU = -1, AxisV = -1, AxisN = -1, Shift = -1, Su0 = -1, DSu = -1, Sv0 = -1,
        DSv = -1, Epsilon = -1, TieFactor = -1, Diagonal = -1, FarSlack = -1, Flip = -1,
        RelativeTolerance = -1, WorkOffset = -1, WorkCount = -1, GlobalCount = -1, HasCasters = -1,
        LoopProbe = -1, Emitting = -1;
  };
  enum Buffer
  {
    Casters,
    ZNear,
    CellStart,
    CellList,
    GlobalList,
    Positions,
    Normals,
    Owners,
    Work,
    LightPoints,
    Results,
    Masks,
    BufferCount
  };

  bool Compile(int k, int rows, bool keepMasks, Program& program, std::string& why);

  penumbra_compute::Device Device;
  std::uint64_t Generation = 0;    // the Device generation Programs belong to
  std::map<int, Program> Programs; // key: (k, rows, masks)
  Program* Current = nullptr;
  std::uint64_t CasterVersion = 0;
  std::size_t CasterCount = 0;
};
}

#endif
