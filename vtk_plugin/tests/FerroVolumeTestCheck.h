// The check the C++ test programs of vtk_plugin/tests share: CHECK(cond, printf-args...)
// prints the failed condition with its file, line and message and counts it in `failures`,
// which the program returns.
#ifndef FerroVolumeTestCheck_h
#define FerroVolumeTestCheck_h

#include <cstdio>

namespace
{
int failures = 0;
}

#define CHECK(cond, ...)                                                                         \
  do                                                                                             \
  {                                                                                              \
    if (!(cond))                                                                                 \
    {                                                                                            \
      std::printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);                               \
      std::printf(__VA_ARGS__);                                                                  \
      std::printf("\n");                                                                         \
      ++failures;                                                                                \
    }                                                                                            \
  } while (0)

#endif
