/**
 * @class   vtkPenumbraFrame
 * @brief   One shadowed frame as the techniques see it: the scene geometry, the view samples
 *          kept on the GPU, a CPU view of them read back only on request, and the
 *          visibility textures the techniques write into.
 *
 * The GPU keeps what the GPU made. vtkPenumbraShadowPass renders the view samples
 * (G-buffer) of each sample layer (0 the opaque surfaces, 1 the nearest translucent surface
 * when translucent receivers are visible) into textures, and hands the frame to the
 * technique. A technique then either
 *
 *  - works on the GPU: it draws each light's visibility into that light's texture of the
 *    layer's visibility texture (BindVisibilityTarget()) and calls MarkOnGPU(); nothing is
 *    read back; or
 *  - works on the CPU: it asks for GetSamples() (the layers read back and stacked, opaque
 *    rows first, at the first call of the frame only) and hands its per-sample arrays to
 *    SetVisibility(); the pass uploads them.
 *
 * Visibility values follow vtkPenumbraShadowTechnique's convention (1 lit, 0 shadowed,
 * fractions for soft shadows, -1 for samples without a surface); the textures start each
 * frame at -1 and the lighting injection reads negative values as 1. GetVisibility() gives any
 * light's values as a CPU array, reading a GPU-written texture back on first request, so tests and
 * the benchmark compare every technique with the exact reference on the same samples.
 *
 * Lights are numbered as the pass numbers them (VTK's shader order of the switched-on
 * lights); each has one R32F visibility texture per layer. Only the lights listed by
 * GetNumberOfShadowedLights() get shadow work this frame.
 */

#ifndef vtkPenumbraFrame_h
#define vtkPenumbraFrame_h

#include "vtkObject.h"
#include "vtkPenumbraShadowsModule.h" // For export macro

#include <functional> // For Begin's sample renderer
#include <memory>     // For std::unique_ptr
#include <string>     // For ShaderLookup
#include <vector>     // For SetActiveLights

class vtkFloatArray;
class vtkLight;
class vtkOpenGLRenderWindow;
class vtkPenumbraRemoteShadows;
class vtkPenumbraSceneGeometry;
class vtkPenumbraViewSamples;
class vtkPenumbraViewSamplesPass;
class vtkRenderer;
class vtkShaderProgram;
class vtkTextureObject;
class vtkWindow;

