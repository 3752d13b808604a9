/**
 * @class   vtkPenumbraGearsShadows
 * @brief   Soft shadows from rectangular and linear area lights the GEARS way (Wang, Wang,
 *          Shi, Popescu, "GEARS: A General and Efficient Algorithm for Rendering Shadows",
 *          Computer Graphics Forum 33(6), 2014): a per-frame grid of conservative potential-blocker
 *          lists and a k x k light-sample bit mask per view sample, bit-exact against the
 *          ray-traced reference.
 *
 * Per area light and frame (CPU, vtkSMPTools; everything rebuilt from scratch, so blockers,
 * receivers and the light may all move):
 * 1. Light frame: origin at the light centre, x/y along the light's U/V axes, z along its
 *    emission direction. Samples with z > 0 form the front side, samples with z < 0 the back
 *    side (the reference traces both: it has no single-sided emitter rule), each side gets
 *    its own grid in a light frame mirrored for the back. A sample exactly on the light
 *    plane is handed to the reference.
 * 2. Grid (Wang et al. 2014, §4, A.1-A.2): camera C behind the light on the line from the samples'
 *    centre through the light centre at CameraDistanceFactor x light diagonal, image plane
 *    = far plane through the farthest sample; samples are binned by their projection from C
 *    into GridResolution^2 cells over the projections' bounding box; empty cells cost nothing.
 * 3. Triangle assignment (A.3, in closed form in the light's frame): each caster triangle's
 *    footprint is the bounding box of its 12 extrusion points F_ij (vertex i seen from the
 *    light-sample extremes j, continued to the far plane) and its 3 projections from C, padded by
 *    the position tolerance; it contains every sample the triangle can shadow (the proof of the
 *    paper's App. A holds for any camera C strictly behind the light plane).
 *    Triangles wholly behind the light plane or beyond the far plane are culled; triangles
 *    touching the light plane (their extrusion is unbounded) and triangles whose footprint
 *    covers more than half the occupied cells go to one global list every sample tests.
 *    List sizes are counted in 64 bits; when they would exceed MaxListEntries the grid is
 *    coarsened (with a warning) until they fit; at 1 x 1 every triangle is global, so no
 *    blocker is ever dropped.
 * 4. Masks (step 4): per view sample, the light samples below its tangent plane are cleared
 *    exactly as the reference does; then for each triangle of its cell (and the global list)
 *    the light samples that the triangle can possibly block are found per mask row as one
 *    interval of the affine edge/plane functions (an exact cone-and-plane predicate, with a
 *    margin), and each of them is decided by a double-precision segment test against the
 *    reference's ray (same origin, epsilons, tie band, own-triangle exclusion); deep inside all
 *    intervals whole spans are set at once. A bit the double test cannot decide against Embree's
 *    float32 ray (within 1e-6 of the scene scale of an edge, of the tie band or of the ray
 *    end; a ray on an edge shared by two triangles that face it from both sides counts as
 *    blocked, as Embree's watertight test guarantees) is traced by vtkPenumbraReference
 *    (TraceAreaRays()) with its exact rules, so the visibility equals the reference's bit
 *    for bit. GetUncertainFraction() reports the share of samples with such rays. The 1e-6
 *    tolerance is an empirical bound on Embree's float32 error (about 8 ulps of the scene
 *    scale), not a proof: TestGearsShadows and penumbra-bench found no differing sample.
 *    Before any of this, cheap rejects skip a triangle: farther from the light plane than
 *    the sample, bounding sphere outside the sample's cone around the light, plane not
 *    separating the sample from the light, every hit provably inside the tie band. Cell
 *    lists are sorted largest triangle first, so umbra samples fill their masks early.
 *    Cells whose list is longer than TraceThreshold x k^2 (counted from the casters' cell
 *    ranges before any list is built) skip all of this: their samples are ray traced whole
 *    by the reference (DenseCells = DENSE_TRACE, the default), or masked from a walk of a
 *    bounding volume hierarchy over the casters that skips whatever cannot reach a light
 *    sample still open (DENSE_TREE). A mask costs O(k) per listed triangle and a ray
 *    O(log N), so on dense meshes under large lights, where a cell meets thousands of
 *    triangles each smaller than the light-sample spacing, the rays are cheaper (the GEARS
 *    paper's Table 3: cost grows with the light). The answer is the reference's either way.
 *
 * Paths (SetPath()): step 4 runs on the CPU (vtkSMPTools) or as a GL 4.3 compute shader
 * (vtkPenumbraGearsCompute.h: the cell lists in shader storage buffers, one invocation per
 * view sample, double precision with the CPU path's margins). The shader flags the view
 * samples whose decision needs the CPU path's per-light-sample bookkeeping (a ray on a
 * triangle edge, a bit too close to call against Embree), and those are redone on the CPU,
 * so both paths give the same visibility bit for bit. Steps 1-3 stay on the CPU either way.
 *
 * Visibility = unoccluded fraction of the k x k (Line: k) light samples, the reference's
 * float(lit) / float(n). Samples facing away from the whole light get 0 without any work.
 *
 * Light samples: with SamplesPerAxis = 0 (default) the light's own k and positions
 * (vtkPenumbraAreaLight::GetSamplePosition) are used, so the result equals
 * vtkPenumbraRayTracedShadows on the same light. A nonzero SamplesPerAxis overrides k with
 * the same cell-centre formula (the reference then runs on a copy of the light with that k).
 *
 * Other lights: GEARS is an area-light algorithm. Point, spot and directional lights are
 * ray traced by the exact reference (one ray per sample, as vtkPenumbraRayTracedShadows does),
 * so a scene mixing light types still renders every light correctly; GetLastLightWasArea()
 * tells which path the last call took.
 */

