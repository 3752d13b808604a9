/**
 * @file   vtkPenumbraLinkedListInternals.h
 * @brief  The state of a vtkPenumbraLinkedListShadows shared by its files: the phases and the
 *         tracing (vtkPenumbraLinkedListShadows.cxx), the per-texel lists
 *         (vtkPenumbraLinkedListLists.cxx), the caster culling (vtkPenumbraLinkedListCulling.cxx)
 *         and the exact tests of casters against the listed samples
 *         (vtkPenumbraLinkedListTests.cxx). Private to the module.
 */

#ifndef vtkPenumbraLinkedListInternals_h
#define vtkPenumbraLinkedListInternals_h

#include "vtkPenumbraLinkedListShadows.h"

#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkUnsignedCharArray.h"

#include "vtkPenumbraCasterBuffers.h"
#include "vtkPenumbraLightViews.h"
#include "vtkPenumbraLinkedListCompute.h"

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

class vtkRenderer;

namespace penumbra_llsm
{
using penumbra::Clock;
using penumbra::ElapsedMs;
using penumbra_light_views::View;
using penumbra_rules::Hit;

// Per-sample states. The first two are also the values of the mask the reference traces.
enum : unsigned char
{
  Settled = 0, // decided: lit, or shadowed with visibility 0 written
  Pending = 1, // to be listed; after the lists: to be traced
  Open = 2,    // listed, no triangle has decided it yet (lit if it stays so)
  Unknown = 3, // listed, a triangle could not be decided: traced unless another shadows it
  Shadowed = 4 // listed, a triangle provably blocks its ray
};

// Everything a sample test needs, for one light and call.
struct TestContext
{
  const penumbra_light_views::FrameInputs* In;
  double Diagonal;
  double Epsilon;
  double TieFactor;
  unsigned char* State;
  const double* Depth; // per sample: its stored depth in its view

  void Position(vtkIdType s, double p[3]) const
  {
    for (int c = 0; c < 3; ++c)
    {
      p[c] = static_cast<double>(this->In->Positions[3 * s + c]) + this->In->Shift[c];
    }
  }

  // The reference's decision for sample s and `triangle` (null: a triangle without area,
  // left to the tracer): a clear hit shadows, an undecidable one leaves it to the tracer
  // unless another triangle shadows it.
  void Test(vtkIdType s, const penumbra_rules::ExactTriangle* triangle) const
  {
    this->Test(s, this->Ray(s), triangle);
  }

  // Sample s's shadow ray, as the reference makes it.
  penumbra_light_views::ShadowRay Ray(vtkIdType s) const
  {
    double p[3];
    this->Position(s, p);
    return penumbra_light_views::MakeShadowRay(
      this->In->Light, p, this->Diagonal, this->Epsilon, this->TieFactor);
  }

  // The same with the sample's ray made already.
  void Test(vtkIdType s, const penumbra_light_views::ShadowRay& ray,
    const penumbra_rules::ExactTriangle* triangle) const
  {
    const Hit hit = triangle ? penumbra_light_views::TestShadowRay(ray, *triangle) : Hit::Unknown;
    if (hit == Hit::Clear)
    {
      this->State[s] = Shadowed;
    }
    else if (hit == Hit::Unknown)
    {
      this->State[s] = Unknown;
    }
  }
};

// The conservative depth test of Hertel et al. 2009, §4.2, as the conservative technique
// uses it: a triangle whose smallest stored depth over the texel lies beyond the sample's
// depth cannot meet the sample's ray, which runs towards smaller depths.
inline bool Behind(float triangleDepth, double sampleDepth)
{
  return triangleDepth > sampleDepth + 1e-6 * (1.0 + std::fabs(sampleDepth));
}

// Texels a footprint's box may reach beyond the box of its projected vertices: the
// rasterizer's quarter-texel growth plus a texel for rounding (as its own tile cull).
constexpr double BoxMargin = 1.25;

// Defined in vtkPenumbraLinkedListCulling.cxx.
bool BoundPoints(
  const View& view, int size, const double* points, int count, double box[4], float& lower);

// The coarse occupancy of one pass's listed samples: per cell of Cell x Cell texels the
// largest stored depth of its samples (-inf when it holds none), as a max pyramid so a box
// query visits few cells. A caster whose box covers no occupied cell, or that lies behind the
// farthest sample of every occupied cell it covers, can decide no listed sample: each of them
// would skip it (Behind), or it touches no texel with a list.
struct SampleCells
{
  int Size = 0;
  int Cell = 1;
  std::vector<int> Dim;                 // cells per side, per level
  std::vector<std::vector<double>> Max; // per level, Dim^2 cells

