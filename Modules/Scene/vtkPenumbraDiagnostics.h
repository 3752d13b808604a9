/**
 * @file   vtkPenumbraDiagnostics.h
 * @brief  The two conventions every Penumbra computation reports through: wall-clock phase
 *         times in milliseconds, and "report the error, return 0" for a failed call.
 */

#ifndef vtkPenumbraDiagnostics_h
#define vtkPenumbraDiagnostics_h

#include "vtkSetGet.h" // For vtkErrorWithObjectMacro

#include <chrono> // For std::chrono::steady_clock

namespace penumbra
{
using Clock = std::chrono::steady_clock;

/**
 * Milliseconds since `start` on the steady clock (phase timers; the caller calls glFinish
 * first where GPU work is being timed).
 */
inline double ElapsedMs(Clock::time_point start)
{
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}
}

/**
 * Reports `text` (stream syntax: "light " << i << " has no axis") as `self`'s error and
 * returns 0 from the calling function: the failure path of every Compute call.
 */
#define PENUMBRA_FAIL_FOR(self, text)                                                              \
  do                                                                                               \
  {                                                                                                \
    vtkErrorWithObjectMacro(self, << text);                                                        \
    return 0;                                                                                      \
  } while (false)

/**
 * PENUMBRA_FAIL_FOR(this, text), inside a member function.
 */
#define PENUMBRA_FAIL(text) PENUMBRA_FAIL_FOR(this, text)

#endif
