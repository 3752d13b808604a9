/**
 * @class   vtkPenumbraConservativeShadows
 * @brief   Exact hard shadows the hybrid way of seed 000: a conservative shadow map classifies
 *          view samples as lit, shadowed or uncertain, and only uncertain ones are ray traced.
 *
 * Per light and frame:
 * 1. Conservative shadow map (CSM) on the rasterizer (seed 000 §1.1): a dedicated
 *    vertex + geometry + fragment program draws the caster triangles of the scene geometry
 *    (uploaded once per geometry/flags change, see GetNumberOfUploads()) into an R32UI id
 *    buffer (triangle id + 1, bit 31 "fully covered") and a 32-bit float depth buffer that
 *    holds, per texel, the smallest *conservative* linear light depth of every triangle whose
 *    projection comes within half a texel diagonal of the texel centre. The geometry stage
 *    enlarges each triangle by the texel diagonal (§1.1.2, clipped to its grown bounding box),
 *    the fragment stage keeps texels by true point-to-segment distance (the note's fix of
 *    §1.1.3) and writes max(plane minimum over the texel, vertex minimum) - epsilon (§1.1.4).
 *    Further depth-peeled layers store the next nearest *other* triangles at each texel (the
 *    note's exact option (ii) for §1.3 rule 6, see SetLayers()).
 *    Light cameras: directional lights get an orthographic view along the light fitted to
 *    the casters and the valid samples; spot lights with a cone of at most 60 degrees one
 *    perspective view covering the cone; wider spots and point lights six 90-degree cube
 *    faces (each drawing only the triangles that reach its frustum). Inside a face's frustum,
 *    triangles that come closer to the light than 0.2 % of the view's depth range (a light
 *    sitting on or very close to geometry) cover the whole face at depth 0: conservative,
 *    but samples there are mostly uncertain (see torture/point_light_on_surface.json).
 * 2. Classification on the CPU (vtkSMPTools, double precision) of the read-back layers; see
 *    the rule list in the implementation. Every decision is provable; anything else is
 *    "uncertain".
 * 3. Uncertain samples are ray traced by vtkPenumbraReference on the CPU (Embree), which also
 *    defines the answer the technique must match exactly.
 *
 * Area lights are rejected (error, the pass renders that light unshadowed).
 *
 * Cost on llvmpipe: the map (one full draw per layer and view, with explicit depth writes and
 * so no early depth test) dominates; Embree traces the few uncertain rays in well under a
 * millisecond. On the two-core llvmpipe target this technique is therefore slower than
 * vtkPenumbraRayTracedShadows; it is exact, and its split pays on a real GPU rasterizer.
 *
 * Memory: Layers x 8 bytes per texel, i.e. 16 MiB at the default 1024^2 and 2 layers, are
 * read back per view; cube faces are processed one after the other.
 */

#ifndef vtkPenumbraConservativeShadows_h
#define vtkPenumbraConservativeShadows_h

#include "vtkPenumbraRenderingModule.h" // For export macro
#include "vtkPenumbraShadowTechnique.h"

#include <memory> // For std::unique_ptr

class vtkPenumbraReference;

class VTKPENUMBRARENDERING_EXPORT vtkPenumbraConservativeShadows
  : public vtkPenumbraShadowTechnique
{
public:
  static vtkPenumbraConservativeShadows* New();
  vtkTypeMacro(vtkPenumbraConservativeShadows, vtkPenumbraShadowTechnique);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) override;

  void ReleaseGraphicsResources(vtkWindow* window) override;

  ///@{
  /**
   * CSM texels per side (per cube face for point lights). Default 1024, clamped to
   * [64, 8192]. Higher resolutions classify more samples and trace fewer rays.
   */
  vtkSetClampMacro(Resolution, int, 64, 8192);
  vtkGetMacro(Resolution, int);
  ///@}

  ///@{
  /**
   * Depth-peeled CSM layers. Layer k stores the nearest triangle no earlier layer stores at
   * that texel, so a sample can look past its own triangle and past neighbours that provably
   * miss its shadow ray (coplanar neighbours at shared edges). Default 2 (the note's option
   * (ii) for seed 000 §1.3b), clamped to [2, 4]. Each layer costs one more full draw and 8
   * bytes per texel; a third layer typically cuts the uncertain share several-fold (e.g.
   * 6.5 % -> 0.7 % on default.json), which pays where the rasterizer is cheaper than rays.
   */
  vtkSetClampMacro(Layers, int, 2, 4);
  vtkGetMacro(Layers, int);
  ///@}

  ///@{
  /**
   * Classification of the last ComputeVisibility call. Every valid sample is counted once:
   * lit (incl. lights that are off), shadowed (incl. facing away from the light and outside
   * a spot cone) or uncertain. Lit + shadowed + uncertain = valid samples.
   */
  vtkGetMacro(NumberOfLitSamples, vtkIdType);
  vtkGetMacro(NumberOfShadowedSamples, vtkIdType);
  vtkGetMacro(NumberOfUncertainSamples, vtkIdType);
  ///@}

  /**
   * Uncertain / (lit + shadowed + uncertain) of the last call; 0 without valid samples.
   */
  double GetUncertainFraction() override;

  /**
   * Shadow rays of the last call: one per uncertain sample.
   */
  vtkGetMacro(NumberOfRays, vtkIdType);

  ///@{
  /**
   * Phase times of the last call in milliseconds: building the maps (upload, render,
   * read back; glFinish included by the read back), classifying, tracing.
   */
  vtkGetMacro(MapTimeMs, double);
  vtkGetMacro(ClassifyTimeMs, double);
  vtkGetMacro(TraceTimeMs, double);
  ///@}

  /**
   * How many times the caster vertices were uploaded to the GPU since construction.
   */
  vtkGetMacro(NumberOfUploads, int);

  /**
   * Number of shadow map views rendered by the last call (1, or 6 for point lights).
   */
  vtkGetMacro(NumberOfViews, int);

  /**
   * The ray tracer for the uncertain samples (exposed for its statistics and epsilons).
   */
  vtkPenumbraReference* GetReference() { return this->Reference; }

protected:
  vtkPenumbraConservativeShadows();
  ~vtkPenumbraConservativeShadows() override;

  int Resolution = 1024;
  int Layers = 2;
  vtkIdType NumberOfLitSamples = 0;
  vtkIdType NumberOfShadowedSamples = 0;
  vtkIdType NumberOfUncertainSamples = 0;
  vtkIdType NumberOfRays = 0;
  double MapTimeMs = 0.0;
  double ClassifyTimeMs = 0.0;
  double TraceTimeMs = 0.0;
  int NumberOfUploads = 0;
  int NumberOfViews = 0;
  vtkPenumbraReference* Reference;

private:
  vtkPenumbraConservativeShadows(const vtkPenumbraConservativeShadows&) = delete;
  void operator=(const vtkPenumbraConservativeShadows&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
