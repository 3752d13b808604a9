/**
 * @file   vtkPenumbraRankMessages.h
 * @brief  Point-to-point messages between MPI ranks for the distributed shadows: a vector
 *         with its length, both ways between two ranks, and the pairwise rounds that let every
 *         pair of ranks exchange without blocking sends waiting on one another.
 */

#ifndef vtkPenumbraRankMessages_h
#define vtkPenumbraRankMessages_h

#include "vtkMultiProcessController.h"

#include <iomanip>
#include <sstream>
#include <string>
#include <vector>

namespace penumbra
{
/**
 * Calls `visit(q)` for every rank q != this one for which `wanted(q)`, in pairwise rounds:
 * round k pairs each rank r with (k - r) mod P (a perfect matching, each pair once), so when
 * both ranks of a pair exchange in the same round with the lower one sending first
 * (ExchangeVectors()), blocking sends never wait in a cycle.
 */
template <typename Wanted, typename Visit>
void ForEachPeer(vtkMultiProcessController* controller, Wanted wanted, Visit visit)
{
  const int ranks = controller->GetNumberOfProcesses();
  const int me = controller->GetLocalProcessId();
  for (int k = 0; k < ranks; ++k)
  {
    const int q = ((k - me) % ranks + ranks) % ranks;
    if (q != me && wanted(q))
    {
      visit(q);
    }
  }
}

/**
 * Sends `out` to rank `q` and receives `in` from it (length first, then the values; `in` is
 * resized), the lower rank sending first. Returns the bytes sent and received.
 */
template <typename T>
std::pair<long long, long long> ExchangeVectors(vtkMultiProcessController* controller, int q,
  const std::vector<T>& out, std::vector<T>& in, int tag)
{
  const long long sent = static_cast<long long>(out.size());
  auto send = [&]
  {
    controller->Send(&sent, 1, q, tag);
    if (sent > 0)
    {
      controller->Send(out.data(), sent, q, tag);
    }
  };
  auto receive = [&]
  {
    long long count = 0;
    controller->Receive(&count, 1, q, tag);
    in.assign(static_cast<size_t>(count), T());
    if (count > 0)
    {
      controller->Receive(in.data(), count, q, tag);
    }
  };
  if (controller->GetLocalProcessId() < q)
  {
    send();
    receive();
  }
  else
  {
    receive();
    send();
  }
  return { static_cast<long long>(sizeof(T)) * sent + 8,
    static_cast<long long>(sizeof(T) * in.size()) + 8 };
}

/**
 * Every rank's `values` (the same count on every rank) gathered on rank 0, as `header` and
 * then a line per rank: "rank r" and the values, the first `counts` of them as integers, the
 * others with one decimal (times in ms). Collective; returns "" on the other ranks.
 */
inline std::string RankReport(vtkMultiProcessController* controller, const std::string& header,
  const std::vector<double>& values, size_t counts)
{
  const int ranks = controller->GetNumberOfProcesses();
  std::vector<double> all(values.size() * static_cast<size_t>(ranks));
  controller->Gather(values.data(), all.data(), static_cast<vtkIdType>(values.size()), 0);
  if (controller->GetLocalProcessId() != 0)
  {
    return std::string();
  }
  std::ostringstream text;
  text << header << "\n";
  for (int r = 0; r < ranks; ++r)
  {
    const double* v = all.data() + values.size() * static_cast<size_t>(r);
    text << "rank " << r;
    for (size_t i = 0; i < values.size(); ++i)
    {
      if (i < counts)
      {
        text << " " << static_cast<long long>(v[i]);
      }
      else
      {
        text << " " << std::fixed << std::setprecision(1) << v[i] << std::defaultfloat;
      }
    }
    text << "\n";
  }
  return text.str();
}
}

#endif
