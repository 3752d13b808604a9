/**
 * @class   vtkPenumbraTechniques
 * @brief   Registry of shadow techniques: installs one, by name, on a renderer.
 *
 * Every way Penumbra can draw shadows is registered here under a short name, with a
 * documented set of options. Applications, the scene files' "technique" block, the
 * `penumbra-render --technique` switch and the benchmark all go through Apply(), so a new
 * technique becomes available everywhere by registering it in this one place.
 *
 * Registered techniques:
 *  - `none`: plain VTK rendering, no shadows. No options.
 *  - `auto` (the default of scene files, the CLI, the examples and the Python helper):
 *    vtkPenumbraShadowPass with vtkPenumbraAutoShadows: per light, the technique the
 *    project's measurements favour (hard lights `raytraced`, area and linear lights `gears`;
 *    see that class for the numbers). Options: `quality` ("balanced", default, "exact", or
 *    "fast": k = 4 light samples for soft lights) and `samples` (as for
 *    `raytraced`, for area and linear lights).
 *  - `vtk-shadowmap`: VTK's own vtkShadowMapPass (exponential shadow maps; directional
 *    lights and spot lights under 90 degrees only; opaque geometry only). Options:
 *    `resolution` (integer texels per side, default 1024, 16..16384).
 *  - `raytraced`: vtkPenumbraShadowPass with vtkPenumbraRayTracedShadows: exact shadows from
 *    every light type, one CPU ray per view sample and light sample. Options: `samples`
 *    (light samples per axis of area/linear lights: 0, default, keeps the light's own k, or
 *    one of 4, 8, 16, 32).
 *  - `conservative`: vtkPenumbraShadowPass with vtkPenumbraConservativeShadows (Hertel
 *    et al. 2009): exact hard shadows from point, spot and directional lights; a
 *    conservative shadow map classifies the samples and only the uncertain ones are ray traced.
 *    Options: `resolution` (integer CSM texels per side, per cube face for point lights, default
 *    1024, 64..8192), `layers` (integer depth-peeled map layers, default 2, 2..4; more
 *    layers let more samples look past their own and neighbouring triangles) and `map`
 *    ("cpu", default: exact double-precision conservative rasterization with vtkSMPTools,
 *    or "gpu": a geometry-shader program).
 *  - `shadowmap`: vtkPenumbraShadowPass with vtkPenumbraShadowMapShadows (Brabec 2003,
 *    ch. 4-6): classical depth-compare shadow maps with linear 32-bit float depth, fitted to the
 *    visible receivers, depth clamping. Options: `resolution` (integer texels per side, per
 *    cube face / hemisphere for point lights, default 2048, 64..8192); `filter` ("none",
 *    default: one nearest texel, 0/1 like a hardware compare; or "pcf": percentage-closer
 *    filtering, fractional visibility); `pcf_kernel` (odd integer kernel width in texels,
 *    default 3, 3..9, used with "pcf"); `bias` (constant bias as a fraction of the light
 *    view's depth range, i.e. unit-free, default 1e-4, 0..0.1); `slope_bias` (slope-scaled
 *    bias in texel footprints, default 1.0, 0..16); `depth` ("linear", default, or
 *    "midpoint": Woo's midpoint of the first two surfaces, one more pass per view);
 *    `point` ("cube", default: six faces, or "paraboloid": two dual-paraboloid hemispheres,
 *    exact per-sample projection); `lookup` ("gpu", default: hardware depth compare, or
 *    "cpu": maps read back and compared in double precision).
 *  - `volumes`: vtkPenumbraShadowPass with vtkPenumbraShadowVolumeShadows (Brabec 2003,
 *    ch. 3, 8, 9): exact hard shadows with stencil shadow volumes. Options: `silhouettes`
 *    ("cpu", default: OpenMesh; "gpu": geometry shader with triangle adjacency; "none":
 *    per-triangle volumes), `method` ("auto", default, "zfail" or "zpass"), `cull` (boolean,
 *    default true: skip casters that cannot shadow a visible receiver), `resolve` (boolean, default
 *    true: ray trace the samples next to stencil changes), `cap_offset` (0..1e-3, default 2^-17),
 *    `measure_fill` (boolean, default false: count stencil fragments) and `lights_per_mask`
 *    (1..4, default 4).
 *  - `gears`: vtkPenumbraShadowPass with vtkPenumbraGearsShadows (Wang et al. 2014):
 *    exact soft shadows of area and linear lights at k x k light samples (hard lights are exact
 *    too). Options: `samples` (as for `raytraced`), `grid` (cells per axis, default 128, 1..4096),
 *    `camera_distance` (light-aligned camera distance in light diagonals, default 1,
 *    0.01..100) and `path` ("auto", default, chooses the CPU; "cpu"; or "gpu": the GL 4.3
 *    compute path).
 *
 * Options are JSON text (an object); unknown options and out-of-range values are rejected
 * with a message naming the option.
 *
 * Papers (docs/techniques.md says what each technique changes):
 * - Hertel, Hormann, Westermann, "A Hybrid GPU Rendering Pipeline for Alias-Free Hard
 *   Shadows", Eurographics 2009 Areas Papers.
 * - Brabec, "Shadow Techniques for Interactive and Real-Time Applications", PhD thesis, 2003.
 * - Wang, Wang, Shi, Popescu, "GEARS: A General and Efficient Algorithm for Rendering
 *   Shadows", Computer Graphics Forum 33(6), 2014.
 */

#ifndef vtkPenumbraTechniques_h
#define vtkPenumbraTechniques_h

#include "vtkObject.h"
#include "vtkPenumbraRenderingModule.h" // For export macro

#include <string> // For std::string

class vtkRenderer;

class VTKPENUMBRARENDERING_EXPORT vtkPenumbraTechniques : public vtkObject
{
public:
  static vtkPenumbraTechniques* New();
  vtkTypeMacro(vtkPenumbraTechniques, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The registered technique names and one-line descriptions.
   */
  static int GetNumberOfTechniques();
  static const char* GetTechniqueName(int index);
  static const char* GetTechniqueDescription(int index);
  static bool HasTechnique(const char* name);
  ///@}

  /**
   * Makes `renderer` draw with technique `name` configured by `options` (JSON object text;
   * nullptr or "" means defaults). Returns 1 on success; 0 leaves the renderer unchanged and
   * sets GetErrorMessage() to "<option>: <problem>" or "unknown technique ...".
   */
  int Apply(vtkRenderer* renderer, const char* name, const char* options);

  /**
   * Why the last Apply() failed; empty after a success.
   */
  const char* GetErrorMessage() { return this->ErrorMessage.c_str(); }

protected:
  vtkPenumbraTechniques() = default;
  ~vtkPenumbraTechniques() override = default;

private:
  vtkPenumbraTechniques(const vtkPenumbraTechniques&) = delete;
  void operator=(const vtkPenumbraTechniques&) = delete;

  std::string ErrorMessage;
};

#endif
