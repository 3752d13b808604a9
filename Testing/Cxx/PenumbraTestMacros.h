// Assertions for the C++ test drivers of every Penumbra module: report the failed condition
// with its location and fail the test function.
#ifndef PenumbraTestMacros_h
#define PenumbraTestMacros_h

#include <cstdlib>
#include <iostream>

#define CHECK(cond)                                                                                \
  do                                                                                               \
  {                                                                                                \
    if (!(cond))                                                                                   \
    {                                                                                              \
      std::cerr << __FILE__ << ":" << __LINE__ << ": check failed: " #cond << std::endl;           \
      return EXIT_FAILURE;                                                                         \
    }                                                                                              \
  } while (false)

// Runs a sub-test returning EXIT_SUCCESS/EXIT_FAILURE and stops at the first failure.
#define RUN(subtest)                                                                               \
  do                                                                                               \
  {                                                                                                \
    if ((subtest) != EXIT_SUCCESS)                                                                 \
    {                                                                                              \
      std::cerr << "sub-test failed: " #subtest << std::endl;                                      \
      return EXIT_FAILURE;                                                                         \
    }                                                                                              \
  } while (false)

#endif
