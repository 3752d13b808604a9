/**
 * @class   vtkPenumbraSoftShadowMapShadows
 * @brief   Soft shadow maps for linear, rectangular and disc area lights: Brabec, "Shadow
 *          Techniques for Interactive and Real-Time Applications", PhD thesis, 2003, ch. 10.
 *
 * Per area or linear light (vtkPenumbraAreaLight):
 * 1. Light samples: a line gets NumberOfLineSamples points evenly spaced from one endpoint
 *    to the other (both included); a rectangle the GridSamples x GridSamples grid whose
 *    outer points are its corners; a disc that grid through Shirley and Chiu's concentric
 *    map (its outer ring on the rim, the centre in its middle). The light is split into equal
 * elements that share samples: segments between adjacent line samples (ch. 10.1.2); grid cells
 * (ELEMENTS_CELLS, Ying et al.'s polygon variant in ch. 10.1.3) or two triangles per cell
 *    (ELEMENTS_TRIANGLES, ch. 10.1.3).
 * 2. Depth maps: one perspective map per light sample with a square field of view (see
 *    SetFit(): the whole scene, kept while only the camera moves, or the view samples),
 *    storing linear 32-bit float depth (distance along the axis / Far) of the casters,
 *    rendered on the GPU with shadowmap's programs and read back; when some triangles do not
 *    cast, a second map of every surface, where the skins end.
 * 3. Depth discontinuities (ch. 10.1.4): a 2 x 2 texel cell whose depths differ by more than
 *    Threshold times the nearest, and where the 3 x 3 Laplacian of one of its texels divided
 *    by 3 times its depth (a straight step of relative height h gives h) exceeds Threshold
 *    too, becomes a "skin": its triangles that join near and far texels, unprojected to world
 *    space, visibility 0 at near (occluder) and 1 at far (receiver) vertices. Cells within 2
 *    texels of the map border (the frustum's edges) and cells whose near side does not cast
 *    make none.
 * 4. Warping (ch. 10.1.1): per element edge (a, b), b's skins are projected into a's map and
 *    scan-converted there on the CPU (vtkSMPTools): depth perspective-correct and tested
 *    against a's real depth, never written (the shadow test must see only real geometry);
 *    the nearest skin wins where skins overlap; the visibility interpolated linearly in a's
 *    image, which for a receiver parallel to a linear light is exactly the linear ramp of
 *    Eq. 10.1.
 * 5. Lookup per view sample on the CPU: light sample i is lit when the view sample passes
 *    map i's shadow test and i lies above its tangent plane (the reference's per-sample
 *    facing rule, vtkPenumbraReference); outside map i nothing blocks it. On an element edge
 *    from a lit a to an unlit b, t(a -> b) is the skin value of b in a's map (0.5 where no
 *    skin covers the sample), or the tangent plane's exact crossing when b lies below it,
 *    the smaller of both. A segment gives 1, t or 0 (the thesis's channels initialised to
 *    0.5); a cell the area of the polygon through its lit corners and its edges' split
 *    points; a triangle 1/3 per lit vertex, or half the smallest skin value of the other two
 *    in its map (the thesis's scheme). The visibility is the mean over the elements.
 *
 * Where it is not exact: the visibility across a penumbra is linear in the skin's parameter
 * (exact only for a line parallel to the receiver, ch. 10, Eq. 10.1; area lights have a
 * rational quadratic transition); points that see the light but none of its samples are in
 * umbra (undersampling, ch. 10.1.2); thin occluders under the threshold and map aliasing.
 * Point, spot and directional lights get vtkPenumbraShadowMapShadows' hard shadows at the
 * same resolution and bias.
 */

#ifndef vtkPenumbraSoftShadowMapShadows_h
#define vtkPenumbraSoftShadowMapShadows_h

#include "vtkPenumbraShadowMapsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr
class vtkPenumbraStatistics;

