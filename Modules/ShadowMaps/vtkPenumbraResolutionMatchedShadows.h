/**
 * @class   vtkPenumbraResolutionMatchedShadows
 * @brief   Resolution-matched shadow maps: Lefohn, Sengupta, Owens, "Resolution-Matched
 *          Shadow Maps", ACM TOG 26(4), 2007. Each view sample gets the shadow-map
 *          resolution it needs, up to MaxResolution^2 effective, from 32 x 32-texel pages
 *          that only the samples' requests allocate.
 *
 * Per directional or spot light and frame, on the GPU-resident frame (vtkPenumbraFrame):
 * - Virtual map: one light view fitted to the bounds of the whole scene (casters and
 *   receivers), not to the current view (the paper's fixed light frustum), so that pages
 *   stay valid while the camera moves. Level k has 2^k texels per side, from the base level
 *   (min(8, log2(AtlasSize) - 1, log2(MaxResolution)), always resident as a whole, the
 *   fallback of every sample) to log2(MaxResolution).
 * - Requests (§3.3.2, Eq. 1): a full-screen pass over the G-buffer computes per pending
 *   sample (facing the light, inside the cone) the level whose texel matches the sample's
 *   footprint in the map, from dX and dY, the map coordinates' change to the neighbouring
 *   pixels on the same prop (one-sided, the smaller side): by default the paper's square
 *   root of its area, or its smallest width (SetFootprint()), rounded up, LODBias levels
 *   finer and no coarser than GetMinimumRequestLevel(); by default for one sample per
 *   2 x 2 block (SetAnalysisStep()), whose samples on another surface add their own level
 *   (the block takes the finest); it writes the key of the page each sample needs and the
 *   level. The keys are read back (4 bytes
 * per pixel; on llvmpipe GPU memory is host memory, so the paper's GPU scan/sort/compaction buys
 * nothing here) and de-duplicated with one byte per page of the pyramid, in key order (coarse
 * levels first, which makes allocation deterministic).
 * - Allocation (§3.3.3): a free list of atlas slots; when it runs out, pages no sample
 *   requested this frame are evicted, and when that is not enough the finest requests are
 *   not made resident: those samples fall back to the finest resident coarser page (never
 *   to nothing: the base level is resident). The page table is a mipmapped R32I texture
 *   (level k at mip log2(MaxResolution) - k) whose every entry names the page that serves
 *   it: its own when resident, else its parent's (the paper's "highest resolution page that
 *   is less than or equal to that page table's resolution", propagated on the CPU and
 *   uploaded only when it changed).
 * - Rendering (§3.3.3): the new pages are binned into superpages (8 x 8 pages of one
 *   level, 256^2 texels, not the paper's 1024^2: on llvmpipe a pass is cheap and the
 *   unrequested texels of a sparse large rectangle are not); each superpage is one geometry pass of
 * the casters with a projection cropped to the bounding rectangle of its new pages (depth
 * untouched, so depths agree across levels), into one of the 16 cells of a scratch; once a
 * batch of 16 is drawn, each page is copied into its atlas slot (glCopyImageSubData).
 * - Shadow-edge refinement (SetRefineLevels()): with those pages resident, the samples whose
 *   2 x 2 texels disagree request the page RefineLevels levels finer, made resident the same
 *   way (a second round of superpages); elsewhere the requested level is already exact.
 * - Lookup (§3.3.1): the level the sample requested (or refined to), the page table entry,
 *   one nearest
 *   atlas texel (or 2 x 2 bilinear PCF at that level, SetFilter()) compared with the
 *   sample's receiver plane at the texel's centre and a small slope-scaled bias of that
 *   level's texel (the paper blends 2 x 2 PCF at two adjacent
 *   levels; not implemented).
 * - Cached mode (§3.3.4, default on): the pages stay resident while the light, the casters
 *   and the settings are unchanged (the virtual map does not follow the camera), so a still
 *   or camera-only frame renders only newly requested pages; any change flushes them all.
 *   Each light has its own virtual map, page table and requests; the lights share the atlas
 *   (a light whose base level does not fit drops the other lights' pages).
 *
 * Point lights (positional, cone above 60 degrees) and area lights: CanShadow() is false
 * (the pass shadows them with its fallback), ComputeFrame() reports an error.
 * Memory: the atlas keeps AtlasSize^2 x 4 bytes (64 MiB at 4096^2, shared by the lights);
 * per light the page table 4/3 x (MaxResolution / 32)^2 x 4 bytes (5.3 MiB at 32768^2), the
 * request targets 20 bytes per analysed pixel and layer (keys RGBA32F, levels R32F), the
 * refine targets 8 bytes per pixel and layer, and on the CPU the page table twice more
 * (slots and entries) and the read-back requests (4 or 16 bytes per analysed pixel, 4 per
 * pixel); the superpage scratch 1024^2 x 4 bytes (4 MiB).
 */

