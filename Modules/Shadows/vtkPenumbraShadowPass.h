/**
 * @class   vtkPenumbraShadowPass
 * @brief   Drop-in shadow pass: view samples, a technique's visibility, VTK's own lighting.
 *
 * The one data flow every Penumbra technique shares (see the design guide):
 *
 *  1. the scene's triangles are extracted in double precision (vtkPenumbraSceneGeometry,
 *     cached by MTime: unchanged props are not re-extracted);
 *  2. the view samples are rendered (vtkPenumbraViewSamplesPass);
 *  3. the technique computes, for each light that is on and not black, the visibility of
 *     every sample; lights that are off or black get no shadow work at all;
 *  4. the delegate renders the scene as usual (default: lights, opaque, translucent,
 *     volumetric and overlay steps) with each shadowed light's colour multiplied by its
 *     visibility at the pixel (and, for a vtkPenumbraGoniometricLight, by its diagram's
 *     relative intensity toward the pixel's sample; GetLightFactor()), which shadows diffuse
 *     and specular terms alike, for Phong and PBR receivers. Props marked as non-receivers
 *     (vtkPenumbraShadowKeys) are lit as if nothing blocked, and their view samples get no
 *     shadow work (they are marked as background before the technique runs). Translucent
 *     props are drawn and shadowed:
 *     when translucent receivers are visible, a second sample layer holds the nearest
 *     translucent surface per pixel, the technique computes its visibility in the same
 *     call (both layers stacked), and translucent props are shaded with it (see
 *     GetTranslucentViewSamples()).
 *
 * The view samples and the visibility stay on the GPU (vtkPenumbraFrame): a technique that
 * answers on the GPU reads nothing back, a CPU technique reads back what it needs. A frame
 * in which nothing the shadows depend on changed (camera, window size, lights, geometry,
 * shadow flags, props, technique and its settings) reuses the last frame's visibility and
 * only shades (SetReuseUnchangedFrames()); a frame in which only lights or technique settings
 * changed keeps the view samples (GetLastFrameRenderedSamples()).
 *
 * Use it inside a vtkCameraPass: `camera->SetDelegatePass(shadowPass); renderer->SetPass(camera)`.
 * The last frame's geometry, samples and per-light visibility are kept for analysis (read
 * back from the GPU when asked).
 */

#ifndef vtkPenumbraShadowPass_h
#define vtkPenumbraShadowPass_h

#include "vtkOpenGLRenderPass.h"
#include "vtkPenumbraShadowsModule.h" // For export macro

#include <memory> // For std::unique_ptr
#include <string> // For GetExplanation

class vtkFloatArray;
class vtkLight;
class vtkPenumbraFrame;
class vtkPenumbraRemoteShadows;
class vtkPenumbraSceneGeometry;
class vtkOpenGLRenderWindow;
class vtkPenumbraShadowTechnique;
class vtkPenumbraStatistics;
class vtkPenumbraViewSamples;
class vtkPenumbraViewSamplesPass;
class vtkInformationObjectBaseKey;
class vtkRenderer;
class vtkWindow;

class VTKPENUMBRASHADOWS_EXPORT vtkPenumbraShadowPass : public vtkOpenGLRenderPass
{
public:
  static vtkPenumbraShadowPass* New();

  /**
   * The shadow pass `renderer` draws with: the one recorded with SetInstalled(), else the
   * first one in the renderer's composition of passes (looked for through VTK's camera,
   * sequence, render-steps, image-processing and translucency passes: the composition
   * vtkPenumbraTechniques installs, and the drop-in vtkPenumbraShadowMapPass in
   * `CameraPass -> Sequence[baker, shadows]`); nullptr otherwise.
   */
  static vtkPenumbraShadowPass* GetInstalled(vtkRenderer* renderer);

  /**
   * The first shadow pass in the composition of passes `pass` (itself included), looked for
   * as GetInstalled() does; nullptr when there is none.
   */
  static vtkPenumbraShadowPass* FindIn(vtkRenderPass* pass);

  /**
   * Records `pass` (nullptr: none) as the shadow pass `renderer` draws with, for
   * applications that wrap it in passes of their own, which GetInstalled() cannot look
   * through (ParaView puts it under IceT's compositing pass). Kept in the renderer's
   * information (INSTALLED()).
   */
  static void SetInstalled(vtkRenderer* renderer, vtkPenumbraShadowPass* pass);
  static vtkInformationObjectBaseKey* INSTALLED();
  vtkTypeMacro(vtkPenumbraShadowPass, vtkOpenGLRenderPass);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The technique that computes visibility. Default: none (the scene renders unshadowed).
   */
  void SetTechnique(vtkPenumbraShadowTechnique* technique);
  vtkPenumbraShadowTechnique* GetTechnique();
  ///@}

