/* Shared by the C test programs: how a failed ferrovol call is reported. */
#ifndef FV_REPORT_H
#define FV_REPORT_H

#include "ferrovol.h"

#include <stdio.h>

/* Prints "CALL failed: STATUS_NAME: message" to stderr; returns 1 (a failing exit code). */
static inline int fv_report(const char *what, FvStatus s) {
  fprintf(stderr, "%s failed: %s: %s\n", what, fv_status_name(s), fv_last_error());
  return 1;
}

/* Runs a ferrovol call; on failure reports it and returns 1 from the calling function. */
#define FV_TRY(call)                                                           \
  do {                                                                         \
    FvStatus s_ = (call);                                                      \
    if (s_ != FV_STATUS_OK)                                                    \
      return fv_report(#call, s_);                                             \
  } while (0)

#endif
