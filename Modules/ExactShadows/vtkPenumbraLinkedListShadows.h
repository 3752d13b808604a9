/**
 * @class   vtkPenumbraLinkedListShadows
 * @brief   Exact hard shadows by irregular rasterization: linked-list shadow maps (LLSM,
 *          Ferko 2014) and the hybrid LLSM of the same thesis: lists built on the CPU or by a
 *          GL 4.3 compute shader, irregular rasterization on the CPU.
 *
 * LLSM builds the irregular z-buffer of Johnson, Lee, Burns, Mark, "The Irregular Z-Buffer:
 * Hardware Acceleration for Irregular Data Structures", ACM TOG 24(4), 2005, the way Ferko
 * (2014) builds it on the GPU: per light-view texel, a list of the view samples that project
 * into it; then every caster triangle is rasterized *conservatively* in light space, and each
 * texel it touches tests it against the samples of its list. A sample's shadow ray projects to
 * its own texel point (orthographic views: it runs along the view axis; perspective views: it
 * runs to the apex), so the triangles tested against a sample are all that can block it, and
 * the result equals ray-traced hard shadows without a ray tracer.
 *
 * Per light and call:
 * 1. The samples to decide: those facing the light (the reference's facing and cone rules),
 *    or with SetHybrid(true) only the ones a conservative shadow map cannot decide
 *    (vtkPenumbraConservativeShadows::Classify, Hertel, Hormann, Westermann 2009): the hybrid
 *    LLSM of Ferko's thesis sends only hard samples to the lists, with an exact classifier in
 *    place of its resolution criterion (which relies on a biased standard shadow map).
 * 2. Light views fitted to those samples: directional lights one orthographic view, spot
 *    lights up to 60 degrees one perspective view, others six cube faces.
 * 3. Lists: per texel a linked list of its samples (head pointers and a node pool of
 *    (sample, next) links), built by one of two paths (SetListBuilder) that give the same
 *    per-texel sample sets. The CPU path sorts the samples by texel (a counting sort, or a
 *    plain sort when they are few) and links each node to the next of its texel. The GPU
 *    path is Ferko 2014's construction, like the per-pixel linked lists of order-independent
 *    transparency (Thibieroz and Gruen 2010): a GL 4.3 compute shader takes a node per
 *    sample from the pool with an atomic counter and links it in front of its texel's list
 *    by an atomic exchange of the head pointer (vtkPenumbraLinkedListCompute.h); the nodes
 *    and the heads of the listed texels are read back. The samples' texels are projected on
 *    the CPU in double precision either way, so both paths list a sample in the texel the
 *    rasterizer tests it at. A node pool smaller than the samples (SetListCapacity) never
 *    drops one: the CPU lists at most that many per pass, the GPU detects the overflow
 *    (counter beyond the pool) and lists the samples that got no node in a further pass.
 * 4. Caster culling (SetCullCasters): casters whose light-space box covers no coarse cell
 *    holding a listed sample, or that lie behind the farthest listed sample of every such
 *    cell, are skipped; they could decide no sample.
 *    Irregular rasterization: the conservative separating-axis rasterizer in double precision
 *    that builds the conservative technique's maps (vtkPenumbraConservativeMapCPU.h, a texel
 *    grown by a quarter for the tracer's float rounding), in parallel over tiles with
 *    vtkSMPTools, visits only texels with open samples (a row walks its listed texels when
 *    they are fewer than the triangle's span). Per sample: its own triangle never
 *    blocks; a triangle whose conservative depth over the texel lies beyond the sample cannot;
 *    otherwise the reference's exact double-precision decision (penumbra_rules::SegmentTest)
 *    shadows it (clear hit), passes over the triangle (clear miss) or marks it unknown.
 *    Triangles that reach a perspective view's apex region (a light on or near a surface)
 *    would cover the whole view: they are tested against every sample of the view instead
 *    (beyond 256 of them, the view's open samples are traced).
 *    Sparse passes (fewer than 2 listed samples per caster, typically the hybrid's hard
 *    samples) skip the culling and the footprints, whose setup then costs more than the tests:
 *    each caster's light-space box is binned to bands of grid rows and meets the listed
 *    texels it overlaps (first per texel, with a margin bound for all the pass's rays, then
 *    per sample); casters the exact test would provably call a miss (depth
 *    plane beyond the sample, or the sample's point outside the projection by more than the
 *    test's slack) are skipped. Every triangle the rasterizer would test is tested, so the
 *    decisions are the same.
 * 5. Unknown samples (grazing, on an edge, in the tie band, outside every view) are traced by
 *    vtkPenumbraReference, so the answer equals the reference's bit for bit.
 *
 * Area lights are rejected (error, the pass renders that light unshadowed).
 *
 * Memory per view: 4 bytes per texel (head pointers) plus 1 (open flag) and about 24 bytes
 * per listed sample; 5 MiB at the default 1024^2 (the GPU path holds another head image and
 * pool in buffers).
 */

