#include "vtkPenumbraRayQueries.h"

#include "vtkCommunicator.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkPenumbraAreaLight.h"
#include "vtkPenumbraDiagnostics.h"
#include "vtkPenumbraRankMessages.h"
#include "vtkPenumbraReference.h"
#include "vtkPenumbraSceneGeometry.h"
#include "vtkPenumbraShadowReach.h"
#include "vtkPenumbraViewSamples.h"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace
{
constexpr int QueryTag = 78312, AnswerTag = 78313;
constexpr int RayFloats = 7; // light, position (3), normal (3)
}

vtkStandardNewMacro(vtkPenumbraRayQueries);

vtkPenumbraRayQueries::vtkPenumbraRayQueries() = default;
vtkPenumbraRayQueries::~vtkPenumbraRayQueries() = default;

void vtkPenumbraRayQueries::SetCasterBoxes(vtkMultiProcessController* controller,
  const std::vector<std::vector<std::array<double, 6>>>& boxes)
{
  this->Controller = controller;
  this->Boxes = boxes;
}

std::vector<std::vector<float>> vtkPenumbraRayQueries::Route(vtkPenumbraViewSamples* samples,
  const std::vector<vtkLight*>& lights, const std::vector<vtkFloatArray*>& visibilities,
  std::vector<std::vector<vtkIdType>>& which)
{
  const int ranks = this->Controller->GetNumberOfProcesses();
  const int me = this->Controller->GetLocalProcessId();
  std::vector<std::vector<float>> out(static_cast<size_t>(ranks));
  which.assign(static_cast<size_t>(ranks), {});
  if (!samples || !samples->CheckArrays().empty())
  {
    return out;
  }
  const float* positions = samples->GetPositions()->GetPointer(0);
  const float* normals = samples->GetNormals()->GetPointer(0);
  const vtkIdType n = samples->GetNumberOfSamples();
  for (size_t i = 0; i < lights.size(); ++i)
  {
    vtkFloatArray* v = visibilities[i];
    penumbra_reach::LightReach reach;
    std::string ignored;
    if (!v || v->GetNumberOfTuples() != n || vtkPenumbraAreaLight::SafeDownCast(lights[i]) ||
      !penumbra_reach::DescribeLight(lights[i], reach, ignored))
    {
      continue;
    }
    const float* values = v->GetPointer(0);
    for (vtkIdType s = 0; s < n; ++s)
    {
      double o[3];
      if (!(values[s] > 0.0f) || !samples->GetWorldPosition(s, o))
      {
        continue;
      }
      // The shadow ray: to the light's position, or along its direction to infinity.
      double d[3];
      double tmax = vtkMath::Inf();
      for (int c = 0; c < 3; ++c)
      {
        d[c] = reach.Directional ? reach.Direction[c] : reach.Points[c] - o[c];
      }
      if (!reach.Directional)
      {
        tmax = 1.0;
      }
      for (int r = 0; r < ranks; ++r)
      {
        if (r == me || static_cast<size_t>(r) >= this->Boxes.size())
        {
          continue;
        }
        const auto& boxes = this->Boxes[r];
        if (std::any_of(boxes.begin(), boxes.end(),
              [&](const std::array<double, 6>& b)
              { return penumbra_reach::SegmentMeetsBox(o, d, tmax, b.data()); }))
        {
          std::vector<float>& q = out[r];
          q.push_back(static_cast<float>(i));
          q.insert(q.end(), positions + 3 * s, positions + 3 * s + 3);
          q.insert(q.end(), normals + 3 * s, normals + 3 * s + 3);
          which[r].push_back(static_cast<vtkIdType>(i) * n + s);
        }
      }
    }
  }
  return out;
}

