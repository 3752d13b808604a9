/**
 * @file   vtkPenumbraCasterExchange.h
 * @brief  Shadow casters across MPI ranks: each rank gets the other ranks' triangles that can
 *         shadow its own receivers (need-based, the default), all of them (all-gather), or
 *         none (distributed: the rays travel instead, vtkPenumbraRayQueries).
 *
 * In a distributed render each rank draws its own piece, but a shadow on it may be cast by
 * another rank's piece. Before each render every rendering rank calls Update() (collective):
 *
 * 1. It extracts its own props' triangles (vtkPenumbraSceneGeometry, world coordinates,
 *    double precision, cached by MTime) and the lights that get shadow work
 *    (penumbra_reach::DescribeLights).
 * 2. One integer all-reduce: did any rank's casters, receivers or the lights change? If none
 *    did, nothing else is sent (a static frame costs 4 bytes a rank).
 * 3. Need and distributed modes: one all-gather of a fixed-size record per rank (whether it
 *    changed, the bounds of its casters and of all its triangles, up to MaxBoxes boxes
 *    around its receivers and as many around its casters: 896 bytes). In need mode rank r
 *    then sends peer q exactly the triangles of r that may block a shadow ray from q's
 *    receiver boxes to a light (penumbra_reach::Region: the box swept towards a directional
 *    light, its hull with a point light or an area light's extent), in pairwise rounds
 *    (penumbra::ForEachPeer). Only the pairs where r or q changed, or the lights did,
 *    exchange again; a peer's triangles are kept until then. With a budget, the counts are
 *    all-gathered first, and an exchange that would make some rank hold more than the budget
 *    becomes distributed on every rank. Distributed mode sends no triangle: the caster boxes
 *    route the rays of vtkPenumbraRayQueries.
 *    All mode: every rank's casters to every rank (AllGatherV).
 * 4. The triangles received are handed to the pass as one shadow-only prop
 *    (vtkPenumbraSceneGeometry::SetShadowOnlyProps): they cast, they are never drawn, they
 *    have no view samples. A triangle found on several ranks (replicated data, duplicated
 *    boundary cells) is kept once, a local copy first: otherwise the copy would shadow the
 *    very samples drawn on its twin.
 *
 * Exactness: a shadow ray of this rank's samples can only be blocked inside the union of its
 * regions, so the triangles left out block none of them, and every technique answers as over
 * all the casters (vtkPenumbraShadowReach.h has the argument and its margin).
 */

#ifndef vtkPenumbraCasterExchange_h
#define vtkPenumbraCasterExchange_h

#include "vtkNew.h"
#include "vtkPenumbraSceneGeometry.h" // For penumbra::CastersStamp
#include "vtkPenumbraShadowReach.h"   // For penumbra_reach::LightReach
#include "vtkType.h"

#include <array>
#include <string>
#include <vector>

class vtkActor;
class vtkDoubleArray;
class vtkMultiProcessController;
class vtkPolyData;
class vtkPropCollection;
class vtkRenderer;

namespace penumbra
{
class CasterExchange
{
public:
  enum Mode
  {
    Need = 0,       // the casters that can shadow a peer's receivers
    All = 1,        // every caster to every rank
    Distributed = 2 // no caster: each rank keeps its own (the others' rays are sent instead)
  };
  static constexpr int MaxBoxes = 8;

  /**
   * What this rank did in its last exchange (unchanged by frames that needed none).
   */
  struct Figures
  {
    int Exchanges = 0;               // exchanges done (the frames that changed something)
    int Peers = 0;                   // peers exchanged with in the last one
    vtkIdType OwnCasters = 0;        // this rank's caster triangles
    vtkIdType TrianglesSent = 0;     // sent to peers, summed over peers
    vtkIdType TrianglesReceived = 0; // received, before removing duplicates
    vtkIdType TrianglesHeld = 0;     // other ranks' triangles held for the pass
    vtkIdType BytesSent = 0;         // payload and counts
    vtkIdType BytesReceived = 0;
    double ExtractMs = 0.0;  // this rank's triangles and lights
    double BoundsMs = 0.0;   // the all-reduce and the all-gather of the records
    double SelectMs = 0.0;   // choosing the triangles for each peer
    double TransferMs = 0.0; // the sends and receives
    double RebuildMs = 0.0;  // the shadow-only prop, duplicates removed
    double TotalMs = 0.0;
  };

