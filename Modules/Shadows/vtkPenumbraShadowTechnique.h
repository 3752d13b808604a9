/**
 * @class   vtkPenumbraShadowTechnique
 * @brief   What every shadow technique provides: per light, a visibility for each view sample.
 *
 * A technique answers one question per frame and light: how much of the light reaches each
 * view sample (0 or 1 for hard shadows, a fraction for area and linear lights). It does not
 * shade; vtkPenumbraShadowPass applies the answer to VTK's own Phong or PBR lighting, and
 * the benchmark compares the same answer against the exact reference on the same samples.
 *
 * Visibility convention, per sample: 1 fully lit, 0 fully shadowed (including samples facing
 * away from the light and samples outside a spot light's cone), values in between for soft
 * shadows, and -1 for samples without a surface (background).
 *
 * vtkPenumbraShadowPass calls ComputeFrame() once per frame. Its default reads the frame's
 * samples back to the CPU and calls ComputeVisibilities(); a technique that can answer on
 * the GPU overrides ComputeFrame() and writes into the frame's visibility textures instead,
 * so that nothing is read back (vtkPenumbraFrame).
 */

#ifndef vtkPenumbraShadowTechnique_h
#define vtkPenumbraShadowTechnique_h

#include "vtkObject.h"
#include "vtkPenumbraShadowsModule.h" // For export macro
#include "vtkSmartPointer.h"          // For FrameResults

#include <functional> // For ComputeFrameLights
#include <string>     // For SelectTechnique
#include <vector>     // For FrameResults

class vtkCollection;
class vtkFloatArray;
class vtkLight;
class vtkLightCollection;
class vtkPenumbraFrame;
class vtkPenumbraSceneGeometry;
class vtkPenumbraStatistics;
class vtkPenumbraViewSamples;
class vtkRenderer;
class vtkWindow;

