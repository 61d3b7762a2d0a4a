/* The checks of the C test programs: a failed check prints what and where, with
 * talus's last error, and counts; main returns non-zero when any failed. */
#ifndef TALUS_TEST_CHECK_H
#define TALUS_TEST_CHECK_H

#include <stdio.h>
#include <string.h>

#include "talus.h"

static int failures = 0;

#define CHECK(cond, what)                                                   \
    do {                                                                    \
        if (!(cond)) {                                                      \
            fprintf(stderr, "FAILED: %s (line %d): %s\n", what, __LINE__,  \
                    talus_last_error());                                    \
            ++failures;                                                     \
        }                                                                   \
    } while (0)

#define REFUSED(call, words)                                                \
    do {                                                                    \
        int s_ = (call);                                                    \
        CHECK(s_ == TALUS_ERROR, #call " must fail");                       \
        CHECK(strstr(talus_last_error(), words) != NULL,                    \
              #call " must say '" words "'");                               \
    } while (0)

#endif