#ifndef vtkPenumbraLinkedListShadows_h
#define vtkPenumbraLinkedListShadows_h

#include "vtkPenumbraExactShadowsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr

class vtkIdTypeArray;
class vtkPenumbraConservativeShadows;
class vtkPenumbraReference;
class vtkPenumbraStatistics;

class VTKPENUMBRAEXACTSHADOWS_EXPORT vtkPenumbraLinkedListShadows
  : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraLinkedListShadows* New();
  vtkTypeMacro(vtkPenumbraLinkedListShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  /**
   * Frees the GPU list path's buffers and program.
   */
  void ReleaseGraphicsResources(vtkWindow* window) override;

  enum ListBuilders
  {
    LISTS_CPU = 0,
    LISTS_GPU = 1
  };

  ///@{
  /**
   * Who builds the per-texel lists (see the class description): LISTS_CPU (default; faster on
   * Mesa llvmpipe, see docs/benchmarks.md) or LISTS_GPU (a GL 4.3 compute shader, in the
   * renderer's context). The same lists and visibility either way. Where the GPU path cannot
   * run (no OpenGL 4.3, no OpenGL window) it says why in an error and the CPU builds them.
   */
  vtkSetClampMacro(ListBuilder, int, LISTS_CPU, LISTS_GPU);
  vtkGetMacro(ListBuilder, int);
  void SetListBuilderToCPU() { this->SetListBuilder(LISTS_CPU); }
  void SetListBuilderToGPU() { this->SetListBuilder(LISTS_GPU); }
  ///@}

  /**
   * The path that built the last call's lists (LISTS_GPU only when every pass ran on it).
   */
  vtkGetMacro(LastListBuilder, int);

  ///@{
  /**
   * For tests: with RecordLists on, every call keeps its lists as (view, texel, sample)
   * tuples (3 components), sorted, so the two paths' per-texel sample sets can be compared
   * whatever their node order and pass split. Default off.
   */
  vtkSetMacro(RecordLists, bool);
  vtkGetMacro(RecordLists, bool);
  vtkBooleanMacro(RecordLists, bool);
  vtkIdTypeArray* GetRecordedLists();
  ///@}

  ///@{
  /**
   * List-grid texels per side (per cube face for point lights). Default 1024, clamped to
   * [1, 4096]. Only speed depends on it: fewer texels give longer lists, more texels more
   * rasterization; 1 tests every caster against every sample.
   */
  vtkSetClampMacro(Resolution, int, 1, 4096);
  vtkGetMacro(Resolution, int);
  ///@}

  ///@{
  /**
   * Node-pool capacity: at most this many samples are listed per pass; the others wait for
   * the next pass (the rasterization is repeated), so none is dropped. Default 0: one node
   * per sample, a single pass.
   */
  vtkSetClampMacro(ListCapacity, vtkIdType, 0, VTK_ID_MAX);
  vtkGetMacro(ListCapacity, vtkIdType);
  ///@}

  ///@{
  /**
   * Hybrid LLSM: only the samples a conservative shadow map cannot decide enter the lists
   * (see the class description). Default false.
   */
  vtkSetMacro(Hybrid, bool);
  vtkGetMacro(Hybrid, bool);

  /**
   * The registry's name: "llsm-hybrid" or "llsm".
   */
  const char* GetTechniqueName() override { return this->Hybrid ? "llsm-hybrid" : "llsm"; }
  vtkBooleanMacro(Hybrid, bool);
  ///@}

  ///@{
  /**
   * Caster culling per view and pass (default on): before the rasterization, each caster's
   * light-space box and lowest depth (first per cluster of 32 casters, then per triangle) are
   * checked against a coarse grid of the listed samples (cells of Resolution / 256 texels,
   * each with the largest depth of its samples, as a max pyramid). A caster that covers no
   * cell holding a listed sample, or lies behind the farthest listed sample of every such
   * cell it covers, could decide no sample, so it is skipped; the answer does not change.
   * Sparse passes (see the class description) need no such culling and skip it. Off: every
   * caster is rasterized (for comparisons).
   */
  vtkSetMacro(CullCasters, bool);
  vtkGetMacro(CullCasters, bool);
  vtkBooleanMacro(CullCasters, bool);
  ///@}

  /**
   * The hybrid's classifier (its Resolution and Layers are the classification's settings).
   * Its Layers default to 3 here, not 2: the third layer decides most of the samples two
   * leave uncertain (the city: 0.6 % listed instead of 5.8 %), and a listed sample costs
   * the hybrid more than the layer does (see docs/benchmarks.md).
   */
  vtkPenumbraConservativeShadows* GetClassifier() { return this->Classifier; }

  /**
   * The ray tracer for the unknown samples (exposed for its statistics and epsilons).
   */
  vtkPenumbraReference* GetReference() { return this->Reference; }

  ///@{
  /**
   * Statistics of the last ComputeVisibility call. Valid samples (not background); samples
   * that entered the lists; the longest list and the mean length of the non-empty ones;
   * exact triangle/sample tests; samples traced by the reference; list passes (more than
   * one per view when the capacity is below the samples); light views.
   */
  vtkGetMacro(NumberOfValidSamples, vtkIdType);
  vtkGetMacro(NumberOfListedSamples, vtkIdType);
  vtkGetMacro(MaxListLength, vtkIdType);
  vtkGetMacro(MeanListLength, double);
  vtkGetMacro(NumberOfTests, vtkIdType);
  vtkGetMacro(NumberOfTracedSamples, vtkIdType);
  vtkGetMacro(NumberOfPasses, int);
  vtkGetMacro(NumberOfViews, int);
  ///@}

  /**
   * GPU lists: passes of the last call whose node pool overflowed (the counter went beyond
   * SetListCapacity); their unlinked samples were listed in further passes.
   */
  vtkGetMacro(NumberOfOverflows, int);

  /**
   * Passes of the last call tested in the sparse form (step 4 of the class description).
   */
  vtkGetMacro(NumberOfSparsePasses, int);

  ///@{
  /**
   * Caster culling of the last call, summed over views and passes: casters skipped before the
   * rasterization, and casters handed to it (every caster per view and pass without culling).
   */
  vtkGetMacro(NumberOfCulledCasters, vtkIdType);
  vtkGetMacro(NumberOfRasterizedCasters, vtkIdType);
  ///@}

  /**
   * Listed / valid samples of the last call; 0 without valid samples.
   */
  double GetListedFraction();

  /**
   * The share of the valid samples handed on to an exact fallback: for the hybrid, the share
   * the classifier sent to the lists (GetListedFraction()); otherwise the share traced.
   */
  double GetUncertainFraction() override;

  ///@{
  /**
   * Phase times of the last call in milliseconds: classification (facing, or the hybrid's
   * conservative map), list construction, irregular rasterization with its tests, tracing.
   */
  vtkGetMacro(ClassifyTimeMs, double);
  vtkGetMacro(ListTimeMs, double);
  vtkGetMacro(RasterTimeMs, double);
  vtkGetMacro(TraceTimeMs, double);
  ///@}

protected:
  vtkPenumbraLinkedListShadows();
  ~vtkPenumbraLinkedListShadows() override;

  int Resolution = 1024;
  vtkIdType ListCapacity = 0;
  bool Hybrid = false;
  bool CullCasters = true;
  int ListBuilder = LISTS_CPU;
  int LastListBuilder = LISTS_CPU;
  bool RecordLists = false;
  int NumberOfOverflows = 0;
  int NumberOfSparsePasses = 0;
  vtkIdType NumberOfCulledCasters = 0;
  vtkIdType NumberOfRasterizedCasters = 0;
  vtkIdType NumberOfValidSamples = 0;
  vtkIdType NumberOfListedSamples = 0;
  vtkIdType MaxListLength = 0;
  double MeanListLength = 0.0;
  vtkIdType NumberOfTests = 0;
  vtkIdType NumberOfTracedSamples = 0;
  int NumberOfPasses = 0;
  int NumberOfViews = 0;
  double ClassifyTimeMs = 0.0;
  double ListTimeMs = 0.0;
  double RasterTimeMs = 0.0;
  double TraceTimeMs = 0.0;
  vtkPenumbraConservativeShadows* Classifier;
  vtkPenumbraReference* Reference;

private:
  vtkPenumbraLinkedListShadows(const vtkPenumbraLinkedListShadows&) = delete;
  void operator=(const vtkPenumbraLinkedListShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
