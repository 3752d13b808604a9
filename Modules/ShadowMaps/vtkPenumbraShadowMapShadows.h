/**
 * @class   vtkPenumbraShadowMapShadows
 * @brief   Classical shadow maps done the practical way of Brabec, "Shadow Techniques for
 *          Interactive and Real-Time Applications", PhD thesis, 2003, ch. 4-6: linear depth,
 *          optional second-depth (midpoint) maps, near/far and extent fitted to the visible
 *          receivers with depth clamping, PCF, and cube or dual-paraboloid maps for point
 *          lights.
 *
 * Per light (maps are cached, see below):
 * - Directional lights: one orthographic map whose s/t extent and depth range are fitted
 *   to the valid view samples that face the light (Brabec 2003, §4.2.1, axis-aligned
 *   rectangle in light space, computed exactly from the samples instead of a control
 *   texture; SetFitRectangle() rotates it, §4.2.2). Casters in front of the fitted near plane are
 * not clipped but clamped to depth 0 (GL_DEPTH_CLAMP plus gl_FragDepth clamping, ch. 4.1.2), so
 * they still shadow.
 * - Spot lights (VTK cone half-angle below 90 degrees): one perspective map along the axis,
 *   its field of view fitted to the receivers inside the cone (never wider than the cone).
 * - Point lights (positional, cone >= 90): six 90-degree cube faces (`Point` = cube,
 *   only the faces that hold receivers are rendered) or two paraboloid hemispheres
 *   (ch. 6). Paraboloid maps: casters are clipped against each hemisphere's equator plane
 *   and tessellated on the CPU so that no edge spans more than about 2 degrees from the
 *   light (the straight rasterized edges then follow the curved images of the true edges to
 *   a fraction of a texel at 2048^2), and the fragment stage writes the exact distance
 *   along the texel centre's direction to the triangle's plane. The lookup projects each
 *   sample exactly (per sample, no per-vertex interpolation). What remains approximate is
 *   the coverage of a texel near a triangle edge (chord vs arc, below 0.2 texel).
 * - Depth is linear everywhere (ch. 4.1): orthographic depth over the fitted range,
 *   perspective depth = distance along the view axis / Far, paraboloid depth = distance
 *   from the light / Far, Far = the farthest receiver. Stored as 32-bit float.
 * - `Depth` = midpoint (ch. 4.1.1, Woo): a second depth-peeled layer is rendered and the map
 *   stores the midpoint of the first two surfaces (the far value 1 when there is no second
 *   surface), which moves the comparison away from the lit surface itself.
 *
 * The depth comparison runs per view sample, after the reference's facing and spot-cone rules
 * (samples facing away or outside the cone are shadowed, lights that are off are lit
 * everywhere and get no map), so the error against vtkPenumbraReference measures shadow-map
 * aliasing only. Two lookups (SetLookup()): on the GPU (default) with a depth compare per
 * tap (texelFetch of the raw depth and a LEQUAL test, the nearest texel's answer of a
 * sampler2DShadow; PCF averages the compared taps), the maps staying on the GPU and only the
 * visibility of the pending samples read back; or on the
 * CPU (vtkSMPTools, double precision) after reading the maps back. A sample is shadowed
 * when stored depth < sample depth - bias, with
 *   bias = Bias + SlopeBias * (1 + r) * texel footprint * tan(angle to the light) / range,
 * r the PCF kernel radius in texels (0 without PCF) and tan clamped to 1000 (0.057 degrees
 * from grazing; lower caps leave grazing receivers in their own shadow).
 *
 * Caching: a light's maps are rendered again only when the light (position, focal point,
 * cone, positional flag, switched on), the casters (geometry or flags time), the camera or
 * window size (the maps are fitted to the view samples) or this object's settings change.
 * GetNumberOfMapRenders() counts rendered views (faces, hemispheres) since construction.
 * Memory: the cached maps keep 4 bytes per texel and view, e.g. 16 MiB per view at 2048^2
 * (96 MiB for a cube at 2048^2), per light, as GPU textures (GPU lookup) or CPU arrays.
 *
 * Area and linear lights are rejected (error; the pass renders that light unshadowed) unless
 * AreaLightMode is AREA_PCSS (the `pcss` technique) or AREA_SINGLE_SAMPLE
 * (`single-sample-soft`): then each gets one perspective map from its centre along its
 * normal (fitted like a spot light with a cone just under 90 degrees, whose cone rule it
 * then follows). A sample is lit by the part of the light above its tangent plane (the
 * reference's rule per light point; closed form for a rectangle or segment), and every map
 * tap is compared with the receiver's tangent plane at the tap's texel (receiver-plane
 * depth bias). Single-sample soft shadows: Brabec, "Shadow Techniques for Interactive and
 * Real-Time Applications", PhD thesis, 2003, ch. 11 (nearest blocker / nearest lit texel in
 * a box around the sample, meeting at 0.5), see vtkPenumbraShadowMapSoft.glsl. PCSS:
 * percentage-closer soft shadows: Fernando,
 * "Percentage-Closer Soft Shadows", NVIDIA 2005, with the search region and the filter
 * kernel the light's own rectangle or segment projected into the map (its U and V axes
 * through the map's rows), taps on a stratified grid of light points. A blocker at
 * light-view depth wb hides light point centre + o from a receiver at depth w where the map
 * shows it at st + xy(o) (1/wb - 1/w), so the blocker search looks at the light's image for
 * wb = SearchDepth * w, the average depth of the blockers found fixes wb, and PCF over the
 * light's image at that wb gives the visible fraction (over the taps above the tangent
 * plane); a search that finds no blocker, or only blockers, ends early. GPU lookup only.
 */

