/**
 * @file   vtkPenumbraGearsShadowsInternals.h
 * @brief  The state of a vtkPenumbraGearsShadows shared by its files: the technique and a
 *         call's set-up, classification and statistics (vtkPenumbraGearsShadows.cxx), the grid
 *         of potential blockers (vtkPenumbraGearsGrid.cxx), the CPU masks
 *         (vtkPenumbraGearsMasks.cxx), the compute path (vtkPenumbraGearsComputePath.cxx) and
 *         the ray-traced cells and samples (vtkPenumbraGearsTraced.cxx). Private to the module.
 */

#ifndef vtkPenumbraGearsShadowsInternals_h
#define vtkPenumbraGearsShadowsInternals_h

#include "vtkPenumbraGearsShadows.h"

#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraGearsCompute.h"
#include "vtkPenumbraGearsTree.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraViewSamples.h"
#include "vtkPenumbraVisibilityRules.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkTypeUInt32Array.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <numeric>
#include <set>
#include <string>
#include <vector>

namespace penumbra_gears_shadows
{

using penumbra::Clock;
using penumbra::ElapsedMs;

constexpr int MaxK = 64; // vtkPenumbraAreaLight's SamplesPerAxis limit: one 64-bit word per row

// Position tolerance of the double-precision decisions against Embree's float32 ray, relative
// to the reference's scene scale max(|p|, bounds diagonal): the value the conservative
// technique validated for the same reference (its exact one-triangle ray test).
constexpr double RelativePositionTolerance = 1e-6;

// A caster in the geometry's rebased frame with the float32 rounding Embree's copy has, and
// what the per-ray test needs precomputed (the tracer's rules).
using Caster = penumbra_rules::ExactTriangle;

// A caster's bounding sphere, kept apart from the casters so the cheap rejects touch 32 bytes
// per triangle instead of a whole Caster.
struct Sphere
{
  double Centre[3];
  double Radius;
};

using penumbra_rules::Hit;
using penumbra_rules::SegmentTest;

inline std::uint64_t Span(int lo, int hi)
{
  if (hi < lo)
  {
    return 0;
  }
  const int width = hi - lo + 1;
  const std::uint64_t ones = width >= 64 ? ~std::uint64_t(0) : ((std::uint64_t(1) << width) - 1);
  return ones << lo;
}

// One affine function of the light-sample position L = centre + su U + sv V, written for
// sample indices: value(i, j) = Base + i * Di + j * Dj.
struct Affine
{
  double Base, Di, Dj;
  double At(int i, int j) const { return this->Base + i * this->Di + j * this->Dj; }
};

// What the mask loop needs about the light (rebased frame).
struct LightSamples
{
  int K = 1;                  // grid cells per row
  int Rows = 1;               // k for a rectangle or a disc, 1 for a line
  int Cells = 1;              // K * Rows grid cells
  int Count = 1;              // light samples: the cells that emit (all but a disc's corners)
  std::vector<double> Points; // 3 per grid cell, index = j K + i
  // Per row: the cells that hold light samples (bit i), and the sample index of the first.
  // The masks run over the grid; a cell that holds no sample is never lit.
  std::uint64_t Emitting[MaxK] = {};
  int RowFirst[MaxK] = {};
  double Centre[3], U[3], V[3], N[3];
  double Su0 = 0, DSu = 0, Sv0 = 0, DSv = 0; // su_i = Su0 + i DSu, sv_j = Sv0 + j DSv
  double HalfU = 0, HalfV = 0;               // largest |su|, |sv| of a sample
  double Diagonal = 0;                       // of the emitter rectangle

  Affine Along(const double g[3], double atCentre) const
  {
    const double gu = vtkMath::Dot(g, this->U);
    const double gv = vtkMath::Dot(g, this->V);
    return { atCentre + this->Su0 * gu + this->Sv0 * gv, this->DSu * gu, this->DSv * gv };
  }
  // The light-sample index (vtkPenumbraAreaLight's numbering) of emitting cell (i, j).
  int SampleIndex(int i, int j) const
  {
    const std::uint64_t below = this->Emitting[j] & ((std::uint64_t(1) << i) - 1);
    return this->RowFirst[j] + __builtin_popcountll(below);
  }
  const double* Corner(int c) const
  {
    const int i = (c & 1) ? this->K - 1 : 0;
    const int j = (c & 2) ? this->Rows - 1 : 0;
    return &this->Points[3 * static_cast<size_t>(j * this->K + i)];
  }
};

// Per-sample constants of the reference's rays.
struct SampleRays
{
  double Z; // distance from the light plane, on this sample's side
  double P[3];
  double Normal[3];
  vtkIdType Own;
  double TNear, TieLimit, ErrPos, Epsilon;
  float TNearF;
};

// The CPU masks of one call (vtkPenumbraGearsMasks.cxx).
struct MaskBuilder;
// The state one ComputeVisibility call shares between its phases: the view samples in the
// geometry's rebased frame, the light, the outputs, the undecided pairs and the statistics.
struct CallState
{
  vtkIdType N = 0;
  const float* Pos = nullptr;
  const float* Nrm = nullptr;
  const int* Props = nullptr;
  const vtkIdType* Tris = nullptr;
  double Shift[3] = { 0, 0, 0 };                         // samples' origin minus the geometry's
  double Epsilon = 0.0, TieFactor = 0.0, Diagonal = 1.0; // the reference's
  vtkSmartPointer<vtkPenumbraAreaLight> Used;            // the light, resampled if asked
  LightSamples Light;
  bool Off = false; // switched off or zero intensity