#ifndef vtkPenumbraGearsShadows_h
#define vtkPenumbraGearsShadows_h

#include "vtkPenumbraGearsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr

class vtkPenumbraReference;
class vtkTypeUInt32Array;
class vtkUnsignedCharArray;
class vtkPenumbraStatistics;

class VTKPENUMBRAGEARS_EXPORT vtkPenumbraGearsShadows : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraGearsShadows* New();
  vtkTypeMacro(vtkPenumbraGearsShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  ///@{
  /**
   * Light samples per axis k (k x k for a rectangle, k for a line). 0 (default) uses the
   * light's own SamplesPerAxis; otherwise 1..64 (the registry accepts 4, 8, 16, 32, the
   * paper's values). No unit.
   */
  vtkSetClampMacro(SamplesPerAxis, int, 0, 64);
  vtkGetMacro(SamplesPerAxis, int);
  ///@}

  ///@{
  /**
   * Grid cells per side (the grid covers the projected view samples). Default 128, the
   * paper's best (Wang et al. 2014, Table 4); clamped to [1, 4096]. Only speed depends on it: the
   * result is identical for every resolution.
   */
  vtkSetClampMacro(GridResolution, int, 1, 4096);
  vtkGetMacro(GridResolution, int);
  ///@}

  ///@{
  /**
   * Distance of the grid camera C behind the light centre, as a multiple of the light's
   * diagonal (the paper's unnamed proportionality constant); at least 1e-3 of the far-plane
   * depth. Default 1, clamped to [0.01, 100]. Only the tightness of the lists depends on it.
   */
  vtkSetClampMacro(CameraDistanceFactor, double, 0.01, 100.0);
  vtkGetMacro(CameraDistanceFactor, double);
  ///@}

  ///@{
  /**
   * Upper bound on the total length of the per-cell triangle lists (entries of 4 bytes).
   * Default 1 << 27 (512 MiB), clamped to [1024, 1 << 31]. Beyond it the grid is coarsened
   * with a warning (see GetEffectiveGridResolution()); nothing is dropped.
   */
  vtkSetClampMacro(MaxListEntries, vtkIdType, 1024, vtkIdType(1) << 31);
  vtkGetMacro(MaxListEntries, vtkIdType);
  ///@}

  ///@{
  /**
   * Triangles per light sample above which a grid cell's view samples are ray traced whole
   * by the reference instead of masked: a cell whose list (cell + global) holds more than
   * TraceThreshold x k^2 triangles costs more in masks than Embree's k^2 rays, as on dense
   * meshes under large lights, where each tiny triangle covers less than one light sample.
   * The answer is the same either way (the reference is the exact one); only speed depends
   * on it. Default 0.5: above the city block's longest lists (33 triangles) at k >= 8, far
   * below a dense mesh's thousands; 0 never traces a cell. Only the CPU path splits cells
   * (the compute path masks every cell). No unit.
   */
  vtkSetClampMacro(TraceThreshold, double, 0.0, 1e6);
  vtkGetMacro(TraceThreshold, double);
  ///@}

  /**
   * What happens to the view samples of a cell above TraceThreshold (a dense cell).
   * - DENSE_TRACE (default): the samples are ray traced whole by the reference.
   * - DENSE_TREE: masks as in every other cell, but from a walk of a bounding volume
   *   hierarchy over all casters (built once per caster set) instead of the cell list: a
   *   node is skipped when it lies outside the sample's pyramid to the light, beyond the
   *   sample's depth, or projects only onto light samples that are blocked already
   *   (vtkPenumbraGearsTree.h). Measured slower than DENSE_TRACE on the dense bench
   *   scenes (docs/gears.md), hence not the default.
   * The answer is the reference's either way; only speed depends on it.
   */
  enum DenseModes
  {
    DENSE_TRACE = 0,
    DENSE_TREE = 1
  };
  vtkSetClampMacro(DenseCells, int, DENSE_TRACE, DENSE_TREE);
  vtkGetMacro(DenseCells, int);
  void SetDenseCellsToTree() { this->SetDenseCells(DENSE_TREE); }
  void SetDenseCellsToTrace() { this->SetDenseCells(DENSE_TRACE); }

  /**
   * Where step 4 (the masks) runs.
   * - PATH_AUTO (default): PATH_CPU. On Mesa llvmpipe, the project's target, the compute
   *   shader runs on the same CPU cores as the CPU path and is not cheaper than its 64-bit
   *   rows and early rejects (docs/gears.md).
   * - PATH_CPU: vtkSMPTools over the busy cells.
   * - PATH_GPU: the GL 4.3 compute shader; needs the renderer's OpenGL window (4.3 context)
   *   and at most 32 light samples per row. When it cannot run, a warning says why (once
   *   per reason) and the CPU path is used; GetLastPath() tells which ran.
   */
  enum Paths
  {
    PATH_AUTO = 0,
    PATH_CPU = 1,
    PATH_GPU = 2
  };
  vtkSetClampMacro(Path, int, PATH_AUTO, PATH_GPU);
  vtkGetMacro(Path, int);

  /**
   * The path the last area-light call's masks took (PATH_CPU or PATH_GPU; PATH_AUTO before
   * any area-light call).
   */
  vtkGetMacro(LastPath, int);

  /**
   * Why the last call could not use the compute path it was asked for (empty when it did,
   * or when it was not asked for).
   */
  const char* GetPathMessage();

  /**
   * Compute path: view samples of the last area-light call the shader flagged and the CPU
   * path redid (see the class description); 0 on the CPU path.
   */
  vtkGetMacro(NumberOfFlaggedSamples, vtkIdType);

  void ReleaseGraphicsResources(vtkWindow* window) override;

  ///@{
  /**
   * When on, the last call keeps every sample's light-sample bit mask (GetMasks()). Off by
   * default (costs k^2 bits per sample). For tests.
   */
  vtkSetMacro(KeepMasks, bool);
  vtkGetMacro(KeepMasks, bool);
  vtkBooleanMacro(KeepMasks, bool);
  ///@}

  /**
   * With KeepMasks on, per sample of the last area-light call: ceil(n / 32) 32-bit words, bit
   * j set when light sample j is above the tangent plane and unoccluded (the layout of
   * vtkPenumbraReference::ComputeAreaMasks). Uncertain samples (GetUncertainSamples()) and
   * invalid samples hold zeros.
   */
  vtkTypeUInt32Array* GetMasks();

  /**
   * Per sample of the last area-light call: 1 when the whole sample was handed to the
   * reference (it lies exactly on the light plane, or in a cell above TraceThreshold; its
   * mask is not kept).
   */
  vtkUnsignedCharArray* GetUncertainSamples();

  /**
   * Share of the last area-light call's valid samples that needed the reference for at least
   * one light sample (or whole); 0 for other lights.
   */
  double GetUncertainFraction() override;

  /// Area and linear lights are what GEARS is for.
  bool HandlesAreaLights() override { return true; }

  const char* GetTechniqueName() override { return "gears"; }

  /** Hard lights are ray traced at every sample, as `raytraced` does. */
  const char* GetTechniqueNameFor(vtkLight* light) override;

  ///@{
  /**
   * Statistics of the last area-light call (Wang et al. 2014, Tables 5 and 6), summed over both
   * sides of the light plane:
   * - cells with at least one view sample, and all cells;
   * - triangles per occupied cell, maximum and average (global-list triangles not included);
   * - triangles in the global list (tested by every sample);
   * - assignments: sum over processed samples of the triangles they had to consider (cell
   *   list + global list);
   * - necessary assignments: those where the triangle blocks at least one light sample that
   *   no earlier triangle of the list blocked (a sample stops early once fully shadowed, so
   *   this is a lower bound of the paper's count);
   * - the grid resolution actually used after any overflow coarsening;
   * - samples handed to the reference whole: on the light plane (uncertain), and those of
   *   cells above TraceThreshold with DENSE_TRACE (traced cells); samples of cells above
   *   TraceThreshold masked from the tree walk (DENSE_TREE; their assignments are the
   *   triangles the walk visited); single light-sample rays the reference traced, and the
   *   samples those belong to;
   * - segment tests run in double precision.
   */
  vtkGetMacro(NumberOfOccupiedCells, vtkIdType);
  vtkGetMacro(NumberOfCells, vtkIdType);
  vtkGetMacro(MaxTrianglesPerCell, vtkIdType);
  vtkGetMacro(AverageTrianglesPerCell, double);
  vtkGetMacro(NumberOfGlobalTriangles, vtkIdType);
  vtkGetMacro(NumberOfAssignments, vtkIdType);
  vtkGetMacro(NumberOfNecessaryAssignments, vtkIdType);
  vtkGetMacro(EffectiveGridResolution, int);
  vtkGetMacro(NumberOfUncertainSamples, vtkIdType);
  vtkGetMacro(NumberOfTracedCellSamples, vtkIdType);
  vtkGetMacro(NumberOfTreeSamples, vtkIdType);
  vtkGetMacro(NumberOfTracedRays, vtkIdType);
  vtkGetMacro(NumberOfSamplesWithTracedRays, vtkIdType);
  vtkGetMacro(NumberOfSegmentTests, vtkIdType);
  ///@}

  /**
   * Necessary / total assignments of the last area-light call, in [0, 1] (0 if none).
   */
  double GetBlockingShare();

  ///@{
  /**
   * Phase times of the last area-light call in milliseconds: grid build (frames, binning,
   * triangle lists), masks, and ray tracing of the uncertain samples.
   */
  vtkGetMacro(GridTimeMs, double);
  vtkGetMacro(MaskTimeMs, double);
  vtkGetMacro(TraceTimeMs, double);
  ///@}

  /**
   * Whether the last ComputeVisibility() call handled an area light with GEARS (true) or
   * another light type with the reference (false).
   */
  vtkGetMacro(LastLightWasArea, bool);

  /**
   * The reference that traces uncertain samples and non-area lights.
   */
  vtkPenumbraReference* GetReference() { return this->Reference; }

protected:
  vtkPenumbraGearsShadows();
  ~vtkPenumbraGearsShadows() override;

  int SamplesPerAxis = 0;
  int GridResolution = 128;
  double CameraDistanceFactor = 1.0;
  vtkIdType MaxListEntries = vtkIdType(1) << 27;
  double TraceThreshold = 0.5;
  int DenseCells = DENSE_TRACE;
  bool KeepMasks = false;
  int Path = PATH_AUTO;
  int LastPath = PATH_AUTO;
  vtkIdType NumberOfFlaggedSamples = 0;

  vtkIdType NumberOfOccupiedCells = 0;
  vtkIdType NumberOfCells = 0;
  vtkIdType MaxTrianglesPerCell = 0;
  double AverageTrianglesPerCell = 0.0;
  vtkIdType NumberOfGlobalTriangles = 0;
  vtkIdType NumberOfAssignments = 0;
  vtkIdType NumberOfNecessaryAssignments = 0;
  int EffectiveGridResolution = 0;
  vtkIdType NumberOfValidSamples = 0;
  vtkIdType NumberOfUncertainSamples = 0;
  vtkIdType NumberOfTracedCellSamples = 0;
  vtkIdType NumberOfTreeSamples = 0;
  vtkIdType NumberOfSegmentTests = 0;
  vtkIdType NumberOfTracedRays = 0;
  vtkIdType NumberOfSamplesWithTracedRays = 0;
  double GridTimeMs = 0.0;
  double MaskTimeMs = 0.0;
  double TraceTimeMs = 0.0;
  bool LastLightWasArea = false;

  vtkPenumbraReference* Reference;

private:
  vtkPenumbraGearsShadows(const vtkPenumbraGearsShadows&) = delete;
  void operator=(const vtkPenumbraGearsShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