  ///@{
  /**
   * The technique that shadows the lights the technique cannot (see
   * vtkPenumbraShadowTechnique::SelectTechnique(): area and linear lights with a hard-shadow
   * technique). Default: none set, and the first such light gets what the default fallback
   * factory makes (SetDefaultFallbackFactory(); the registry, Penumbra::Techniques, sets
   * GEARS: exact soft shadows at the light's own samples). The pass warns once per light that
   * it did so, naming the light and the technique; without any fallback, that the light is
   * not shadowed.
   */
  void SetFallbackTechnique(vtkPenumbraShadowTechnique* technique);
  vtkPenumbraShadowTechnique* GetFallbackTechnique();
  ///@}

#ifndef __VTK_WRAP__
  /**
   * What makes the fallback technique of a pass that has none set (a new reference), for
   * every pass of the process. The contract names no technique: the registry layer
   * (vtkPenumbraTechniques) registers its factory when its library is loaded. Default: none.
   */
  using FallbackFactory = vtkPenumbraShadowTechnique* (*)();
  static void SetDefaultFallbackFactory(FallbackFactory factory);
#endif

  ///@{
  /**
   * What the last computed frame did per light `index` (see GetNumberOfLights()): the
   * technique that shadowed it (nullptr when it got no shadow work) and its registry name
   * ("" then). Different lights of one frame may use different techniques.
   */
  vtkPenumbraShadowTechnique* GetLightTechnique(int index);
  const char* GetLightTechniqueName(int index);
  ///@}

  /**
   * Lights of the last computed frame that are switched on but got no shadow work: black
   * lights, lights no visible sample can receive (every sample faces away from them or lies
   * outside a spot light's cone; tested where the samples are on the CPU anyway), lights
   * over the texture-unit budget.
   */
  int GetNumberOfSkippedLights();

  /** The renderer's switched-off lights in the last frame (never any shadow work). */
  int GetNumberOfLightsOff();

  /**
   * Per light of the last computed frame, the technique chosen and why, or why the light
   * was skipped, and under a chosen technique a "figures:" line with its statistics
   * (vtkPenumbraShadowTechnique::GetStatistics()); then the number of skipped lights and of
   * lights off (`penumbra-render --explain` prints it).
   */
  std::string GetExplanation();

  /**
   * The last computed frame's figures for light `index` as a name -> value table, into
   * `stats` (cleared first): the pass's phase times ("extraction_ms", "samples_ms",
   * "technique_ms", "shading_ms") and the statistics of the light's technique
   * (vtkPenumbraShadowTechnique::GetStatistics()). Returns false, with `stats` left empty,
   * when there is no computed frame or no such light.
   */
  bool GetLightStatistics(int index, vtkPenumbraStatistics* stats);

  ///@{
  /**
   * The pass that draws the shaded scene. Default (and after SetDelegatePass(nullptr)):
   * the renderer's own drawing, as VTK draws without a pass (vtkRenderer::UpdateLights and
   * UpdateGeometry: opaque props with hidden-line removal or SSAO when the renderer asks,
   * translucent ones with order-independent transparency or depth peeling as the renderer
   * is set, FXAA, volumes, overlays), inside the vtkCameraPass this pass stands in. A pass
   * of the user's own (vtkOutlineGlowPass, vtkSSAOPass ...) is composed by making it the
   * delegate: its props are then drawn with shadows (vtkPenumbraTechniques does this when
   * the renderer already has a pass).
   */
  void SetDelegatePass(vtkRenderPass* pass);
  vtkRenderPass* GetDelegatePass();
  ///@}

  /** Whether the delegate is the renderer's own drawing (no pass of the user's composed). */
  bool GetDrawsWithRenderer();

  vtkPenumbraSceneGeometry* GetGeometry();
  vtkPenumbraViewSamplesPass* GetViewSamplesPass();

  /**
   * A pass that does nothing, so code written for VTK's shadows,
   * `Sequence[shadows->GetShadowMapBakerPass(), shadows]` inside a vtkCameraPass, keeps
   * working when vtkShadowMapPass is replaced by this class: this pass prepares its own
   * shadows when it renders, so there is nothing to bake beforehand.
   */
  vtkRenderPass* GetShadowMapBakerPass();
  vtkPenumbraViewSamples* GetViewSamples();

  /**
   * Lights of the last frame as VTK numbers them in its shaders (switched-on lights only,
   * in renderer order).
   */
  int GetNumberOfLights();
  vtkLight* GetLight(int index);

  /**
   * Visibility of light `index` (see GetNumberOfLights) per view sample in the last frame,
   * or nullptr if that light got no shadow work (black light) or the technique failed.
   * The pass refills the same arrays each frame (DeepCopy to keep a frame's values).
   */
  vtkFloatArray* GetVisibility(int index);