#ifndef vtkPenumbraShadowMapShadows_h
#define vtkPenumbraShadowMapShadows_h

#include "vtkPenumbraShadowMapsModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr
class vtkPenumbraStatistics;

class VTKPENUMBRASHADOWMAPS_EXPORT vtkPenumbraShadowMapShadows : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraShadowMapShadows* New();
  vtkTypeMacro(vtkPenumbraShadowMapShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Appends the last frame's counts and phase times (vtkPenumbraShadowTechnique::GetStatistics()).
   */
  void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  /**
   * With the GPU lookup (default), every light is answered on the GPU: the maps are fitted to
   * the frame's G-buffer by a reduction on the GPU and looked up from the G-buffer straight
   * into the light's visibility channel, so no sample is read back. The CPU lookup reads the
   * samples back (vtkPenumbraShadowTechnique::ComputeFrame()).
   */
  int ComputeFrame(vtkPenumbraFrame* frame) override;
  bool ReadsSamples() override { return this->Lookup == LOOKUP_CPU; }
  /**
   * In a distributed render every process draws its own casters into maps fitted to all the
   * processes' receivers (or the whole scene), and the maps are composited by a minimum per
   * texel (two for midpoint depth): the image of one process holding every caster, at a
   * cost per light of the maps' texels, not of the triangles.
   */
  bool CompositesAcrossProcesses() override { return true; }

  void ReleaseGraphicsResources(vtkWindow* window) override;

  /**
   * True with AREA_PCSS or AREA_SINGLE_SAMPLE: area and linear lights get soft shadows.
   */
  bool HandlesAreaLights() override { return this->AreaLightMode != AREA_NONE; }

  /**
   * The registry's name of this configuration: "pcss", "single-sample-soft", "resm" or
   * "shadowmap".
   */
  const char* GetTechniqueName() override
  {
    if (this->AreaLightMode != AREA_NONE)
    {
      return this->AreaLightMode == AREA_PCSS ? "pcss" : "single-sample-soft";
    }
    return this->ResolutionMode == RESOLUTION_ESTIMATED ? "resm" : "shadowmap";
  }

  /** `pcss` and `single-sample-soft` shadow hard lights as `shadowmap`. */
  const char* GetTechniqueNameFor(vtkLight* light) override;

  enum AreaLightModes
  {
    AREA_NONE = 0,         ///< area and linear lights are rejected (hard-shadow technique)
    AREA_PCSS = 1,         ///< percentage-closer soft shadows (Fernando 2005)
    AREA_SINGLE_SAMPLE = 2 ///< single-sample soft shadows (Brabec 2003, ch. 11)
  };

  ///@{
  /**
   * AREA_NONE (default), AREA_PCSS or AREA_SINGLE_SAMPLE, see the class description. Both
   * soft modes need the GPU lookup.
   */
  vtkSetClampMacro(AreaLightMode, int, AREA_NONE, AREA_SINGLE_SAMPLE);
  vtkGetMacro(AreaLightMode, int);
  ///@}

  ///@{
  /**
   * PCSS blocker-search taps per light axis (n x n for a rectangle, 2 n for a line); single-
   * sample soft shadows: taps per half side of the search box ((2n + 1)^2 taps, one per
   * texel while the box is narrower). Default 4, clamped to [1, 16].
   */
  vtkSetClampMacro(SearchTaps, int, 1, 16);
  vtkGetMacro(SearchTaps, int);
  ///@}

  ///@{
  /**
   * PCSS filter taps per light axis (n x n for a rectangle, 2 n for a line): the number of
   * visibility levels. Default 6, clamped to [1, 32].
   */
  vtkSetClampMacro(FilterTaps, int, 1, 32);
  vtkGetMacro(FilterTaps, int);
  ///@}

  ///@{
  /**
   * PCSS: the nearest blocker the search looks for, as a fraction of the receiver's distance
   * from the light along its axis (smaller finds blockers nearer the light, over a wider
   * region). Default 0.2, clamped to [0.01, 0.99].
   */
  vtkSetClampMacro(SearchDepth, double, 0.01, 0.99);
  vtkGetMacro(SearchDepth, double);
  ///@}

  ///@{
  /**
   * Single-sample soft shadows: true (default) derives each penumbra from the light's own
   * size (no calibration); false uses the thesis's radii (RScale, RBias, RShrink).
   */
  vtkSetMacro(Physical, bool);
  vtkGetMacro(Physical, bool);
  vtkBooleanMacro(Physical, bool);
  ///@}

  ///@{
  /**
   * Single-sample soft shadows with Physical off (Brabec 2003, ch. 11): the search radius
   * r_max = RScale * w + RBias texels (w the receiver's distance along the light's axis) and,
   * at a blocker of depth d, r_max * RShrink * (w - d). RScale in texels per unit length
   * (default 4), RBias in texels (default 0), RShrink per unit length (default 1).
   */
  vtkSetClampMacro(RScale, double, 0.0, 1e6);
  vtkGetMacro(RScale, double);
  vtkSetClampMacro(RBias, double, 0.0, 4096.0);
  vtkGetMacro(RBias, double);
  vtkSetClampMacro(RShrink, double, 1e-9, 1e9);
  vtkGetMacro(RShrink, double);
  ///@}

  ///@{
  /**
   * The soft lookups' adaptive sampling (Brabec 2003, ch. 11.3, for single-sample soft
   * shadows; used for PCSS too): the search runs at the corners of AdaptiveBlock x
   * AdaptiveBlock pixel blocks, and a pixel whose four corners lie on its prop and share its
   * hard shadow test interpolates them bilinearly (others search). 1 searches at every
   * pixel. Default 4 (the thesis's 4 x 4 blocks), clamped to [1, 16].
   */
  vtkSetClampMacro(AdaptiveBlock, int, 1, 16);
  vtkGetMacro(AdaptiveBlock, int);
  ///@}

  ///@{
  /**
   * PCSS: no tap lies farther than this from the sample, in map texels (bounds the cost of
   * huge lights; the penumbra is then too narrow). Default 64, clamped to [1, 4096].
   */
  vtkSetClampMacro(MaxRadius, double, 1.0, 4096.0);
  vtkGetMacro(MaxRadius, double);
  ///@}

  enum FilterModes
  {
    FILTER_NONE = 0,    ///< one nearest texel, 0 or 1 (what a hardware depth compare gives)
    FILTER_PCF = 1,     ///< percentage-closer filtering over PCFKernel^2 nearest texels (ch. 5)
    FILTER_BILINEAR = 2 ///< Fast PCF: bilinear weights of the 2 x 2 adjacent compared texels
  };
  enum DepthModes
  {
    DEPTH_LINEAR = 0,  ///< the nearest surface, linear depth (ch. 4.1)
    DEPTH_MIDPOINT = 1 ///< midpoint of the first two surfaces (ch. 4.1.1)
  };
  enum PointModes
  {
    POINT_CUBE = 0,      ///< six perspective cube faces
    POINT_PARABOLOID = 1 ///< two paraboloid hemispheres (ch. 6)
  };

  ///@{
  /**
   * Map texels per side (per cube face / hemisphere for point lights). Default 2048,
   * clamped to [64, 8192].
   */
  vtkSetClampMacro(Resolution, int, 64, 8192);
  vtkGetMacro(Resolution, int);
  ///@}

  enum ResolutionModes
  {
    RESOLUTION_FIXED = 0,    ///< Resolution x Resolution texels for every view
    RESOLUTION_ESTIMATED = 1 ///< RESM: the view samples' need, per axis (see below)
  };

  ///@{
  /**
   * RESOLUTION_FIXED (default) or RESOLUTION_ESTIMATED: resolution-estimation shadow
   * mapping (RESM; Ferko 2013, in the alias-free shadow mapping thesis it belongs to). For
   * directional and spot lights the view is fitted tightly to the receivers as always, and
   * every sample that can be lit (facing the light, inside the cone) estimates the map
   * resolution it needs: the Jacobian J of its map coordinates with respect to screen pixels
   * (finite differences to a neighbour on its own plane) gives 2 |row of J| / |det J| texels
   * across the map per axis, so that a texel projects back onto at most one pixel. The map
   * gets, per axis, the Coverage quantile of the 4 x 4-sample tiles' largest needs, rounded up
   * to a multiple of 64, clamped to [64, MaxResolution]; it shrinks only when the need falls
   * below 85 % of the current size (hysteresis against shimmering), and grows at once. The
   * estimate runs when the maps are rebuilt (light, casters or view changed), on the GPU from
   * the G-buffer, or on the CPU for a CPU sample set. Point lights keep Resolution per face.
   */
  vtkSetClampMacro(ResolutionMode, int, RESOLUTION_FIXED, RESOLUTION_ESTIMATED);
  vtkGetMacro(ResolutionMode, int);
  ///@}

  ///@{
  /**
   * RESM: the largest map side in texels. Default 4096, clamped to [64, 16384] (llvmpipe's
   * largest texture).
   */
  vtkSetClampMacro(MaxResolution, int, 64, 16384);
  vtkGetMacro(MaxResolution, int);
  ///@}

  ///@{
  /**
   * RESM: the share of the view's tiles whose samples get at least the resolution they need.
   * Default 0.99; 1 takes the largest need, which a single grazing sample drives to
   * MaxResolution (Ferko's outliers). Clamped to [0.5, 1].
   */
  vtkSetClampMacro(Coverage, double, 0.5, 1.0);
  vtkGetMacro(Coverage, double);
  ///@}

  ///@{
  /**
   * RESM: the estimate analyses every AnalysisStep-th sample per axis (its neighbours stay
   * the adjacent pixels), AnalysisStep^2 times less work. Default 2, clamped to [1, 4].
   */
  vtkSetClampMacro(AnalysisStep, int, 1, 4);
  vtkGetMacro(AnalysisStep, int);
  ///@}

  /**
   * The map size (texels along s and t) of the last light computed, and for RESM the
   * estimated need before rounding and clamping (0 when nothing was estimated).
   */
  vtkGetVector2Macro(LastMapSize, int);
  vtkGetVector2Macro(LastEstimate, double);

  /**
   * The cached map size of `light` (texels along s and t) and, for RESM, its estimated need
   * (0 when not estimated); false when the light has no maps.
   */
  bool GetMapSize(vtkLight* light, int size[2], double need[2]);

  ///@{
  /**
   * FILTER_NONE (default), FILTER_PCF or FILTER_BILINEAR. PCF returns the fraction of lit
   * taps, so visibility takes values between 0 and 1 at shadow edges. FILTER_BILINEAR is
   * Fast PCF (Brabec 2003, ch. 5.2): the four texels adjacent to the sample's continuous map
   * position are compared and their 0/1 results weighted bilinearly by the position's
   * fraction between the texel centres, so the visibility ramps over one texel at an edge and
   * is 0 or 1 elsewhere; four taps, explicitly weighted on the GPU and the CPU alike (a
   * GL_LINEAR depth compare weights in an implementation-defined way). Its slope bias uses a
   * radius of 1 texel.
   */
  vtkSetClampMacro(Filter, int, FILTER_NONE, FILTER_BILINEAR);
  vtkGetMacro(Filter, int);
  ///@}

  ///@{
  /**
   * PCF kernel width in texels, odd, default 3, clamped to [3, 9] (even values are rounded
   * up to the next odd one when used).
   */
  vtkSetClampMacro(PCFKernel, int, 3, 9);
  vtkGetMacro(PCFKernel, int);
  ///@}

  ///@{
  /**
   * Constant depth bias as a fraction of the light view's depth range (orthographic: the
   * fitted receiver depth span; perspective and paraboloid: Far, the farthest receiver's
   * distance), so it is independent of the scene's units. Default 1e-4 (1 mm for a 10 m
   * range), clamped to [0, 0.1]. Linear float depth needs little: its main purpose is the
   * float rounding of the rasterizer.
   */
  vtkSetClampMacro(Bias, double, 0.0, 0.1);
  vtkGetMacro(Bias, double);
  ///@}

  ///@{
  /**
   * Slope-scaled bias in texel footprints: the receiver's depth change across
   * SlopeBias * (1 + PCF radius) texels at its angle to the light is added to the bias.
   * Default 1.0 (covers the half texel diagonal of nearest lookup with margin), clamped to
   * [0, 16].
   */
  vtkSetClampMacro(SlopeBias, double, 0.0, 16.0);
  vtkGetMacro(SlopeBias, double);
  ///@}

  ///@{
  /**
   * DEPTH_LINEAR (default) or DEPTH_MIDPOINT (one more depth-peeled pass per view).
   */
  vtkSetClampMacro(DepthMode, int, DEPTH_LINEAR, DEPTH_MIDPOINT);
  vtkGetMacro(DepthMode, int);
  ///@}

  enum LookupModes
  {
    LOOKUP_GPU = 0,    ///< hardware depth compare on the GPU (default, see SetLookup())
    LOOKUP_CPU = 1,    ///< maps read back, compared in double precision with vtkSMPTools
    LOOKUP_GBUFFER = 2 ///< LOOKUP_GPU, always as a full-screen pass over the G-buffer
  };

  ///@{
  /**
   * Where the per-sample depth comparison runs (see the class description). Both give the
   * same answers up to float rounding of the projection; the GPU lookup avoids reading the
   * maps back, which dominates at high resolutions. LOOKUP_GPU
   * compares a light with one map (directional, spot) inside the receivers' own fragment
   * shaders while they are shaded, as VTK's vtkShadowMapPass does, and runs the full-screen
   * G-buffer pass only when the visibility is asked for (vtkPenumbraFrame::ShaderLookup);
   * LOOKUP_GBUFFER always runs that pass (the same values; for comparisons).
   */
  vtkSetClampMacro(Lookup, int, LOOKUP_GPU, LOOKUP_GBUFFER);
  vtkGetMacro(Lookup, int);
  ///@}

  ///@{
  /**
   * POINT_CUBE (default) or POINT_PARABOLOID for point lights.
   */
  vtkSetClampMacro(PointMode, int, POINT_CUBE, POINT_PARABOLOID);
  vtkGetMacro(PointMode, int);
  ///@}

  enum FitRectangles
  {
    FIT_AXIS = 0,    ///< axis-aligned in the light's arbitrary basis (ch. 4.2.1)
    FIT_MINIMUM = 1, ///< the minimum-area rectangle over the receivers (ch. 4.2.2)
    FIT_SQUARE = 2   ///< the rectangle whose longer side is shortest
  };

  ///@{
  /**
   * How a directional light's orthographic map is fitted in its plane: FIT_AXIS (default),
   * the rectangle aligned with an arbitrary in-plane basis of the light direction, or
   * FIT_MINIMUM, the minimum-area enclosing rectangle of the receivers' light-plane hull
   * (Brabec 2003, ch. 4.2.2), so the same texels cover less area, or FIT_SQUARE, the
   * enclosing rectangle whose longer side is shortest (a square map's texels are that side
   * over the resolution; within a degree's rotation of the optimum). Other lights ignore it.
   */
  vtkSetClampMacro(FitRectangle, int, FIT_AXIS, FIT_SQUARE);
  vtkGetMacro(FitRectangle, int);
  ///@}

  enum FitTargets
  {
    FIT_TO_VIEW = 0,  ///< the receivers the view samples see
    FIT_TO_SCENE = 1, ///< every surface of the scene: kept while only the camera moves
    FIT_TO_AUTO = 2   ///< the scene while the camera sees all of it, else the view (default)
  };

  ///@{
  /**
   * What the maps cover. FIT_TO_VIEW: the receivers the view samples see (their tile boxes,
   * Brabec 2003, ch. 4.2), the densest map for the view, fitted and rendered again whenever
   * the camera moves. FIT_TO_SCENE: every triangle of the scene, as VTK's vtkShadowMapPass
   * fits its maps: coarser texels on what is seen, but the maps depend only on the lights
   * and the scene, so a frame where only the camera moved renders none (and the lookup in
   * the receivers' shaders needs no view samples for them). FIT_TO_AUTO (default): the scene
   * while the camera sees the whole scene box (the visible receivers are then the scene, so
   * the view fit would cover about as much and cost a G-buffer and a fit per camera move),
   * else the view (a part of a larger scene is seen: its denser map matters). RESM
   * (RESOLUTION_ESTIMATED) sizes its maps from the view samples and always fits to the view.
   */
  vtkSetClampMacro(FitTo, int, FIT_TO_VIEW, FIT_TO_AUTO);
  vtkGetMacro(FitTo, int);
  ///@}

  /**
   * The world-space side lengths of the cached orthographic map of directional `light`
   * (the fitted rectangle, padding included); false when the light has no such map.
   */
  bool GetMapFootprint(vtkLight* light, double sides[2]);

  /**
   * Views (faces, hemispheres) rendered since construction; cached maps do not count.
   */
  vtkGetMacro(NumberOfMapRenders, int);

  /**
   * Views the last call used (rendered or cached): 1, up to 6 cube faces or 2 hemispheres,
   * 0 when no map was needed (light off, nothing facing the light, no casters).
   */
  vtkGetMacro(NumberOfViews, int);

  /**
   * How many times the caster vertices were uploaded to the GPU since construction.
   */
  vtkGetMacro(NumberOfUploads, int);

  ///@{
  /**
   * Phase times of the last call in milliseconds: map rendering and read back (0 when the
   * cached maps were used), and the per-sample lookup.
   */
  vtkGetMacro(MapTimeMs, double);
  vtkGetMacro(LookupTimeMs, double);
  ///@}

  ///@{
  /**
   * The dual-paraboloid mapping (Brabec 2003, ch. 6, Eq. 6.3 in closed form). A unit direction
   * d goes to hemisphere 0 (d_z >= 0, axis +z) or 1 (d_z < 0, axis -z, mirrored in z only)
   * and to paraboloid coordinates xy = (d_x, d_y) / (1 + |d_z|) inside the unit disk. The
   * hemisphere is chosen by the sign of d_z, so 1 + |d_z| >= 1 and the z -> -1 singularity of
   * a single paraboloid is never evaluated. The inverse returns a unit direction.
   */
  static int ParaboloidFromDirection(const double d[3], double xy[2]);
  static void DirectionFromParaboloid(const double xy[2], int hemisphere, double d[3]);
  ///@}

protected:
  vtkPenumbraShadowMapShadows();
  ~vtkPenumbraShadowMapShadows() override;

  int Resolution = 2048;
  int ResolutionMode = RESOLUTION_FIXED;
  int MaxResolution = 4096;
  double Coverage = 0.99;
  int AnalysisStep = 2;
  int LastMapSize[2] = { 0, 0 };
  double LastEstimate[2] = { 0.0, 0.0 };
  int Filter = FILTER_NONE;
  int PCFKernel = 3;
  double Bias = 1e-4;
  double SlopeBias = 1.0;
  int DepthMode = DEPTH_LINEAR;
  int PointMode = POINT_CUBE;
  int FitRectangle = FIT_AXIS;
  int FitTo = FIT_TO_AUTO;
  int Lookup = LOOKUP_GPU;
  int AreaLightMode = AREA_NONE;
  int SearchTaps = 4;
  int FilterTaps = 6;
  double SearchDepth = 0.2;
  double MaxRadius = 64.0;
  bool Physical = true;
  double RScale = 4.0;
  double RBias = 0.0;
  double RShrink = 1.0;
  int AdaptiveBlock = 4;
  int NumberOfMapRenders = 0;
  int NumberOfViews = 0;
  int NumberOfUploads = 0;
  double MapTimeMs = 0.0;
  double LookupTimeMs = 0.0;

private:
  vtkPenumbraShadowMapShadows(const vtkPenumbraShadowMapShadows&) = delete;
  void operator=(const vtkPenumbraShadowMapShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