class VTKPENUMBRASHADOWS_EXPORT vtkPenumbraShadowTechnique : public vtkObject
{
public:
  vtkTypeMacro(vtkPenumbraShadowTechnique, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Fills `visibility` (one value per sample, see the class description) for `light`.
   * Returns 1 on success, 0 on failure (with an error reported); the caller then renders
   * without shadows for that light rather than with wrong ones.
   */
  virtual int ComputeVisibility(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLight* light, vtkFloatArray* visibility) = 0;

  /**
   * The same for several lights of one frame: `visibilities` holds one vtkFloatArray per
   * light of `lights`, in the same order, and each is filled as ComputeVisibility would.
   * Returns the number of lights that succeeded; a failed light's array is left with 0
   * tuples. The default calls ComputeVisibility per light; techniques that share work
   * between lights override it (shadow volumes: four lights per RGBA mask, Brabec, "Shadow
   * Techniques for Interactive and Real-Time Applications", PhD thesis, 2003, ch. 8).
   * vtkPenumbraShadowPass calls this once per frame with every light that casts light.
   */
  virtual int ComputeVisibilities(vtkRenderer* renderer, vtkPenumbraSceneGeometry* geometry,
    vtkPenumbraViewSamples* samples, vtkLightCollection* lights, vtkCollection* visibilities);

  /**
   * Computes the visibility of every shadowed light of `frame` (vtkPenumbraFrame), and
   * returns how many lights got an answer. The default reads the samples back
   * (frame->GetSamples()), calls ComputeVisibilities() and hands the arrays to
   * frame->SetVisibility(); GPU techniques override it.
   */
  virtual int ComputeFrame(vtkPenumbraFrame* frame);

  /**
   * Frees the GL objects the technique holds for `window` (default: none). Called by
   * vtkPenumbraShadowPass::ReleaseGraphicsResources while the context can still be made
   * current.
   */
  virtual void ReleaseGraphicsResources(vtkWindow*) {}

  /**
   * Share of the last call's valid samples the technique could not decide by itself and
   * handed to an exact fallback (hybrid techniques: the uncertain samples that were ray
   * traced), in [0, 1]; -1 (the default) for techniques without such a split. Reported by
   * the benchmark.
   */
  virtual double GetUncertainFraction() { return -1.0; }

  /**
   * True when ComputeVisibility accepts vtkPenumbraAreaLight (soft shadows). Hard-shadow
   * techniques (the default) refuse area and linear lights with an error, and the pass then
   * renders such a light unshadowed; the benchmark skips them on area-light scenes.
   */
  virtual bool HandlesAreaLights() { return false; }

  /**
   * True when this technique can shadow `light`: every light, except area and linear lights
   * (vtkPenumbraAreaLight) for techniques that do not HandlesAreaLights().
   */
  virtual bool CanShadow(vtkLight* light);

  /**
   * The technique that shadows `light` this frame, with a short reason in `why` (for
   * vtkPenumbraShadowPass::GetExplanation()). Default: this technique when CanShadow(light),
   * else nullptr, and the pass then shadows the light with its soft fallback
   * (vtkPenumbraShadowPass::SetFallbackTechnique()) and says so once. A technique that
   * chooses per light (`auto`, vtkPenumbraAutoShadows) returns one of its members; the pass
   * hands each technique only the lights it was chosen for (vtkPenumbraFrame::SetActiveLights()).
   */
  virtual vtkPenumbraShadowTechnique* SelectTechnique(vtkLight* light, std::string& why);

  /**
   * True when ComputeFrame() reads the view samples back to the CPU (the default
   * ComputeFrame() does). The pass then also uses them to skip lights no visible sample
   * faces; GPU techniques return false and the pass reads nothing back for them.
   */
  virtual bool ReadsSamples() { return true; }

  /**
   * True when, in a distributed render, this technique combines every process's own casters
   * itself (through the collective operations of vtkPenumbraFrame::GetProcesses(): the
   * shadow-map family composites its maps by a minimum) instead of having its lit samples'
   * rays resolved by the other processes (vtkPenumbraRemoteShadows). The pass then gives its
   * lights shadow work on every process, whatever that process's samples.
   */
  virtual bool CompositesAcrossProcesses() { return false; }

  /**
   * The name this technique is registered under in vtkPenumbraTechniques ("raytraced",
   * "gears", ...), or the class name for a technique that is not registered.
   */
  virtual const char* GetTechniqueName();

  /**
   * The registry's name of what this technique does for `light`: GetTechniqueName(), except
   * for soft-shadow techniques, which shadow hard lights with the hard technique they are
   * built on (`pcss` a sun as `shadowmap`, `adaptive-soft` a point light as `raytraced`).
   * Explanations and the benchmark report lights under it.
   */
  virtual const char* GetTechniqueNameFor(vtkLight* light);

  /**
   * Wall-clock time of the last ComputeVisibility call, in milliseconds.
   */
  vtkGetMacro(LastTimeMs, double);

  /**
   * Appends this technique's counts and phase times of its last frame to `stats` (a name ->
   * value table, see vtkPenumbraStatistics for the naming). `light` is the light asked about,
   * for figures a technique keeps per light (a shadow map's size); the other figures describe
   * the last light the technique shadowed. The default sets "time_ms" (GetLastTimeMs()) and,
   * for techniques with an exact fallback, "uncertain_share" (GetUncertainFraction());
   * techniques call it first and add their own. vtkPenumbraShadowPass::GetLightStatistics()
   * collects it with the pass's phase times.
   */
  virtual void GetStatistics(vtkLight* light, vtkPenumbraStatistics* stats);

protected:
  vtkPenumbraShadowTechnique() = default;

  /**
   * ComputeFrame() of a technique that answers light by light on the GPU: calls
   * `light(k, error)` for every shadowed light k of `frame`, marks the lights that succeed
   * as answered on the GPU (vtkPenumbraFrame::MarkOnGPU()) and reports the others' errors
   * prefixed with `what`. Returns the number of lights answered.
   */
  int ComputeFrameLights(
    vtkPenumbraFrame* frame, const char* what, const std::function<bool(int, std::string&)>& light);

  ~vtkPenumbraShadowTechnique() override = default;

  double LastTimeMs = 0.0;

private:
  // ComputeFrame()'s per-light arrays, kept between frames (no per-frame allocation).
  std::vector<vtkSmartPointer<vtkFloatArray>> FrameResults;

  vtkPenumbraShadowTechnique(const vtkPenumbraShadowTechnique&) = delete;
  void operator=(const vtkPenumbraShadowTechnique&) = delete;
};

#endif