  /**
   * What light `index`'s colour is multiplied by per view sample in the last frame: the
   * visibility, times the light's relative intensity toward the sample for goniometric
   * lights (vtkPenumbraGoniometricLight; Brabec, "Shadow Techniques for Interactive and Real-Time
   * Applications", PhD thesis, 2003, §8.3.1; every technique renders the
   * diagram, and GetVisibility() stays the geometric visibility). nullptr as for
   * GetVisibility().
   */
  vtkFloatArray* GetLightFactor(int index);

  ///@{
  /**
   * The second sample layer, present in frames with translucent receivers (visible actors
   * with translucent geometry that receive shadows): per pixel, the nearest translucent
   * surface, and each light's visibility there; nullptr otherwise. Translucent props are
   * shaded with this layer, so they are shadowed like opaque ones (and cast shadows like
   * opaque ones). Where several translucent surfaces overlap, the ones behind the nearest
   * take its visibility.
   */
  vtkPenumbraViewSamples* GetTranslucentViewSamples();
  vtkFloatArray* GetTranslucentVisibility(int index);
  ///@}

  /**
   * The last shadowed frame: its G-buffer textures, visibility textures and the CPU views
   * of both; nullptr when the last frame had no shadow work.
   */
  vtkPenumbraFrame* GetFrame();

  ///@{
  /**
   * Reuse the last frame's visibility when nothing it depends on changed: the camera
   * (view and projection), the window size, every switched-on light (by value and MTime),
   * the scene geometry and shadow flags, the props drawn, and this pass's and the
   * technique's settings. Default on. The benchmark turns it off to time the technique on a
   * still scene.
   */
  vtkSetMacro(ReuseUnchangedFrames, bool);
  vtkGetMacro(ReuseUnchangedFrames, bool);
  vtkBooleanMacro(ReuseUnchangedFrames, bool);
  ///@}

  /** True when the last Render() reused the previous frame's visibility. */
  bool GetLastFrameReused();

  ///@{
  /**
   * Shadows cast by what this process does not hold (a distributed render; see
   * vtkPenumbraRemoteShadows): when set, every Render() calls its Resolve() once, after the
   * techniques and before the answers are uploaded, and no frame is reused. Default nullptr.
   */
  void SetRemoteShadows(vtkPenumbraRemoteShadows* remote);
  vtkPenumbraRemoteShadows* GetRemoteShadows();
  ///@}

  /**
   * True when the last Render(), or a read-back since (GetVisibility(), GetViewSamples()),
   * rendered the view samples (G-buffer). A new view's samples are rendered only when first
   * asked for: a frame
   * whose lights are all looked up in the receivers' shaders with maps that do not depend on
   * the view (shadowmap's fit "scene") renders none. They are kept while the view is
   * unchanged (camera, window size, geometry, flags, props), so a frame in which only lights
   * or the technique changed computes the visibility on the same samples without rendering
   * or reading them again.
   */
  bool GetLastFrameRenderedSamples();

  ///@{
  /**
   * Times of the last frame's phases, in milliseconds (after glFinish where GPU work is
   * involved): scene extraction, view samples, technique (all lights), shaded render.
   */
  double GetExtractionTimeMs();
  double GetSamplesTimeMs();
  double GetTechniqueTimeMs();
  double GetShadingTimeMs();
  ///@}

  void Render(const vtkRenderState* s) override;
  void ReleaseGraphicsResources(vtkWindow* w) override;

  bool PreReplaceShaderValues(std::string& vertexShader, std::string& geometryShader,
    std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop) override;
  bool PostReplaceShaderValues(std::string& vertexShader, std::string& geometryShader,
    std::string& fragmentShader, vtkAbstractMapper* mapper, vtkProp* prop) override;
  bool SetShaderParameters(vtkShaderProgram* program, vtkAbstractMapper* mapper, vtkProp* prop,
    vtkOpenGLVertexArrayObject* VAO = nullptr) override;
  vtkMTimeType GetShaderStageMTime() override;

protected:
  vtkPenumbraShadowPass();
  ~vtkPenumbraShadowPass() override;

  bool ReuseUnchangedFrames = true;

private:
  vtkPenumbraShadowPass(const vtkPenumbraShadowPass&) = delete;
  void operator=(const vtkPenumbraShadowPass&) = delete;

  void RenderShaded(const vtkRenderState* s, vtkOpenGLRenderWindow* win);

  struct Internals;
  std::unique_ptr<Internals> Impl;
#ifndef __VTK_WRAP__
  static FallbackFactory DefaultFallback;
#endif
};

#endif