  CasterExchange();
  ~CasterExchange();

  /**
   * Collective over `controller` (every rank calls it with the same mode and budget).
   * `budget`: bytes a rank may hold of other ranks' casters in Need mode (0: no limit); an
   * exchange that would exceed it on some rank is made Distributed on every rank. Returns
   * false with `error` when the casters could not be exchanged (they are then left out); the
   * rank still takes part, so no rank waits for it.
   */
  bool Update(vtkMultiProcessController* controller, vtkRenderer* renderer, Mode mode,
    double budget, std::string& error);

  /**
   * What the last exchange did: `mode`, or Distributed when Need would have made some rank
   * hold more than `budget` bytes of other ranks' casters.
   */
  Mode GetEffectiveMode() const { return this->Effective; }

  /**
   * Need and Distributed: per rank, up to MaxBoxes boxes around its casters (as of the last
   * exchange; empty in All mode), where the rays of distributed queries are sent.
   */
  const std::vector<std::vector<std::array<double, 6>>>& GetCasterBoxes() const
  {
    return this->CasterBoxes;
  }

  /**
   * Whether the last Update() exchanged anything (false: no rank's casters, receivers or
   * lights changed).
   */
  bool GetExchangedLastUpdate() const { return this->ExchangedLast; }

  /**
   * The other ranks' triangles as one shadow-only prop, for the pass's geometry.
   */
  vtkPropCollection* GetShadowOnlyProps();

  const Figures& GetFigures() const { return this->Last; }

  /**
   * The bounds of every rank's triangles (need mode; uninitialized in all mode, where the
   * pass holds them all): for the pass's vtkPenumbraSceneGeometry::SetSceneBounds().
   */
  const double* GetSceneBounds() const { return this->SceneBounds; }

  /**
   * Every rank's figures of the last exchange, one line each, on rank 0 (collected at the end
   * of each exchange); empty elsewhere and before the first.
   */
  const std::string& GetReport() const { return this->Report; }

private:
  CasterExchange(const CasterExchange&) = delete;
  CasterExchange& operator=(const CasterExchange&) = delete;

  bool ExchangeAll(vtkMultiProcessController* controller, std::string& error);
  bool ExchangeNeeded(
    vtkMultiProcessController* controller, Mode mode, bool lightsChanged, bool mine, double budget);
  bool OverBudget(vtkMultiProcessController* controller,
    const std::vector<std::vector<double>>& outgoing, const std::vector<char>& exchange,
    double budget) const;
  std::vector<double> Select(const double* record, const double* casterBounds) const;
  void Transfer(vtkMultiProcessController* controller, const std::vector<char>& exchange,
    const std::vector<std::vector<double>>& outgoing);
  void BuildRemote();
  void Gather(vtkMultiProcessController* controller);

  vtkNew<vtkPenumbraSceneGeometry> Local;    // this rank's props only
  vtkNew<vtkDoubleArray> LocalCasters;       // their caster triangles, 9 coordinates each
  std::vector<std::vector<double>> Received; // per rank, the triangles it sent here
  int Me = 0;
  vtkNew<vtkPolyData> Remote;
  vtkNew<vtkActor> RemoteActor;
  vtkNew<vtkPropCollection> ShadowOnly;
  CastersStamp Sent;
  std::vector<penumbra_reach::LightReach> Lights;
  double SceneBounds[6];
  std::vector<std::vector<std::array<double, 6>>> CasterBoxes;
  int LastMode = -1;
  double LastBudget = 0.0;
  Mode Effective = Distributed; // nothing held yet
  bool ExchangedLast = false;
  Figures Last;
  std::string Report;
};
}

#endif