class VTKPENUMBRASHADOWS_EXPORT vtkPenumbraFrame : public vtkObject
{
public:
  static vtkPenumbraFrame* New();
  vtkTypeMacro(vtkPenumbraFrame, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkRenderer* GetRenderer();
  vtkOpenGLRenderWindow* GetWindow();
  vtkPenumbraSceneGeometry* GetGeometry();

  /**
   * In a distributed render whose every process computes this frame, the processes'
   * collective operations (vtkPenumbraRemoteShadows) for the techniques that
   * CompositesAcrossProcesses(); null otherwise (a single process, or a frame some process
   * does not compute: each then shadows with what it holds). Set by vtkPenumbraShadowPass.
   */
  vtkPenumbraRemoteShadows* GetProcesses();
  void SetProcesses(vtkPenumbraRemoteShadows* processes);

  /** Viewport size in pixels: every layer has Width x Height samples. */
  int GetWidth();
  int GetHeight();

  /** 1 (opaque surfaces) or 2 (and the nearest translucent surface per pixel). */
  int GetNumberOfLayers();

  /**
   * The G-buffer of `layer`: its position, normal and primitive textures (see
   * vtkPenumbraViewSamplesPass). nullptr for a layer that does not exist.
   */
  vtkPenumbraViewSamplesPass* GetLayer(int layer);

  /**
   * The CPU view of every layer, stacked (opaque rows, then translucent rows; height =
   * layers x Height). Read back at the first call of a frame; later calls return the same
   * samples.
   */
  vtkPenumbraViewSamples* GetSamples();

  /**
   * Changes whenever the layers hold newly rendered view samples (a new view); equal values
   * mean the same samples, so per-view summaries a technique derives from them stay valid.
   */
  vtkMTimeType GetSamplesTime();

  /** True once this frame's samples are on the CPU (read back this frame or an earlier one
   * with the same view). */
  bool GetSamplesReadBack();

  ///@{
  /**
   * The lights that get shadow work this frame (switched on, not black), and for each its
   * number in the pass (see the class description).
   */
  int GetNumberOfShadowedLights();
  vtkLight* GetShadowedLight(int k);
  int GetLightIndex(int k);
  ///@}

  ///@{
  /**
   * Restricts what a technique sees of the frame to some of its shadowed lights: while set,
   * GetNumberOfShadowedLights() is `ks.size()` and shadowed light k of every call above and
   * below is the frame's shadowed light `ks[k]`. vtkPenumbraShadowPass uses it to hand each
   * technique only the lights it shadows this frame (different lights of one frame may use
   * different techniques); each light keeps its own visibility textures, so the techniques
   * never see each other's lights. Begin() and ClearActiveLights() show every light again.
   */
#ifndef __VTK_WRAP__
  void SetActiveLights(const std::vector<int>& ks);
#endif
  void ClearActiveLights();
  ///@}

  /**
   * A CPU technique's answer for shadowed light `k`: one value per stacked sample (see
   * GetSamples()). The frame keeps the array (until the next frame) and uploads it.
   */
  void SetVisibility(int k, vtkFloatArray* visibility);

  /**
   * A GPU technique's answer for shadowed light `k`: its visibility texture of every layer
   * was written through BindVisibilityTarget().
   */
  void MarkOnGPU(int k);

  /**
   * True when shadowed light `k` got an answer (SetVisibility(), MarkOnGPU() or
   * SetShaderLookup()).
   */
  bool HasVisibility(int k);

#ifndef __VTK_WRAP__
  /**
   * An answer the receivers' own fragment shaders compute while they are shaded, the way
   * VTK's vtkShadowMapPass looks its maps up: no full-screen pass writes a visibility
   * texture, so the shadowed frame costs about one depth map more than the unshadowed one.
   * vtkPenumbraShadowPass injects GetSource() into each receiver's fragment shader and calls
   * Activate(), SetUniforms() and Deactivate() around the draw. Resolve() writes the same
   * values into the light's visibility textures from the G-buffer, and runs only when they
   * are asked for (GetVisibility(), GetVisibilityTexture(): the benchmark and the tests), so
   * what is measured is what is shown.
   */
  class VTKPENUMBRASHADOWS_EXPORT ShaderLookup
  {
  public:
    virtual ~ShaderLookup();
    /**
     * What the source depends on: equal keys give equal sources, so the pass rebuilds the
     * receivers' shaders only when a key changes.
     */
    virtual std::string GetKey() = 0;
    /**
     * GLSL declarations defining `float penumbraReceive<suffix>(vec3 p, vec3 n)`: the light's
     * visibility at the fragment whose surface is p, n (the rebased position and facet
     * normal that vtkPenumbraViewSamplesPass::GetSurfaceDeclarations()'s `penumbraSurface`
     * gives; the pass computes them once for every light). Every global name in it ends with
     * `suffix`.
     */
    virtual std::string GetSource(const std::string& suffix) = 0;
    /** Sets its uniforms on a receiver's program (textures already active). */
    virtual void SetUniforms(vtkShaderProgram* program, const std::string& suffix) = 0;
    virtual void Activate() = 0;
    virtual void Deactivate() = 0;
    /**
     * Writes the frame's shadowed light 0 (the frame shows this light alone while it runs)
     * through BindVisibilityTarget(); false (with `error`) when it cannot.
     */
    virtual bool Resolve(vtkPenumbraFrame* frame, std::string& error) = 0;
  };

  /** Shadowed light `k`'s answer is `lookup`, evaluated while shading (see ShaderLookup). */
  void SetShaderLookup(int k, std::shared_ptr<ShaderLookup> lookup);

  /** Pass light `index`'s shader lookup, or nullptr when it has none this frame. */
  ShaderLookup* GetShaderLookup(int index);
#endif

  /**
   * Binds shadowed light `k`'s visibility texture of `layer` as the colour target of the
   * current framebuffer state, with the viewport set to the layer, and the layer's G-buffer
   * depth as a
   * read-only depth test (GREATER) so that a full-viewport quad drawn at depth 1 (see
   * GetSurfaceQuadVS()) runs its fragment program only where a surface was seen: the
   * background keeps -1 (on llvmpipe every fragment costs, and the sky is often half the
   * frame). Everything is restored when the returned object is destroyed.
   */
#ifndef __VTK_WRAP__
  class VTKPENUMBRASHADOWS_EXPORT VisibilityTarget
  {
  public:
    ~VisibilityTarget();
    VisibilityTarget(VisibilityTarget&&) noexcept;
    VisibilityTarget(const VisibilityTarget&) = delete;
    VisibilityTarget& operator=(const VisibilityTarget&) = delete;

  private:
    friend class vtkPenumbraFrame;
    struct State;
    explicit VisibilityTarget(State* state);
    std::unique_ptr<State> Saved;
  };
  VisibilityTarget BindVisibilityTarget(int layer, int k);
#endif

  /**
   * A vertex program for vtkOpenGLQuadHelper that draws the full-viewport quad at depth 1,
   * for use with BindVisibilityTarget().
   */
  static const char* GetSurfaceQuadVS();

  /**
   * The visibility of pass light `index` on `layer`'s samples, on the CPU (a GPU-written
   * texture is read back at the first request of the frame), or nullptr when that light got
   * no shadow work. The geometric visibility: a goniometric light's diagram is not in it.
   */
  vtkFloatArray* GetVisibility(int layer, int index);

  /**
   * What light `index`'s colour is scaled by on `layer`: the visibility, times a
   * goniometric light's relative intensity; nullptr when unshadowed.
   */
  vtkFloatArray* GetLightFactor(int layer, int index);

  /**
   * Light `index`'s R32F visibility texture of `layer`, for the lighting injection; nullptr
   * when that light got no shadow work.
   */
  vtkTextureObject* GetVisibilityTexture(int layer, int index);

  ///@{
  /**
   * Used by vtkPenumbraShadowPass: Begin() starts a frame (layer passes, lights, size; the
   * visibility textures are sized; `newSamples` false when the layers still hold the last
   * frame's samples, whose CPU view then stays valid), Finish() applies
   * goniometric diagrams and uploads the CPU answers. Release() frees the GL objects.
   * With a `renderSamples` function, new samples are rendered on demand: by it, on the
   * first request of the layers or the samples (GetLayer(), GetSamples(), a visibility
   * target or a read-back of a shader lookup), so a frame nothing asks them of renders none.
   * EnsureSamples() makes that request.
   */
  void Begin(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamplesPass* opaque, vtkPenumbraViewSamplesPass* translucent, int numberOfLights,
    bool newSamples, std::function<void()> renderSamples = nullptr);
  void EnsureSamples();
  /** Drops the on-demand rendering of Begin() (its pass is going away). */
  void ForgetPendingSamples();
  void AddShadowedLight(vtkLight* light, int index);
  void Finish();
  void Release(vtkWindow* window);
  ///@}

  /** Milliseconds spent reading samples or visibility back, and uploading, this frame. */
  vtkGetMacro(TransferTimeMs, double);

protected:
  vtkPenumbraFrame();
  ~vtkPenumbraFrame() override;

  double TransferTimeMs = 0.0;

private:
  vtkPenumbraFrame(const vtkPenumbraFrame&) = delete;
  void operator=(const vtkPenumbraFrame&) = delete;

  void Resolve(int index);

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