std::vector<unsigned char> vtkPenumbraRayQueries::Trace(vtkPenumbraSceneGeometry* geometry,
  const std::vector<float>& rays, const double origin[3], const std::vector<vtkLight*>& lights,
  std::string& error)
{
  const size_t count = rays.size() / RayFloats;
  std::vector<unsigned char> bits((count + 7) / 8, 0);
  if (count == 0)
  {
    return bits;
  }
  this->Tracer->SetGeometry(geometry);
  // One batch per light: the rays as samples keeping the sender's rebased floats.
  for (size_t i = 0; i < lights.size(); ++i)
  {
    std::vector<size_t> mine;
    for (size_t k = 0; k < count; ++k)
    {
      if (static_cast<size_t>(rays[RayFloats * k]) == i)
      {
        mine.push_back(k);
      }
    }
    if (mine.empty())
    {
      continue;
    }
    vtkNew<vtkPenumbraViewSamples> samples;
    samples->SetSize(static_cast<int>(mine.size()), 1);
    samples->SetOrigin(origin[0], origin[1], origin[2]);
    float* p = samples->GetPositions()->GetPointer(0);
    float* nrm = samples->GetNormals()->GetPointer(0);
    for (size_t j = 0; j < mine.size(); ++j)
    {
      const float* ray = rays.data() + RayFloats * mine[j];
      std::copy_n(ray + 1, 3, p + 3 * j);
      std::copy_n(ray + 4, 3, nrm + 3 * j);
      samples->GetPropIndices()->SetValue(static_cast<vtkIdType>(j), 0);
      // The sample's triangle is the sender's: none of these casters is its own.
      samples->GetTriangleIds()->SetValue(static_cast<vtkIdType>(j), -1);
    }
    vtkNew<vtkFloatArray> visibility;
    if (!this->Tracer->ComputeVisibility(samples, lights[i], visibility))
    {
      error = std::string("the exact tracer failed on other ranks' rays: ") +
        this->Tracer->GetErrorMessage();
      return bits;
    }
    for (size_t j = 0; j < mine.size(); ++j)
    {
      const float v = visibility->GetValue(static_cast<vtkIdType>(j));
      if (v >= 0.0f && v < 0.5f)
      {
        bits[mine[j] / 8] |= static_cast<unsigned char>(1u << (mine[j] % 8));
      }
    }
  }
  return bits;
}

bool vtkPenumbraRayQueries::AgreeToReuse(bool mine)
{
  if (!this->Controller)
  {
    return false;
  }
  int reuse = mine && !this->CastersChanged ? 1 : 0, all = 0;
  this->Controller->AllReduce(&reuse, &all, 1, vtkCommunicator::MIN_OP);
  // A new frame (a reused one sends nothing: its figures stay zero).
  this->Last = Figures();
  return all != 0;
}

vtkMultiProcessController* vtkPenumbraRayQueries::Peers() const
{
  return this->Controller && this->Controller->GetNumberOfProcesses() > 1 ? this->Controller
                                                                          : nullptr;
}

bool vtkPenumbraRayQueries::AllAgree(bool mine)
{
  vtkMultiProcessController* peers = this->Peers();
  if (!peers)
  {
    return mine;
  }
  int value = mine ? 1 : 0, all = 0;
  peers->AllReduce(&value, &all, 1, vtkCommunicator::MIN_OP);
  return all != 0;
}

void vtkPenumbraRayQueries::ReduceMinimum(double* values, int count)
{
  vtkMultiProcessController* peers = this->Peers();
  if (!peers || count <= 0)
  {
    return;
  }
  const auto start = penumbra::Clock::now();
  const std::vector<double> mine(values, values + count);
  peers->AllReduce(mine.data(), values, count, vtkCommunicator::MIN_OP);
  ++this->Last.Reductions;
  this->Last.ReducedBytes += static_cast<long long>(sizeof(double)) * count;
  this->Last.ReduceMs += penumbra::ElapsedMs(start);
}

void vtkPenumbraRayQueries::ReduceMinimum(float* values, size_t count)
{
  vtkMultiProcessController* peers = this->Peers();
  if (!peers || count == 0)
  {
    return;
  }
  const auto start = penumbra::Clock::now();
  const std::vector<float> mine(values, values + count);
  peers->AllReduce(mine.data(), values, static_cast<vtkIdType>(count), vtkCommunicator::MIN_OP);
  ++this->Last.Reductions;
  this->Last.ReducedBytes += static_cast<long long>(sizeof(float) * count);
  this->Last.ReduceMs += penumbra::ElapsedMs(start);
}

void vtkPenumbraRayQueries::GatherValues(std::vector<double>& values)
{
  vtkMultiProcessController* peers = this->Peers();
  if (!peers)
  {
    return;
  }
  const auto start = penumbra::Clock::now();
  const int ranks = peers->GetNumberOfProcesses();
  vtkIdType length = static_cast<vtkIdType>(values.size());
  std::vector<vtkIdType> lengths(static_cast<size_t>(ranks), 0), offsets(lengths);
  peers->AllGather(&length, lengths.data(), 1);
  vtkIdType total = 0;
  for (int r = 0; r < ranks; ++r)
  {
    offsets[static_cast<size_t>(r)] = total;
    total += lengths[static_cast<size_t>(r)];
  }
  std::vector<double> all(static_cast<size_t>(std::max<vtkIdType>(total, 1)));
  const double none = 0.0; // a send buffer apart from the receive one
  peers->AllGatherV(
    values.empty() ? &none : values.data(), all.data(), length, lengths.data(), offsets.data());
  all.resize(static_cast<size_t>(total));
  values.swap(all);
  ++this->Last.Reductions;
  this->Last.ReducedBytes += static_cast<long long>(sizeof(double)) * length;
  this->Last.ReduceMs += penumbra::ElapsedMs(start);
}