  float* Vis = nullptr;
  unsigned char* Uncertain = nullptr;
  std::uint32_t* Masks = nullptr; // only with KeepMasks
  int Words = 0;                  // mask words per sample

  bool UseGpu = false;     // step 4 on the compute path
  double TraceLimit = 0.0; // list length above which a cell is dense; 0: never
  bool DenseTree = false;  // dense cells walk the casters' tree (else: ray traced whole)

  // Undecided (view sample, light sample) pairs, appended by the mask loop in sample order
  // within each thread's chunk.
  std::vector<vtkIdType> TraceSamples;
  std::vector<int> TraceLights;
  std::mutex TraceMutex;

  // Statistics, summed over both sides of the light plane.
  int GridUsed = 0;
  vtkIdType Flagged = 0, TracedCellSamples = 0, TreeSamples = 0, Occupied = 0, Cells = 0,
            MaxPerCell = 0, ListTotal = 0, GlobalTotal = 0;
  std::atomic<vtkIdType> Assignments{ 0 }, Necessary{ 0 }, SegmentTests{ 0 };
  double GridMs = 0.0, MaskMs = 0.0, TraceMs = 0.0;
  vtkIdType UncertainSamples = 0, TracedRays = 0, SamplesWithTracedRays = 0;

  // The reference's per-ray constants of view sample s; false if the sample is invalid.
  bool LoadSample(vtkIdType s, SampleRays& r) const
  {
    for (int c = 0; c < 3; ++c)
    {
      r.P[c] = static_cast<double>(this->Pos[3 * s + c]) + this->Shift[c];
      r.Normal[c] = this->Nrm[3 * s + c];
    }
    if (this->Props[s] < 0 || !std::isfinite(r.P[0]) || !std::isfinite(r.P[1]) ||
      !std::isfinite(r.P[2]) || !std::isfinite(r.Normal[0]) || !std::isfinite(r.Normal[1]) ||
      !std::isfinite(r.Normal[2]))
    {
      return false;
    }
    const penumbra_rules::RayBand band =
      penumbra_rules::SampleBand(r.P, this->Diagonal, this->Epsilon, this->TieFactor);
    r.Own = this->Tris[s];
    r.Epsilon = this->Epsilon;
    r.TNear = band.TNear;
    r.TNearF = static_cast<float>(r.TNear);
    r.TieLimit = static_cast<double>(static_cast<float>(band.TieLimit));
    r.ErrPos = RelativePositionTolerance * band.Scale;
    return true;
  }

  // ORs the light samples set in rows (one word per row) into sample s's kept mask.
  void WriteMask(vtkIdType s, const std::uint64_t* rows) const
  {
    if (!this->Masks)
    {
      return;
    }
    const LightSamples& ls = this->Light;
    std::uint32_t* out = this->Masks + static_cast<size_t>(s) * this->Words;
    for (int j = 0; j < ls.Rows; ++j)
    {
      for (int i = 0; i < ls.K; ++i)
      {
        if ((rows[j] & ls.Emitting[j]) >> i & 1u)
        {
          const int index = ls.SampleIndex(i, j);
          out[index / 32] |= 1u << (index % 32);
        }
      }
    }
  }
};

// Per caster on one side: culled, global or the grid box it touches.
struct Footprint
{
  double Box[4];
  int State; // 0 culled, 1 global, 2 cells
};

// One side of the light plane: its samples in the light's frame with z toward them
// (Wang et al. 2014, §4, A.1; the back side mirrors), the grid camera C, the casters'
// footprints and the grid being built.
struct SideState
{
  int Flip = 1;
  double Ax[3][3];                // the frame's axes
  const double* Centre = nullptr; // the light's centre, the frame's origin
  vtkIdType M = 0;                // samples on this side (Scratch.Ids, Scratch.Frame)
  double ZFar = 0.0;              // farthest sample from the light plane
  double Lo3[3], Hi3[3];          // bounds of the samples and the light, in the frame
  double Tolerance = 0.0;         // how far off the float32 ray may hit a triangle
  double Distance = 0.0, Cam[3];  // the camera C, behind the light
  double Pb[4];                   // bounds of the projected samples
  double Extent = 0.0;            // their larger side
  std::vector<double> ZNear;      // per caster: nearest vertex to the light
  std::vector<Footprint> Foot;