  void Build(int size, const vtkIdType* samples, vtkIdType count,
    const std::vector<vtkIdType>& texel, const double* depth);
  bool Culled(const double box[4], float lower) const;

private:
  bool Live(int level, const int range[4], float lower, int px = -1, int py = -1) const;
};

// Caster triangles grouped for culling: sorted along a Morton curve of their centroids and
// cut into runs of ClusterSize, each with its bounding box, so most of a view's culling is
// decided per cluster. Rebuilt when the caster list changes.
constexpr vtkIdType ClusterSize = 32;

struct CasterClusters
{
  const void* Source = nullptr; // the caster list it was built from (CasterIds::Key)
  size_t SourceSize = 0;
  const penumbra::SceneTriangles* Vertices = nullptr;
  vtkMTimeType Time = 0;
  penumbra_casters::CasterIds Order; // caster ids, Morton order
  std::vector<double> Boxes;         // 6 per cluster: x0, x1, y0, y1, z0, z1

  bool Update(const penumbra_casters::CasterIds& casters, const penumbra::SceneTriangles* vertices,
    vtkMTimeType time);
  vtkIdType Cull(const View& view, int size, const SampleCells& cells,
    const penumbra::SceneTriangles& vertices, std::vector<unsigned char>& keep,
    penumbra_casters::CasterIds& kept) const;
};

// Defined in vtkPenumbraLinkedListLists.cxx.
void ProjectSamples(const View& view, int size, signed char viewIndex,
  const std::vector<signed char>& sampleView, const TestContext& ctx,
  const std::vector<vtkIdType>& pending, std::vector<vtkIdType>& texel, std::vector<double>& depth,
  std::vector<float>& point, std::vector<vtkIdType>& listed);

// The per-texel lists of one pass (Johnson et al. 2005's grid of lists, as Ferko 2014 builds
// it: head pointers and a node pool of (sample, next) links). The CPU builds them as a sort
// by texel, each node linking to the next of its texel; the GPU (ListCompute) by atomic
// counter and head exchange, in any order within a list. The rasterizer walks either by the
// links. Head and Active have a value per texel and are reset only where a list was, so a
// pass with few samples costs no full-grid clear. Sample ids are pixel indices (32 bits).
struct Lists
{
  std::vector<std::uint32_t> Head;       // per texel: first node, NoNode when empty
  std::vector<unsigned char> Active;     // per texel: holds an undecided sample
  std::vector<std::uint32_t> Nodes;      // per node: sample id, next node (NoNode: list end)
  std::vector<std::uint32_t> NodeTexel;  // per node: its texel
  std::vector<vtkIdType> Samples;        // the pass's samples, in node order
  std::vector<vtkIdType> Counts;         // dense CPU passes: the counting sort's rows
  std::vector<std::uint32_t> Items;      // GPU passes: (sample, texel) pairs
  std::vector<std::uint32_t> TexelHeads; // GPU passes: per node, its texel's head