#ifndef vtkPenumbraResolutionMatchedShadows_h
#define vtkPenumbraResolutionMatchedShadows_h

#include "vtkPenumbraShadowMapsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr

class vtkIntArray;
class vtkPenumbraStatistics;

class VTKPENUMBRASHADOWMAPS_EXPORT vtkPenumbraResolutionMatchedShadows
  : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraResolutionMatchedShadows* New();
  vtkTypeMacro(vtkPenumbraResolutionMatchedShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  /**
   * Not supported: the technique answers on the GPU-resident frame only (ComputeFrame());
   * reports an error and returns 0.
   */
  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  int ComputeFrame(vtkPenumbraFrame* frame) override;
  bool ReadsSamples() override { return false; }
  void ReleaseGraphicsResources(vtkWindow* window) override;

  /**
   * Directional lights and spot lights with a cone of at most 60 degrees (VTK's half
   * angle).
   */
  bool CanShadow(vtkLight* light) override;

  const char* GetTechniqueName() override { return "rmsm"; }

  ///@{
  /**
   * The largest effective resolution, texels per side of the finest level: a power of two
   * in [2048, 32768] (other values are rounded down to one). Default 32768 (the paper's).
   */
  void SetMaxResolution(int resolution);
  vtkGetMacro(MaxResolution, int);
  ///@}

  ///@{
  /**
   * Side of the physical page atlas in texels: a power of two in [512, 8192] (rounded down),
   * (AtlasSize / 32)^2 pages. Default 4096: 16,384 pages, 64 MiB.
   */
  void SetAtlasSize(int size);
  vtkGetMacro(AtlasSize, int);
  ///@}

  enum FilterModes
  {
    FILTER_NONE = 0,    ///< the nearest texel of the requested level, 0 or 1
    FILTER_BILINEAR = 1 ///< 2 x 2 PCF at the requested level, bilinear weights
  };

  ///@{
  /**
   * FILTER_NONE (default) or FILTER_BILINEAR: the four texels around the sample's position
   * at its level, each resolved through the page table, compared and weighted bilinearly (a
   * one-texel ramp at shadow edges; the slope bias then reaches one texel, twice SlopeBias).
   * The paper blends two such lookups at adjacent levels; this one uses one level.
   */
  vtkSetClampMacro(Filter, int, FILTER_NONE, FILTER_BILINEAR);
  vtkGetMacro(Filter, int);
  ///@}

  enum FootprintRules
  {
    FOOTPRINT_AREA = 0, ///< Eq. 1: texel side sqrt(|dX x dY|), the footprint's area
    FOOTPRINT_WIDTH = 1 ///< texel side |dX x dY| / max(|dX|, |dY|), its smallest width
  };

  ///@{
  /**
   * How a sample's footprint in the map sets its level. FOOTPRINT_AREA is the paper's Eq. 1
   * (§3.3.2), the texel as large as the square root of the footprint's area: along the short
   * axis of an anisotropic footprint (receivers seen at a slant) the texel is then coarser
   * than the pixel (the default: the shadow edges are refined, SetRefineLevels(), and the
   * receiver plane keeps coarse texels from leaking light onto grazed receivers).
   * FOOTPRINT_WIDTH takes the footprint's smallest width, the same for a square footprint
   * and finer for a slanted one (2.5 times the pages under a grazing light). Measured in
   * docs/benchmarks.md.
   */
  vtkSetClampMacro(Footprint, int, FOOTPRINT_AREA, FOOTPRINT_WIDTH);
  vtkGetMacro(Footprint, int);
  ///@}

  ///@{
  /**
   * Levels finer than the one whose texel matches a sample's footprint (Eq. 1 rounded up):
   * 0 matches the paper; each level more halves the texel and quadruples the pages. Default
   * 1 (with 0, shadow edges the refinement does not reach, at creases and contacts, are
   * twice as often wrong: the city at 1280 x 720, 9.3e-5 against 3.7e-5). Clamped to [0, 2].
   */
  vtkSetClampMacro(LODBias, int, 0, 2);
  vtkGetMacro(LODBias, int);
  ///@}

  ///@{
  /**
   * Levels finer at shadow edges: once the requested pages are resident, each sample whose
   * 2 x 2 texels at its level disagree (a shadow boundary passes within a texel of it, the
   * only place where a point-sampled map can answer wrongly) requests the page RefineLevels
   * levels finer and is looked up there (the edge test of the adaptive shadow maps Lefohn et
   * al. 2007 improve on, applied once). 0 turns it off. Default 3, clamped to [0, 4].
   */
  vtkSetClampMacro(RefineLevels, int, 0, 4);
  vtkGetMacro(RefineLevels, int);
  ///@}

  ///@{
  /**
   * The request pass computes the level (Eq. 1) of one sample per AnalysisStep x
   * AnalysisStep block of pixels (Lefohn et al. 2007, §3.3.5, reduced analysis resolution);
   * the block's other samples request their own pages at that level and are looked up at
   * it; a block sample on another prop or surface adds its own level, and the block takes
   * the finest. Default 2, clamped to [1, 2].
   */
  vtkSetClampMacro(AnalysisStep, int, 1, 2);
  vtkGetMacro(AnalysisStep, int);
  ///@}

  ///@{
  /**
   * Cached mode: keep the pages while the light, the casters and the settings are
   * unchanged. Default on.
   */
  vtkSetMacro(Cached, bool);
  vtkGetMacro(Cached, bool);
  vtkBooleanMacro(Cached, bool);
  ///@}

  ///@{
  /**
   * Constant depth bias as a fraction of the virtual map's depth range. Default 1e-4,
   * clamped to [0, 0.1].
   */
  vtkSetClampMacro(Bias, double, 0.0, 0.1);
  vtkGetMacro(Bias, double);
  ///@}

  ///@{
  /**
   * Slope-scaled bias in texel footprints of the level a sample is compared at, on top of
   * the receiver plane: each texel is compared with the depth of the sample's tangent plane
   * at the texel's centre (receiver plane depth bias), so this only covers curvature and
   * rounding. Default 0.25, clamped to [0, 16].
   */
  vtkSetClampMacro(SlopeBias, double, 0.0, 16.0);
  vtkGetMacro(SlopeBias, double);
  ///@}

  /** The coarsest level in the page table, always resident: log2 of its side in texels. */
  int GetBaseLevel();

  /**
   * The coarsest level a sample requests, log2 of texels per side: min(10, log2
   * MaxResolution). Samples whose footprint needs less still get 1024^2 texels, so that
   * occluders thinner than a coarser texel stay in the map (only requested pages of it are
   * rendered).
   */
  int GetMinimumRequestLevel();

  /** Atlas slots (pages of 32 x 32 texels). */
  int GetAtlasCapacity() { return (this->AtlasSize / PageSize) * (this->AtlasSize / PageSize); }

  static constexpr int PageSize = 32;

  ///@{
  /**
   * Diagnostics of the last light computed: distinct pages its samples requested, the
   * coarsest and finest requested level (log2 of texels per side; 0 when nothing was
   * requested), pages rendered and superpage passes this frame, pages resident in the atlas
   * afterwards, and the share of requesting samples served by a coarser page than they
   * asked for (atlas full).
   */
  vtkGetMacro(NumberOfRequestedPages, int);
  vtkGetVector2Macro(RequestedLevels, int);
  vtkGetMacro(NumberOfRenderedPages, int);
  vtkGetMacro(NumberOfRefinedPages, int);
  vtkGetMacro(NumberOfSuperpages, int);
  vtkGetMacro(NumberOfResidentPages, int);
  vtkGetMacro(CoarserShare, double);
  ///@}

  /**
   * Diagnostics: the level (log2 of texels per side) each pixel of the frame's first layer
   * requested for `light` in its last request pass and was looked up at, 0 where it
   * requested nothing (not facing the light, outside the cone, background), row by row from
   * the bottom (with AnalysisStep 2, per pixel its block's level). Returns false (and leaves
   * `levels` empty) when the light has no requests.
   */
  bool GetSampleLevels(vtkLight* light, vtkIntArray* levels);

  /** Pages rendered since construction. */
  vtkGetMacro(TotalRenderedPages, long long);

  ///@{
  /**
   * Phase times of the last light in milliseconds: requests (pass, read-back,
   * de-duplication), page allocation and rendering, lookup.
   */
  vtkGetMacro(RequestTimeMs, double);
  vtkGetMacro(PageTimeMs, double);
  vtkGetMacro(LookupTimeMs, double);
  ///@}

protected:
  vtkPenumbraResolutionMatchedShadows();
  ~vtkPenumbraResolutionMatchedShadows() override;

  int MaxResolution = 32768;
  int AtlasSize = 4096;
  int Filter = FILTER_NONE;
  int Footprint = FOOTPRINT_AREA;
  int LODBias = 1;
  int AnalysisStep = 2;
  int RefineLevels = 3;
  bool Cached = true;
  double Bias = 1e-4;
  double SlopeBias = 0.25;
  int NumberOfRequestedPages = 0;
  int RequestedLevels[2] = { 0, 0 };
  int NumberOfRenderedPages = 0;
  int NumberOfRefinedPages = 0;
  int NumberOfSuperpages = 0;
  int NumberOfResidentPages = 0;
  double CoarserShare = 0.0;
  long long TotalRenderedPages = 0;
  double RequestTimeMs = 0.0;
  double PageTimeMs = 0.0;
  double LookupTimeMs = 0.0;

private:
  vtkPenumbraResolutionMatchedShadows(const vtkPenumbraResolutionMatchedShadows&) = delete;
  void operator=(const vtkPenumbraResolutionMatchedShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