  // The grid: resolution G, origin (X0, Y0), cell size Cw x Ch, and the per-resolution
  // working arrays of its construction.
  int G = 1;
  double X0 = 0, Y0 = 0, Cw = 1, Ch = 1;
  std::vector<std::uint32_t> Count;  // samples per cell
  std::vector<std::int64_t> Sat;     // summed-area table of occupied cells
  std::vector<int> Range;            // per caster: ix0, ix1, iy0, iy1
  std::vector<std::int64_t> Touched; // per caster: busy cells touched, -1 global
  std::int64_t Total = 0;            // list entries the cells would hold

  void ToFrame(const double w[3], double f[3]) const
  {
    const double d[3] = { w[0] - this->Centre[0], w[1] - this->Centre[1], w[2] - this->Centre[2] };
    for (int a = 0; a < 3; ++a)
    {
      f[a] = vtkMath::Dot(this->Ax[a], d);
    }
  }
  // Projection from C onto the far plane z = ZFar.
  void Project(const double f[3], double out[2]) const
  {
    const double g = (this->ZFar - this->Cam[2]) / (f[2] - this->Cam[2]);
    out[0] = this->Cam[0] + g * (f[0] - this->Cam[0]);
    out[1] = this->Cam[1] + g * (f[1] - this->Cam[1]);
  }
};
}

// The files of the technique use these names as the one file they came from did.
using namespace penumbra_gears_shadows;

struct vtkPenumbraGearsShadows::Internals
{
  // Casters, rebuilt when the geometry changes (same rule as the reference's scene).
  std::vector<Caster> Casters;
  std::vector<Sphere> Bounds;
  penumbra::CastersStamp CastersBuilt;
  double Diagonal = 1.0;

  // Per-frame working arrays sized by the samples (tens of MB at 1280 x 720), kept between
  // frames: allocating them afresh each frame cost more in page faults than the grid itself.
  struct ScratchArrays
  {
    std::vector<signed char> Side;
    std::vector<vtkIdType> Ids;
    std::vector<double> Frame, Proj;
    std::vector<std::int32_t> SampleCell, Occupied;
    std::vector<unsigned char> Traced; // per cell: a dense cell (tree walk or ray tracer)
    // Per caster, kept for the next side (SideState's arrays of the same names).
    std::vector<double> ZNear;
    std::vector<Footprint> Foot;
    std::vector<int> Range;
    std::vector<std::int64_t> Touched;
    std::vector<double> TriangleBoxes; // per caster: its box in the side's light frame, grown
    std::vector<double> TreeBoxes;     // by the float32 tolerance; the same per tree node
    std::vector<std::uint32_t> CellStart, CellList, GlobalList, SampleOrder, SampleStart, OnCPU,
      Work, Results, Rows; // Work, Results, Rows: the compute path's
  } Scratch;

  vtkNew<vtkTypeUInt32Array> Masks;
  vtkNew<vtkUnsignedCharArray> Uncertain;

  // The casters flattened for the compute path (penumbra_gears::CasterStride doubles each),
  // and a version that changes whenever they are rebuilt (the GPU copy follows it).
  std::vector<double> CasterData;
  std::uint64_t CasterVersion = 0;
  penumbra_gears::MaskCompute Compute;
  penumbra_gears::Tree Tree; // over the casters, for the dense cells
  std::string PathMessage;
  std::set<std::string> Reported; // compute-path problems already warned about