bool vtkPenumbraRayQueries::Resolve(vtkPenumbraSceneGeometry* geometry,
  vtkPenumbraViewSamples* samples, const std::vector<vtkLight*>& lights,
  const std::vector<vtkFloatArray*>& visibilities, std::string& error)
{
  if (!this->Controller)
  {
    error = "no controller";
    return false;
  }
  vtkMultiProcessController* controller = this->Controller;
  const int ranks = controller->GetNumberOfProcesses();
  auto start = penumbra::Clock::now();
  std::vector<std::vector<vtkIdType>> which;
  const std::vector<std::vector<float>> out = this->Route(samples, lights, visibilities, which);
  this->Last.RouteMs = penumbra::ElapsedMs(start);

  // The rays, with the origin their positions are rebased to, both ways.
  start = penumbra::Clock::now();
  double origin[3];
  if (samples)
  {
    samples->GetOrigin(origin);
  }
  else
  {
    geometry->GetOrigin(origin);
  }
  const std::vector<double> myOrigin(origin, origin + 3);
  std::vector<std::vector<float>> in(static_cast<size_t>(ranks));
  std::vector<std::vector<double>> origins(static_cast<size_t>(ranks));
  auto everyone = [](int) { return true; };
  penumbra::ForEachPeer(controller, everyone,
    [&](int q)
    {
      const auto bytes = penumbra::ExchangeVectors(controller, q, out[q], in[q], QueryTag);
      penumbra::ExchangeVectors(controller, q, myOrigin, origins[q], QueryTag);
      this->Last.RaysSent += static_cast<long long>(out[q].size() / RayFloats);
      this->Last.BytesSent += bytes.first + 32;
      this->Last.BytesReceived += bytes.second + 32;
    });
  this->Last.QueryMs = penumbra::ElapsedMs(start);

  // Their rays against this rank's casters.
  start = penumbra::Clock::now();
  std::vector<std::vector<unsigned char>> answers(static_cast<size_t>(ranks));
  bool ok = true;
  for (int q = 0; q < ranks; ++q)
  {
    if (in[q].empty() || origins[q].size() != 3)
    {
      continue;
    }
    std::string failure;
    answers[q] = this->Trace(geometry, in[q], origins[q].data(), lights, failure);
    this->Last.RaysAnswered += static_cast<long long>(in[q].size() / RayFloats);
    if (!failure.empty())
    {
      ok = false;
      error = failure;
    }
  }
  this->Last.TraceMs = penumbra::ElapsedMs(start);

  // The answers back; a sample any rank blocks is shadowed.
  start = penumbra::Clock::now();
  std::vector<std::vector<unsigned char>> replies(static_cast<size_t>(ranks));
  penumbra::ForEachPeer(controller, everyone,
    [&](int q)
    {
      const auto bytes =
        penumbra::ExchangeVectors(controller, q, answers[q], replies[q], AnswerTag);
      this->Last.BytesSent += bytes.first;
      this->Last.BytesReceived += bytes.second;
    });
  const vtkIdType n = samples ? samples->GetNumberOfSamples() : 0;
  for (int q = 0; q < ranks; ++q)
  {
    for (size_t k = 0; k < which[q].size() && k / 8 < replies[q].size(); ++k)
    {
      if (replies[q][k / 8] & (1u << (k % 8)))
      {
        const vtkIdType code = which[q][k];
        float* value = visibilities[static_cast<size_t>(code / n)]->GetPointer(code % n);
        this->Last.RaysBlocked += *value > 0.0f ? 1 : 0;
        *value = 0.0f;
      }
    }
  }
  this->Last.AnswerMs = penumbra::ElapsedMs(start);
  this->Gather();
  return ok;
}

void vtkPenumbraRayQueries::Gather()
{
  const Figures& f = this->Last;
  const std::vector<double> mine = { static_cast<double>(f.RaysSent),
    static_cast<double>(f.RaysAnswered), static_cast<double>(f.RaysBlocked),
    static_cast<double>(f.BytesSent), static_cast<double>(f.BytesReceived),
    static_cast<double>(f.Reductions), static_cast<double>(f.ReducedBytes), f.RouteMs, f.QueryMs,
    f.TraceMs, f.AnswerMs, f.ReduceMs };
  this->Report = penumbra::RankReport(this->Controller,
    "ray queries and composited maps, per rank: rays sent, rays answered, samples shadowed by "
    "other ranks, bytes sent, bytes received, map/fit reductions, bytes reduced, "
    "route/query/trace/answer/reduce ms",
    mine, 7);
}