  void Reserve(int size);
  void BuildOnCPU(
    int size, const vtkIdType* first, vtkIdType count, const std::vector<vtkIdType>& texel);
  bool BuildOnGPU(ListCompute& compute, int size, const std::vector<vtkIdType>& listed,
    vtkIdType capacity, const std::vector<vtkIdType>& texel, const unsigned char* state,
    bool& overflow, std::string& why);
  vtkIdType Finish(unsigned char* state, vtkIdType& rows);
  void Clear();
};

// Defined in vtkPenumbraLinkedListTests.cxx.
vtkIdType RasterizeLists(const View& view, int size, const TestContext& ctx,
  const penumbra_casters::CasterIds& casters, Lists& lists, penumbra_casters::ExactTriangles& exact,
  std::vector<vtkIdType>& nearTriangles);

// Passes with few listed samples for their casters (fewer than SparseFactor per caster, as the
// hybrid's hard samples): instead of every caster's conservative footprint (clipping and
// separating axes, the setup that dominates when few texels hold a list), each caster's
// light-space box (BoundPoints: its projection plus a margin for rounding) is binned to bands
// of BandRows grid rows, and meets the listed texels its box overlaps, found by a search per
// row. Per sample, MayBlock then skips the casters the exact test would call a miss (its
// depth plane beyond the sample, or the sample's point outside its projection by more than
// the test's own slack), and the rest get the exact test. A box covers every texel the
// rasterizer's footprint covers and MayBlock only drops provable misses, so each sample ends
// with the same decision as under the rasterizer (Hit::Clear is sticky, Unknown is traced).
constexpr vtkIdType SparseFactor = 2;

// Rays of a run of nodes: node j's is Rays[j - First].
struct RayRun
{
  const penumbra_light_views::ShadowRay* Rays;
  size_t First;
};

struct CasterGrid
{
  static constexpr int BandRows = 16;
  bool Perspective = false;

  // Nothing is kept per caster (the whole description took about 180 bytes a caster): the
  // band walk makes a binned caster's box (BoxOf) and description (Describe) again from its
  // triangle, the same values wherever they are made.
  // One binned caster, described for MayBlock: edge lines and depth plane (EdgeLines), unit
  // normal, the float rounding of its vertices (world), the texels per world unit at its
  // nearest, and MayBlock's margin for any of the pass's rays (-1: none). Flat: a projection
  // without area (no edge test).
  struct Description
  {
    double Edge[9];
    double Plane[3];
    double Normal[3];
    double Slop = 0.0;
    double Scale = 0.0;
    double TexelMargin = -1.0;
    bool Flat = true;
  };
  // What Describe needs of the pass.
  View PassView;
  int Size = 0;
  double RowScale = 0.0;
  double ErrPos = 0.0; // the largest positional slack of the pass's rays

  void Describe(
    const double tri[9], const penumbra_light_views::LightSetup& light, Description& d) const;
  static double MarginBound(const Description& d, const double* tri,
    const penumbra_light_views::LightSetup& light, double errPos);
  static bool TexelNear(const Description& d, double x, double y);
  bool MayBlock(const Description& d, const float* point, double depth,
    const penumbra_light_views::ShadowRay& ray) const;
  static constexpr int TileTexels = 16;
  std::vector<std::uint32_t> TileSums; // summed-area table of listed texels per tile
  int Tiles = 0;                       // tiles per side
  std::vector<std::uint32_t> Texels;   // the pass's texels with a list, ascending
  std::vector<double> TexelDepth;      // per entry of Texels: its samples' farthest depth
  std::vector<std::uint32_t> RowStart; // per grid row: its first entry in Texels (size + 1)
  std::vector<vtkIdType> BandStart;    // per band of grid rows: first entry (bands + 1)
  std::vector<std::uint32_t> Entries;  // per band: the casters (index in the pass's list) whose
                                       // box reaches it, in caster order
  std::vector<penumbra_light_views::ShadowRay> Rays; // per node, unless NodesByTexel
  bool NodesByTexel = false;                         // the lists' nodes in texel order (CPU lists)

