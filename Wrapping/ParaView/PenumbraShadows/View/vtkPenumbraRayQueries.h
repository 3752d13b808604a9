/**
 * @class   vtkPenumbraRayQueries
 * @brief   Distributed exact shadows: the shadow rays a rank's own casters leave lit are sent
 *          to the ranks whose casters they may cross, and come back as one bit each.
 *
 * The vtkPenumbraRemoteShadows of the ParaView view's `distributed` caster exchange, where
 * each rank holds only its own casters. Every frame, collectively over the global controller:
 *
 * 1. Route: for each hard light and each sample this rank's technique found lit, the shadow
 *    ray (to a point or spot light's position, or along a directional light to infinity) is
 *    tested against every other rank's caster boxes (penumbra::CasterExchange::
 *    GetCasterBoxes(), a few per rank); it goes to each rank whose boxes it meets, as the
 *    light's number and the sample's rebased float position and normal (28 bytes).
 * 2. Queries are exchanged in pairwise rounds (penumbra::ForEachPeer).
 * 3. Each rank traces the rays it received against its own casters with the exact tracer
 *    (vtkPenumbraReference, on the pass's geometry, which holds them; the samples keep the
 *    sender's origin, so the rays are bit for bit the sender's), one batch per light.
 * 4. The answers go back as one bit per ray; a sample any rank blocks becomes shadowed.
 *
 * The tracer's rules (own-triangle exclusion, epsilons relative to the whole scene's bounds,
 * ties that do not block) are the single-process ones, so the combined answer equals the
 * tracer's over every rank's casters. Area and linear lights are not resolved (their answers
 * are fractions): under this mode they are shadowed by each rank's own casters only.
 */

#ifndef vtkPenumbraRayQueries_h
#define vtkPenumbraRayQueries_h

#include "vtkNew.h"
#include "vtkPenumbraRemoteShadows.h"

#include <array>
#include <vector>

class vtkMultiProcessController;
class vtkPenumbraReference;

class vtkPenumbraRayQueries : public vtkPenumbraRemoteShadows
{
public:
  static vtkPenumbraRayQueries* New();
  vtkTypeMacro(vtkPenumbraRayQueries, vtkPenumbraRemoteShadows);

  /** The ranks' caster boxes (see the class description); rank r's at index r. */
  void SetCasterBoxes(vtkMultiProcessController* controller,
    const std::vector<std::vector<std::array<double, 6>>>& boxes);

  bool Resolve(vtkPenumbraSceneGeometry* geometry, vtkPenumbraViewSamples* samples,
    const std::vector<vtkLight*>& lights, const std::vector<vtkFloatArray*>& visibilities,
    std::string& error) override;

  /**
   * Whether some rank's casters, receivers or lights changed this frame (the caster
   * exchange's all-reduce, the same on every rank): such a frame is never reused.
   */
  void SetCastersChanged(bool changed) { this->CastersChanged = changed; }

  /**
   * A MIN all-reduce of `mine`, false when SetCastersChanged(true). Starts the frame's
   * figures.
   */
  bool AgreeToReuse(bool mine) override;

  ///@{
  /**
   * The collective operations of the techniques that composite across ranks (the shadow
   * maps): all-reduces and an all-gather over the controller's ranks, counted in the
   * figures.
   */
  bool AllAgree(bool mine) override;
  void ReduceMinimum(double* values, int count) override;
  void ReduceMinimum(float* values, size_t count) override;
  void GatherValues(std::vector<double>& values) override;
  ///@}

  /** This rank's figures of the last frame. */
  struct Figures
  {
    long long RaysSent = 0;     // summed over the ranks they went to
    long long RaysAnswered = 0; // the other ranks' rays traced here
    long long RaysBlocked = 0;  // this rank's samples another rank shadowed
    long long BytesSent = 0;
    long long BytesReceived = 0;
    long long Reductions = 0;   // composited maps' and fits' collective operations
    long long ReducedBytes = 0; // the bytes this rank put into them
    double RouteMs = 0.0, QueryMs = 0.0, TraceMs = 0.0, AnswerMs = 0.0, ReduceMs = 0.0;
  };
  const Figures& GetFigures() const { return this->Last; }

  /** Every rank's figures of the last frame, a line each, on rank 0. */
  const std::string& GetReport() const { return this->Report; }

protected:
  vtkPenumbraRayQueries();
  ~vtkPenumbraRayQueries() override;

private:
  vtkPenumbraRayQueries(const vtkPenumbraRayQueries&) = delete;
  void operator=(const vtkPenumbraRayQueries&) = delete;

  // Per rank, this rank's rays for it (RayFloats each), and which light and sample each is
  // (light * samples + sample).
  std::vector<std::vector<float>> Route(vtkPenumbraViewSamples* samples,
    const std::vector<vtkLight*>& lights, const std::vector<vtkFloatArray*>& visibilities,
    std::vector<std::vector<vtkIdType>>& which);
  std::vector<unsigned char> Trace(vtkPenumbraSceneGeometry* geometry,
    const std::vector<float>& rays, const double origin[3], const std::vector<vtkLight*>& lights,
    std::string& error);
  void Gather();

  // The controller when there are other ranks, else null (the single-process defaults).
  vtkMultiProcessController* Peers() const;

  vtkMultiProcessController* Controller = nullptr;
  bool CastersChanged = true;
  std::vector<std::vector<std::array<double, 6>>> Boxes;
  vtkNew<vtkPenumbraReference> Tracer;
  Figures Last;
  std::string Report;
};

#endif
