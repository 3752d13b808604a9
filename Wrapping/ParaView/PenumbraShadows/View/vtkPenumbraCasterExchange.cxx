#include "vtkPenumbraCasterExchange.h"

#include "vtkActor.h"
#include "vtkCellArray.h"
#include "vtkCommunicator.h"
#include "vtkDoubleArray.h"
#include "vtkIdTypeArray.h"
#include "vtkMath.h"
#include "vtkMultiProcessController.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraRankMessages.h"
#include "vtkPenumbraShadowKeys.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkPropCollection.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <sstream>

namespace penumbra
{
namespace
{
constexpr int Tag = 78311; // the exchange's point-to-point messages

// A rank's record: [its casters or receivers changed, its lights changed, number of receiver
// boxes, number of caster boxes, bounds of its casters (6), bounds of all its triangles (6),
// MaxBoxes boxes around its receivers, MaxBoxes around its casters (6 each)].
constexpr int ReceiversAt = 16;
constexpr int CastersAt = ReceiversAt + 6 * CasterExchange::MaxBoxes;
constexpr int RecordSize = CastersAt + 6 * CasterExchange::MaxBoxes;

// What the pass holds per triangle received: the received copy (72 bytes), the shadow-only
// prop (104, measured, docs/paraview.md) and the pass's geometry, which stores the prop's
// unshared corners as they come (72 bytes of points, 12 of indices, 36 of float32 copy and a
// role: 121; 157 before the geometry kept one indexed copy).
constexpr double BytesPerHeldTriangle = 297.0;

// Grows `b` (uninitialized: empty) to `other` (uninitialized: nothing).
void Grow(double b[6], const double other[6])
{
  if (!vtkMath::AreBoundsInitialized(other))
  {
    return;
  }
  const bool first = !vtkMath::AreBoundsInitialized(b);
  for (int c = 0; c < 3; ++c)
  {
    b[2 * c] = first ? other[2 * c] : std::min(b[2 * c], other[2 * c]);
    b[2 * c + 1] = first ? other[2 * c + 1] : std::max(b[2 * c + 1], other[2 * c + 1]);
  }
}

// A triangle's 9 world coordinates, hashed bit for bit (splitmix64 per coordinate).
std::uint64_t HashTriangle(const double* t)
{
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (int k = 0; k < 9; ++k)
  {
    std::uint64_t z;
    std::memcpy(&z, t + k, sizeof z);
    z = (z ^ h) + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    h = z ^ (z >> 31);
  }
  return h;
}

// Bounds of `count` triangles (9 coordinates each); uninitialized when there are none.
void TriangleBounds(const double* xyz, vtkIdType count, double b[6])
{
  vtkMath::UninitializeBounds(b);
  for (vtkIdType i = 0; i < 3 * count; ++i)
  {
    const double* p = xyz + 3 * i;
    for (int c = 0; c < 3; ++c)
    {
      b[2 * c] = i == 0 ? p[c] : std::min(b[2 * c], p[c]);
      b[2 * c + 1] = i == 0 ? p[c] : std::max(b[2 * c + 1], p[c]);
    }
  }
}
}

CasterExchange::CasterExchange()
{
  vtkMath::UninitializeBounds(this->SceneBounds);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(this->Remote);
  this->RemoteActor->SetMapper(mapper);
  // Drawn by the rank that owns them; here they only cast.
  vtkPenumbraShadowKeys::SetReceivesShadows(this->RemoteActor, false);
  vtkPenumbraSceneGeometry::SetPropName(this->RemoteActor, "other ranks' casters");
  this->ShadowOnly->AddItem(this->RemoteActor);
}

CasterExchange::~CasterExchange() = default;

vtkPropCollection* CasterExchange::GetShadowOnlyProps()
{
  return this->ShadowOnly;
}

bool CasterExchange::Update(vtkMultiProcessController* controller, vtkRenderer* renderer, Mode mode,
  double budget, std::string& error)
{
  const auto start = Clock::now();
  const int ranks = controller->GetNumberOfProcesses();
  this->Me = controller->GetLocalProcessId();
  this->Received.resize(static_cast<size_t>(ranks));
  // A rank whose extraction fails (NaN coordinates: reported by the geometry) sends nothing
  // but still takes part.
  const bool extracted = this->Local->Update(renderer) != 0;
  std::vector<penumbra_reach::LightReach> lights = penumbra_reach::DescribeLights(renderer);
  const bool lightsChanged = lights != this->Lights;
  const bool mine =
    this->Sent.Changed(this->Local) || mode != this->LastMode || budget != this->LastBudget;
  const double extractMs = ElapsedMs(start);
  const auto reduce = Clock::now();
  int changed = (mine || lightsChanged) ? 1 : 0, anyChanged = 0;
  controller->AllReduce(&changed, &anyChanged, 1, vtkCommunicator::MAX_OP);
  this->ExchangedLast = anyChanged != 0;
  if (!anyChanged)
  {
    return true;
  }
  this->Last.ExtractMs = extractMs;
  this->Last.BoundsMs = ElapsedMs(reduce);
  if (extracted)
  {
    this->Local->GetCasterWorldTriangles(this->LocalCasters);
  }
  else
  {
    this->LocalCasters->SetNumberOfComponents(9);
    this->LocalCasters->SetNumberOfTuples(0);
  }
  this->Lights = std::move(lights);
  this->Last.OwnCasters = this->LocalCasters->GetNumberOfTuples();
  this->Last.TrianglesSent = this->Last.TrianglesReceived = 0;
  this->Last.BytesSent = this->Last.BytesReceived = 0;
  this->Last.SelectMs = this->Last.TransferMs = this->Last.RebuildMs = 0.0;
  bool ok = true;
  if (mode == All)
  {
    this->Effective = All;
    this->CasterBoxes.clear();
    ok = this->ExchangeAll(controller, error);
  }
  else
  {
    ok = this->ExchangeNeeded(controller, mode, lightsChanged, mine, budget);
  }
  const auto rebuild = Clock::now();
  this->BuildRemote();
  if (this->Effective == All)
  {
    // Every frame that changes anything sends everything again: nothing to keep.
    this->Received.assign(this->Received.size(), std::vector<double>());
  }
  this->Last.RebuildMs = ElapsedMs(rebuild);
  this->Sent.Remember(this->Local);
  this->LastMode = mode;
  this->LastBudget = budget;
  ++this->Last.Exchanges;
  this->Last.TotalMs = ElapsedMs(start);
  this->Gather(controller);
  return ok;
}

bool CasterExchange::ExchangeAll(vtkMultiProcessController* controller, std::string& error)
{
  const auto start = Clock::now();
  vtkMath::UninitializeBounds(this->SceneBounds); // every rank holds every triangle
  const int ranks = controller->GetNumberOfProcesses();
  const vtkIdType length = 9 * this->LocalCasters->GetNumberOfTuples();
  std::vector<vtkIdType> lengths(static_cast<size_t>(ranks), 0), offsets(lengths);
  controller->AllGather(&length, lengths.data(), 1);
  vtkIdType total = 0;
  for (int r = 0; r < ranks; ++r)
  {
    offsets[r] = total;
    total += lengths[r];
  }
  for (auto& received : this->Received)
  {
    received.clear();
  }
  // MPI counts and displacements are ints.
  if (total > INT_MAX)
  {
    error = "the casters of all ranks exceed one MPI message (2^31 coordinates); shadows "
            "from other ranks are left out (the need-based exchange sends only what shadows)";
    return false;
  }
  std::vector<double> all(static_cast<size_t>(total));
  if (total > 0)
  {
    controller->AllGatherV(
      this->LocalCasters->GetPointer(0), all.data(), length, lengths.data(), offsets.data());
  }
  for (int r = 0; r < ranks; ++r)
  {
    if (r != this->Me)
    {
      this->Received[r].assign(all.begin() + offsets[r], all.begin() + offsets[r] + lengths[r]);
      this->Last.TrianglesReceived += lengths[r] / 9;
    }
  }
  this->Last.Peers = ranks - 1;
  this->Last.TrianglesSent = (ranks - 1) * (length / 9);
  this->Last.BytesSent = static_cast<vtkIdType>(sizeof(double)) * (ranks - 1) * length;
  this->Last.BytesReceived = static_cast<vtkIdType>(sizeof(double)) * (total - length);
  this->Last.TransferMs = ElapsedMs(start);
  return true;
}

bool CasterExchange::ExchangeNeeded(
  vtkMultiProcessController* controller, Mode mode, bool lightsChanged, bool mine, double budget)
{
  const auto start = Clock::now();
  const int ranks = controller->GetNumberOfProcesses();
  std::vector<double> record(RecordSize, 0.0), records(static_cast<size_t>(RecordSize) * ranks);
  record[0] = mine ? 1.0 : 0.0;
  record[1] = lightsChanged ? 1.0 : 0.0;
  const auto receivers = penumbra_reach::TriangleBoxes(
    this->Local, vtkPenumbraSceneGeometry::RECEIVES_SHADOWS, MaxBoxes);
  const auto casters =
    penumbra_reach::TriangleBoxes(this->Local, vtkPenumbraSceneGeometry::CASTS_SHADOWS, MaxBoxes);
  record[2] = static_cast<double>(receivers.size());
  record[3] = static_cast<double>(casters.size());
  TriangleBounds(
    this->LocalCasters->GetPointer(0), this->LocalCasters->GetNumberOfTuples(), record.data() + 4);
  this->Local->GetBounds(record.data() + 10);
  for (size_t b = 0; b < receivers.size(); ++b)
  {
    std::copy(receivers[b].begin(), receivers[b].end(), record.begin() + ReceiversAt + 6 * b);
  }
  for (size_t b = 0; b < casters.size(); ++b)
  {
    std::copy(casters[b].begin(), casters[b].end(), record.begin() + CastersAt + 6 * b);
  }
  controller->AllGather(record.data(), records.data(), RecordSize);
  // The records count as traffic too: this rank's to every other, theirs to it.
  const vtkIdType recordBytes = static_cast<vtkIdType>(sizeof(double)) * RecordSize;
  this->Last.BytesSent += recordBytes * (ranks - 1);
  this->Last.BytesReceived += recordBytes * (ranks - 1);
  // The casters of every rank lie in `bounds` (they set a directional light's sweep); the
  // scene's bounds are those of every triangle (vtkPenumbraSceneGeometry::SetSceneBounds).
  double bounds[6];
  vtkMath::UninitializeBounds(bounds);
  vtkMath::UninitializeBounds(this->SceneBounds);
  this->CasterBoxes.assign(static_cast<size_t>(ranks), {});
  bool anyLights = false;
  for (int r = 0; r < ranks; ++r)
  {
    const double* rec = records.data() + static_cast<size_t>(RecordSize) * r;
    anyLights = anyLights || rec[1] != 0.0;
    Grow(bounds, rec + 4);
    Grow(this->SceneBounds, rec + 10);
    for (int b = 0; b < static_cast<int>(rec[3]); ++b)
    {
      std::array<double, 6> box;
      std::copy_n(rec + CastersAt + 6 * b, 6, box.begin());
      this->CasterBoxes[r].push_back(box);
    }
  }
  this->Last.BoundsMs += ElapsedMs(start);
  if (mode == Distributed)
  {
    this->Effective = Distributed;
    this->Received.assign(this->Received.size(), std::vector<double>());
    return true;
  }
  // A pair exchanges again when either side changed or the lights did (both sides decide
  // this from the same records), and every pair after a frame that held nothing.
  const bool all = this->Effective != Need;
  std::vector<std::vector<double>> outgoing(static_cast<size_t>(ranks));
  std::vector<char> exchange(static_cast<size_t>(ranks), 0);
  const auto select = Clock::now();
  for (int q = 0; q < ranks; ++q)
  {
    exchange[q] = q != this->Me &&
      (all || anyLights || mine || records[static_cast<size_t>(RecordSize) * q] != 0.0);
    if (exchange[q])
    {
      outgoing[q] = this->Select(records.data() + static_cast<size_t>(RecordSize) * q, bounds);
    }
  }
  this->Last.SelectMs = ElapsedMs(select);
  if (budget > 0.0 && this->OverBudget(controller, outgoing, exchange, budget))
  {
    this->Effective = Distributed;
    this->Received.assign(this->Received.size(), std::vector<double>());
    return true;
  }
  this->Effective = Need;
  this->Transfer(controller, exchange, outgoing);
  return true;
}

bool CasterExchange::OverBudget(vtkMultiProcessController* controller,
  const std::vector<std::vector<double>>& outgoing, const std::vector<char>& exchange,
  double budget) const
{
  // What each rank sends each (-1: nothing new, the receiver keeps what it holds).
  const int ranks = controller->GetNumberOfProcesses();
  std::vector<long long> counts(static_cast<size_t>(ranks), -1), all(counts.size() * ranks);
  for (int q = 0; q < ranks; ++q)
  {
    if (exchange[q])
    {
      counts[q] = static_cast<long long>(outgoing[q].size() / 9);
    }
  }
  controller->AllGather(counts.data(), all.data(), ranks);
  double held = 0.0;
  for (int r = 0; r < ranks; ++r)
  {
    const long long in = all[static_cast<size_t>(r) * ranks + this->Me];
    held +=
      static_cast<double>(in >= 0 ? in : static_cast<long long>(this->Received[r].size() / 9));
  }
  double most = 0.0;
  const double bytes = held * BytesPerHeldTriangle;
  controller->AllReduce(&bytes, &most, 1, vtkCommunicator::MAX_OP);
  return most > budget;
}

std::vector<double> CasterExchange::Select(const double* record, const double* casterBounds) const
{
  std::vector<double> out;
  const int boxes = static_cast<int>(record[2]);
  if (boxes == 0 || this->Lights.empty() || !vtkMath::AreBoundsInitialized(casterBounds))
  {
    return out;
  }
  std::vector<penumbra_reach::Region> regions;
  for (int b = 0; b < boxes; ++b)
  {
    for (const auto& light : this->Lights)
    {
      regions.emplace_back(record + ReceiversAt + 6 * b, light, casterBounds);
    }
  }
  std::vector<vtkIdType> selected;
  penumbra_reach::SelectTriangles(
    this->LocalCasters->GetPointer(0), this->LocalCasters->GetNumberOfTuples(), regions, selected);
  out.resize(9 * selected.size());
  const double* xyz = this->LocalCasters->GetPointer(0);
  for (size_t k = 0; k < selected.size(); ++k)
  {
    std::copy_n(xyz + 9 * selected[k], 9, out.data() + 9 * k);
  }
  return out;
}

void CasterExchange::Transfer(vtkMultiProcessController* controller,
  const std::vector<char>& exchange, const std::vector<std::vector<double>>& outgoing)
{
  const auto start = Clock::now();
  int peers = 0;
  ForEachPeer(
    controller, [&](int q) { return exchange[q] != 0; },
    [&](int q)
    {
      ++peers;
      const auto bytes = ExchangeVectors(controller, q, outgoing[q], this->Received[q], Tag);
      this->Last.TrianglesSent += static_cast<vtkIdType>(outgoing[q].size() / 9);
      this->Last.TrianglesReceived += static_cast<vtkIdType>(this->Received[q].size() / 9);
      this->Last.BytesSent += bytes.first;
      this->Last.BytesReceived += bytes.second;
    });
  this->Last.Peers = peers;
  this->Last.TransferMs = ElapsedMs(start);
}

void CasterExchange::BuildRemote()
{
  if (std::all_of(this->Received.begin(), this->Received.end(),
        [](const std::vector<double>& r) { return r.empty(); }))
  {
    // Distributed mode, or nothing needed: no triangle to sort against the local ones.
    this->Remote->Initialize();
    this->Last.TrianglesHeld = 0;
    return;
  }
  // Every rank's triangles in rank order, this rank's own among them.
  std::vector<const double*> blocks;
  std::vector<vtkIdType> counts;
  for (size_t r = 0; r < this->Received.size(); ++r)
  {
    const bool own = static_cast<int>(r) == this->Me;
    blocks.push_back(own ? this->LocalCasters->GetPointer(0) : this->Received[r].data());
    counts.push_back(own ? this->LocalCasters->GetNumberOfTuples()
                         : static_cast<vtkIdType>(this->Received[r].size() / 9));
  }
  struct Ref
  {
    std::uint64_t Hash;
    const double* T;
    bool Local;
    vtkIdType Order;
  };
  std::vector<Ref> order;
  vtkIdType n = 0;
  for (size_t r = 0; r < blocks.size(); ++r)
  {
    for (vtkIdType t = 0; t < counts[r]; ++t, ++n)
    {
      const double* tri = blocks[r] + 9 * t;
      order.push_back({ HashTriangle(tri), tri, static_cast<int>(r) == this->Me, n });
    }
  }
  // Each distinct triangle once: equal triangles end up next to each other, a local one
  // first; it drops the others, otherwise the first of them is kept.
  std::sort(order.begin(), order.end(),
    [](const Ref& a, const Ref& b)
    {
      if (a.Hash != b.Hash)
      {
        return a.Hash < b.Hash;
      }
      const int bytes = std::memcmp(a.T, b.T, 9 * sizeof(double));
      return bytes != 0 ? bytes < 0
                        : std::make_pair(!a.Local, a.Order) < std::make_pair(!b.Local, b.Order);
    });
  std::vector<const Ref*> kept;
  for (size_t i = 0; i < order.size(); ++i)
  {
    const bool first = i == 0 || order[i - 1].Hash != order[i].Hash ||
      std::memcmp(order[i - 1].T, order[i].T, 9 * sizeof(double)) != 0;
    if (first && !order[i].Local)
    {
      kept.push_back(&order[i]);
    }
  }
  // The ranks' order, as they extracted them.
  std::sort(
    kept.begin(), kept.end(), [](const Ref* a, const Ref* b) { return a->Order < b->Order; });

  const vtkIdType count = static_cast<vtkIdType>(kept.size());
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(3 * count);
  vtkNew<vtkIdTypeArray> connectivity, offsets;
  connectivity->SetNumberOfValues(3 * count);
  offsets->SetNumberOfValues(count + 1);
  double* xyz = coordinates->GetPointer(0);
  for (vtkIdType k = 0; k < count; ++k)
  {
    std::copy_n(kept[k]->T, 9, xyz + 9 * k);
    offsets->SetValue(k, 3 * k);
  }
  offsets->SetValue(count, 3 * count);
  for (vtkIdType i = 0; i < 3 * count; ++i)
  {
    connectivity->SetValue(i, i);
  }
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);
  this->Remote->Initialize();
  this->Remote->SetPoints(points);
  this->Remote->SetPolys(polys);
  this->Last.TrianglesHeld = count;
}

void CasterExchange::Gather(vtkMultiProcessController* controller)
{
  const Figures& f = this->Last;
  const std::vector<double> mine = { static_cast<double>(f.OwnCasters),
    static_cast<double>(f.TrianglesHeld), static_cast<double>(f.TrianglesSent),
    static_cast<double>(f.BytesSent), static_cast<double>(f.BytesReceived),
    static_cast<double>(f.Peers), f.ExtractMs, f.BoundsMs, f.SelectMs, f.TransferMs, f.RebuildMs,
    f.TotalMs };
  const char* names[] = { "need", "all", "distributed" };
  std::ostringstream header;
  header << "caster exchange " << f.Exchanges << " (" << names[this->Effective]
         << "), per rank: own casters, other ranks' triangles held, sent, bytes sent, bytes "
            "received, peers, extract/bounds/select/transfer/rebuild/total ms";
  this->Report = RankReport(controller, header.str(), mine, 6);
}
}