class VTKPENUMBRASHADOWMAPS_EXPORT vtkPenumbraSoftShadowMapShadows
  : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraSoftShadowMapShadows* New();
  vtkTypeMacro(vtkPenumbraSoftShadowMapShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  void ReleaseGraphicsResources(vtkWindow* window) override;

  bool HandlesAreaLights() override { return true; }
  const char* GetTechniqueName() override { return "soft-shadowmap"; }
  /** Hard lights get `shadowmap`'s hard shadows. */
  const char* GetTechniqueNameFor(vtkLight* light) override;

  ///@{
  /**
   * Light samples along a linear light, both endpoints included. Default 3 (the thesis's
   * endpoints and centre: 2 show the overlap artifact of ch. 10.1.2), clamped to [2, 16].
   */
  vtkSetClampMacro(NumberOfLineSamples, int, 2, 16);
  vtkGetMacro(NumberOfLineSamples, int);
  ///@}

  ///@{
  /**
   * Light samples per axis of a rectangular light, the corners included. Default 2 (the 4
   * corners), clamped to [2, 4].
   */
  vtkSetClampMacro(GridSamples, int, 2, 4);
  vtkGetMacro(GridSamples, int);
  ///@}

  enum ElementModes
  {
    ELEMENTS_CELLS = 0,    ///< grid cells, visible polygon (Ying et al.'s variant, ch. 10.1.3)
    ELEMENTS_TRIANGLES = 1 ///< two triangles per cell, per-vertex channels (ch. 10.1.3)
  };

  ///@{
  /**
   * How a rectangular light's samples are combined, see the class description. Default
   * ELEMENTS_CELLS.
   */
  vtkSetClampMacro(Elements, int, ELEMENTS_CELLS, ELEMENTS_TRIANGLES);
  vtkGetMacro(Elements, int);
  ///@}

  enum FitModes
  {
    FIT_VIEW = 0, ///< maps fitted to the view samples: rebuilt when the camera moves
    FIT_SCENE = 1 ///< maps fitted to the whole scene: kept while only the camera moves
  };

  ///@{
  /**
   * What each light sample's map covers. FIT_SCENE (default): the box of every surface, seen
   * along the axis from the light's centre to the box's centre, when each corner lies within
   * 85 degrees of that axis from every sample (else as FIT_VIEW); the maps and channels are
   * then kept while only the camera moves, at the resolution the whole scene leaves (coarser
   * when the view shows a part of it). FIT_VIEW: the view samples in front of each sample,
   * along the light's emission direction (every texel serves the view; maps and skins are
   * rebuilt whenever the view samples change).
   */
  vtkSetClampMacro(Fit, int, FIT_VIEW, FIT_SCENE);
  vtkGetMacro(Fit, int);
  ///@}

  ///@{
  /**
   * Texels per side of each light sample's map. Default 1024, clamped to [64, 4096].
   */
  vtkSetClampMacro(Resolution, int, 64, 4096);
  vtkGetMacro(Resolution, int);
  ///@}

  ///@{
  /**
   * Depth-discontinuity threshold, relative: a depth jump of this fraction of the depth
   * (linear depth from the light sample) makes a skin. Too low makes skins at creases and on
   * sloped receivers (false penumbrae), too high misses occluders close to their receivers.
   * Default 0.02, clamped to [0.001, 1].
   */
  vtkSetClampMacro(Threshold, double, 0.001, 1.0);
  vtkGetMacro(Threshold, double);
  ///@}

  ///@{
  /**
   * Constant depth bias of the shadow test as a fraction of the map's Far. Default 5e-4
   * (shadowmap's 1e-4 leaves acne on the city's roofs: the maps' fields of view are wide,
   * fitted to every receiver from each light sample), clamped to [0, 0.1].
   */
  vtkSetClampMacro(Bias, double, 0.0, 0.1);
  vtkGetMacro(Bias, double);
  ///@}

  ///@{
  /**
   * Slope-scaled bias in texel footprints (as vtkPenumbraShadowMapShadows'). Default 1,
   * clamped to [0, 16].
   */
  vtkSetClampMacro(SlopeBias, double, 0.0, 16.0);
  vtkGetMacro(SlopeBias, double);
  ///@}

  ///@{
  /**
   * Lookup block side in samples (not in the thesis): the lookup runs at every Block-th
   * sample per axis first, and a block whose four corners agree on full light or full
   * umbra, and whose samples all lie on the corners' plane (same prop, same facet normal),
   * takes that value without a lookup per sample; every other block is looked up sample by
   * sample. 1 looks up every sample. Default 4, clamped to [1, 16]. A shadow or gap narrower
   * than a block that falls between its corners is missed (docs/benchmarks.md has its error).
   */
  vtkSetClampMacro(Block, int, 1, 16);
  vtkGetMacro(Block, int);
  ///@}

  ///@{
  /**
   * What the last area light's call did: light samples (maps), skin triangles built (over
   * all maps), and the phase times in milliseconds (maps rendered and read back; skins found
   * and warped; lookup; the first two are 0 when the light's maps were kept). Builds: how
   * many times maps and channels were built since construction.
   */
  vtkGetMacro(NumberOfBuilds, int);
  vtkGetMacro(NumberOfMaps, int);
  vtkGetMacro(NumberOfSkins, vtkIdType);
  vtkGetMacro(MapTimeMs, double);
  vtkGetMacro(SkinTimeMs, double);
  vtkGetMacro(LookupTimeMs, double);
  ///@}

protected:
  vtkPenumbraSoftShadowMapShadows();
  ~vtkPenumbraSoftShadowMapShadows() override;

  int NumberOfLineSamples = 3;
  int GridSamples = 2;
  int Elements = ELEMENTS_CELLS;
  int Fit = FIT_SCENE;
  int Resolution = 1024;
  double Threshold = 0.02;
  double Bias = 5e-4;
  double SlopeBias = 1.0;
  int Block = 4;
  int NumberOfMaps = 0;
  int NumberOfBuilds = 0;
  vtkIdType NumberOfSkins = 0;
  double MapTimeMs = 0.0;
  double SkinTimeMs = 0.0;
  double LookupTimeMs = 0.0;

private:
  vtkPenumbraSoftShadowMapShadows(const vtkPenumbraSoftShadowMapShadows&) = delete;
  void operator=(const vtkPenumbraSoftShadowMapShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
