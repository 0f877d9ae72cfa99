/* sf_fuzz.h — the one entry point every harness in tests/fuzz/ defines: libFuzzer calls it with each
 * generated input (make check-fuzz, make fuzz), and fuzz_replay.c calls it with each file of the
 * corpus and crashers directories (a plain ctest in every build, gcc ASan included). It returns 0;
 * a bug shows as a crash, a sanitizer report, a leak or a failed reference check (abort()). */
#ifndef SF_FUZZ_H
#define SF_FUZZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The input as a read-only stream (fmemopen; CMake builds the harnesses with _GNU_SOURCE), or NULL for an
 * empty input (nothing to read) or when no stream can be made. */
static inline FILE *sf_fuzz_stream(const uint8_t *const data, const size_t size)
{
    return size > 0 ? fmemopen((void *)(uintptr_t)data, size, "rb") : NULL;
}

/* A reference check that failed: says which and aborts, so the fuzzer keeps the input. */
#define SF_FUZZ_CHECK(cond)                                                                      \
    do {                                                                                         \
        if (!(cond)) {                                                                           \
            fprintf(stderr, "%s:%d: fuzz reference check failed: %s\n", __FILE__, __LINE__, #cond); \
            abort();                                                                             \
        }                                                                                        \
    } while (0)

#endif
