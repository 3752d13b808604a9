/**
 * @class   vtkPenumbraRemoteShadows
 * @brief   Shadows cast by geometry this process does not hold: the hook through which a
 *          distributed render asks the other processes about the view samples' shadow rays.
 *
 * In a distributed render (MPI ranks, each holding only its own piece of the data), a rank's
 * technique decides its samples against the casters it holds. A sample it finds shadowed is
 * shadowed; one it finds lit may still be shadowed by another rank's piece. When a
 * vtkPenumbraRemoteShadows is set (vtkPenumbraShadowPass::SetRemoteShadows()), the pass calls
 * Resolve() exactly once in every frame it renders, after the techniques answered and before
 * the answers are uploaded, on every rank, whatever the rank has to shadow (a rank without
 * visible receivers passes no samples but still answers the others). The implementation
 * sends the lit samples' rays to the processes whose casters they may cross, answers theirs
 * with its own casters, and turns the samples that any of them blocks to shadowed.
 *
 * While a hook is set, the pass does not rule out shadow work because of the casters it holds
 * (a process whose own props cast nothing, or whose samples' rays miss them, still computes
 * its frame), only because of its samples (none visible, all facing away, outside a cone).
 * Only hard lights (directional, point, spot: not vtkPenumbraAreaLight, whose answers are
 * fractions) are resolved. A frame is reused (and Resolve() skipped) only when AgreeToReuse()
 * says so, on every process at once.
 *
 * Techniques that combine their own per-process work instead of asking rays (the shadow-map
 * family, vtkPenumbraShadowTechnique::CompositesAcrossProcesses(): maps fitted to the whole
 * scene's receivers, each process drawing its own casters, combined by a minimum) use the
 * collective operations below through vtkPenumbraFrame::GetProcesses(). The pass hands the
 * hook to a frame only when every process computes that frame, and it neither skips such a
 * technique's lights because of its own samples nor resolves them by rays, so every process
 * makes the same calls in the same order. The defaults are those of a single process.
 */

#ifndef vtkPenumbraRemoteShadows_h
#define vtkPenumbraRemoteShadows_h

#include "vtkObject.h"
#include "vtkPenumbraShadowsModule.h" // For export macro

#include <string> // For Resolve's error
#include <vector> // For Resolve's arguments

class vtkFloatArray;
class vtkLight;
class vtkPenumbraSceneGeometry;
class vtkPenumbraViewSamples;

class VTKPENUMBRASHADOWS_EXPORT vtkPenumbraRemoteShadows : public vtkObject
{
public:
  vtkTypeMacro(vtkPenumbraRemoteShadows, vtkObject);

#ifndef __VTK_WRAP__
  /**
   * `lights`: the pass's switched-on lights as it shadows them, in its order (the same on
   * every process). `visibilities[i]`: this process's answer for light i, one value per
   * sample of `samples` (stacked layers), or nullptr when the light got no shadow work here;
   * `samples` is nullptr when nothing was shadowed. `geometry`: the casters this process
   * holds. Lowers to 0 the values of the samples whose shadow ray another process's casters
   * block; false (with `error`) when that could not be decided (the values are then left as
   * they were).
   */
  virtual bool Resolve(vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples,
    const std::vector<vtkLight*>& lights, const std::vector<vtkFloatArray*>& visibilities,
    std::string& error) = 0;
#endif

  /**
   * Called by the pass once in every frame, on every process, before any shadow work:
   * `mine` is whether this process could reuse its last frame (nothing it depends on changed,
   * or it has nothing to shadow). Returns true only when every process can and no process's
   * casters changed since the last frame; the pass then reuses its frame and does not call
   * Resolve(). Collective.
   */
  virtual bool AgreeToReuse(bool mine) = 0;

  ///@{
  /**
   * Collective operations, called in the same order on every process. AllAgree(): true when
   * `mine` is true on every process. ReduceMinimum(): each value becomes its minimum over the
   * processes (a maximum is the minimum of the negated values). GatherValues(): every
   * process's values, concatenated in process order. The defaults are a single process's.
   */
  virtual bool AllAgree(bool mine)
  {
    return mine;
  }
  virtual void ReduceMinimum(double* /*values*/, int /*count*/) {}
#ifndef __VTK_WRAP__
  virtual void ReduceMinimum(float* /*values*/, size_t /*count*/) {}
  virtual void GatherValues(std::vector<double>& /*values*/) {}
#endif
  /** True when some process's `mine` is true (AllAgree() of the negation). Collective. */
  bool AnyProcess(bool mine)
  {
    return !this->AllAgree(!mine);
  }
  ///@}

protected:
  vtkPenumbraRemoteShadows() = default;
  ~vtkPenumbraRemoteShadows() override = default;

private:
  vtkPenumbraRemoteShadows(const vtkPenumbraRemoteShadows&) = delete;
  void operator=(const vtkPenumbraRemoteShadows&) = delete;
};

#endif