  // With `withTree` the casters' tree is built too (and the casters stored in its order):
  // only the DENSE_TREE walk needs it, and on a 1 M-triangle mesh it costs a frame's grid.
  void UpdateCasters(vtkPenumbraSceneGeometry* geometry, bool withTree)
  {
    if (!this->CastersBuilt.Changed(geometry) &&
      (!withTree || !this->Tree.Nodes.empty() || this->Casters.empty()))
    {
      return;
    }
    const penumbra::SceneTriangles& triangles = geometry->GetTriangles();
    const vtkIdType n = triangles.Size();
    this->Casters.clear();
    this->Bounds.clear();
    for (vtkIdType t = 0; t < n; ++t)
    {
      Caster c;
      if (penumbra_rules::MakeOccluder(triangles, t, c))
      {
        this->Casters.push_back(c);
        Sphere b;
        b.Radius = 0.0;
        for (int k = 0; k < 3; ++k)
        {
          b.Centre[k] = (c.V[0][k] + c.V[1][k] + c.V[2][k]) / 3.0;
        }
        for (int i = 0; i < 3; ++i)
        {
          const double d[3] = { c.V[i][0] - b.Centre[0], c.V[i][1] - b.Centre[1],
            c.V[i][2] - b.Centre[2] };
          b.Radius = std::max(b.Radius, vtkMath::Norm(d));
        }
        this->Bounds.push_back(b);
      }
    }
    this->Tree = penumbra_gears::Tree();
    if (withTree)
    {
      this->SortCastersByTree();
    }
    this->CasterData.clear();
    this->CasterData.reserve(this->Casters.size() * penumbra_gears::CasterStride);
    for (size_t t = 0; t < this->Casters.size(); ++t)
    {
      const Caster& c = this->Casters[t];
      const Sphere& b = this->Bounds[t];
      const double* parts[] = { &c.V[0][0], c.N, &c.M[0][0], c.MD };
      const size_t sizes[] = { 9, 3, 9, 3 };
      for (int p = 0; p < 4; ++p)
      {
        this->CasterData.insert(this->CasterData.end(), parts[p], parts[p] + sizes[p]);
      }
      this->CasterData.push_back(static_cast<double>(c.Id));
      this->CasterData.insert(this->CasterData.end(), b.Centre, b.Centre + 3);
      this->CasterData.push_back(b.Radius);
    }
    ++this->CasterVersion;
    this->Diagonal = penumbra_rules::SceneDiagonal(geometry);
    this->CastersBuilt.Remember(geometry);
  }
  // The casters' tree (vtkPenumbraGearsTree.h), and the casters stored in its leaf order, so
  // that a leaf's triangles are Casters[First, First + Count) and a walk reads memory in
  // order (the caster index is internal: Caster::Id names the owner of the triangle).
  void SortCastersByTree()
  {
    const size_t n = this->Casters.size();
    std::vector<double> vertices(9 * n);
    for (size_t t = 0; t < n; ++t)
    {
      std::copy(&this->Casters[t].V[0][0], &this->Casters[t].V[0][0] + 9, &vertices[9 * t]);
    }
    this->Tree.Build(vertices.data(), 9, n);
    std::vector<Caster> casters(n);
    std::vector<Sphere> bounds(n);
    for (size_t t = 0; t < n; ++t)
    {
      casters[t] = this->Casters[this->Tree.Order[t]];
      bounds[t] = this->Bounds[this->Tree.Order[t]];
      this->Tree.Order[t] = static_cast<std::uint32_t>(t);
    }
    this->Casters.swap(casters);
    this->Bounds.swap(bounds);
  }

  // The phases of ComputeVisibility, in the order it runs them (defined below it).
  std::string ReadSamples(vtkPenumbraViewSamples* samples, CallState& call);
  bool SetUpLight(vtkPenumbraGearsShadows* self, vtkPenumbraAreaLight* area,
    vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples, CallState& call);
  void SetUpOutputs(vtkPenumbraGearsShadows* self, vtkFloatArray* visibility, CallState& call);
  void ChoosePath(vtkPenumbraGearsShadows* self, vtkRenderer* renderer, CallState& call);
  void ReportPathProblem(vtkPenumbraGearsShadows* self, const std::string& why);
  void ClassifySamples(vtkPenumbraGearsShadows* self, CallState& call);
  int TraceUndecided(vtkPenumbraGearsShadows* self, vtkPenumbraViewSamples* samples,
    vtkFloatArray* visibility, CallState& call);
  void StoreStatistics(vtkPenumbraGearsShadows* self, const CallState& call);
  // Per side of the light plane (ProcessSide runs them in this order).
  void ProcessSide(vtkPenumbraGearsShadows* self, CallState& call, int flip);
  bool GatherSide(const CallState& call, SideState& S, int flip);
  void PlaceCamera(vtkPenumbraGearsShadows* self, const CallState& call, SideState& S);
  void CasterFootprints(const CallState& call, SideState& S);
  void BuildGrid(vtkPenumbraGearsShadows* self, const CallState& call, SideState& S);
  void BinSamples(SideState& S);
  void CasterRanges(SideState& S);
  void MarkTracedCells(const CallState& call, SideState& S);
  void FillCellLists(SideState& S);
  void RouteTracedCells(CallState& call);
  bool MasksOnComputePath(vtkPenumbraGearsShadows* self, CallState& call, const SideState& S);
  void MasksOnCPU(CallState& call, const SideState& S, bool allOnCPU);
  void MaskOneSample(CallState& call, MaskBuilder& builder, std::vector<int>& undecided,
    std::uint32_t o, std::int32_t cell);
};

#endif