  void MakeRays(const TestContext& ctx, const Lists& lists);
  RayRun RaysOfBand(const TestContext& ctx, const Lists& lists, int size, int rowLo, int rowHi,
    std::vector<penumbra_light_views::ShadowRay>& scratch) const;

  // Grid rows and columns of the texels whose square a box [v0, v1] overlaps
  // (x + 1 >= x0 and x <= x1).
  static int First(double v, int size)
  {
    return std::max(0, std::min(size - 1, static_cast<int>(std::ceil(v)) - 1));
  }
  static int Last(double v, int size)
  {
    return std::max(0, std::min(size - 1, static_cast<int>(std::floor(v))));
  }

  void CountTiles(int size, const Lists& lists);
  bool BoxMeetsList(const double box[4], int size) const;
  void Classify(const View& view, int size, const TestContext& ctx,
    const penumbra_casters::CasterIds& casters, std::vector<unsigned char>& kinds) const;
  void BoxOf(const double tri[9], int range[4], float& lower) const;
  vtkIdType Build(const View& view, int size, const TestContext& ctx,
    const penumbra_casters::CasterIds& casters, const Lists& lists,
    std::vector<vtkIdType>& nearTriangles);
};

vtkIdType TestListsByBands(int size, const TestContext& ctx,
  const penumbra_casters::CasterIds& casters, const Lists& lists, const CasterGrid& grid,
  const float* point, penumbra_casters::ExactTriangles& exact);
vtkIdType TestNearTriangles(const TestContext& ctx, const vtkIdType* listed, vtkIdType count,
  const std::vector<vtkIdType>& nearTriangles);
}

struct vtkPenumbraLinkedListShadows::Internals
{
  penumbra_casters::CasterBuffers Casters; // CPU lists only, never uploaded
  vtkMTimeType CastersTime = 0;            // the geometry's GetCastersTime() of this call
  vtkNew<vtkUnsignedCharArray> State;
  std::vector<double> Depth;       // per sample
  std::vector<vtkIdType> Texel;    // per sample, its texel in its view
  std::vector<float> Point;        // per sample, its point in its view (texel units)
  std::vector<vtkIdType> ToDecide; // the call's samples to decide, ascending
  std::vector<vtkIdType> Listed;   // the view's listable samples, ascending
  std::vector<vtkIdType> Pick;     // CPU passes: the pass's samples
  penumbra_llsm::Lists Grid;
  penumbra_llsm::ListCompute Compute;     // the GPU list path
  bool UseGpu = false;                    // this call's lists are built on the GPU
  std::string ReportedProblem;            // the last reason the GPU path could not run
  vtkNew<vtkIdTypeArray> Recorded;        // RecordLists: (view, texel, sample)
  std::vector<vtkIdType> Near;            // the apex region's triangles
  penumbra_llsm::SampleCells Cells;       // the pass's listed samples, coarse
  penumbra_llsm::CasterGrid Bands;        // sparse passes: the casters binned by box
  penumbra_llsm::CasterClusters Clusters; // the casters, grouped for culling
  std::vector<unsigned char> Keep;        // per caster (cluster order): not culled
  penumbra_casters::CasterIds Kept;       // the pass's casters after culling

  // The phases of ComputeVisibility, in the order it runs them (defined below it).
  void ChooseListPath(vtkPenumbraLinkedListShadows* self, vtkRenderer* renderer, vtkIdType n);
  bool BuildPass(vtkPenumbraLinkedListShadows* self, int view, vtkIdType capacity,
    unsigned char* state, vtkIdType& rows);
  void ListView(vtkPenumbraLinkedListShadows* self, const penumbra_llsm::View& view, int vi,
    const penumbra_llsm::TestContext& ctx, vtkIdType& rows);
  void ReportListPath(vtkPenumbraLinkedListShadows* self, const std::string& why);
  void ReleaseLists();
};

#endif
// VTK-HeaderTest-Exclude: vtkPenumbraLinkedListInternals.h
