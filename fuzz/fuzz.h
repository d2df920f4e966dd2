/*
 * fuzz.h -- what the fuzz targets share.  Each target defines
 * LLVMFuzzerTestOneInput(); it is linked either with libFuzzer (clang,
 * -DRADIOSITY_FUZZ=ON: the fuzzer) or with replay.c (any compiler, every
 * build: the corpus replayed as a CTest test).
 *
 * A target checks the contract, not just survival: a failure must leave a
 * one-line message, success must give a usable result.  A broken contract
 * aborts, which both libFuzzer and the replay report as a crash.
 */
#ifndef RAD_FUZZ_H
#define RAD_FUZZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Abort with a message when a contract is broken (assert() would vanish
 * under NDEBUG in release builds). */
#define FUZZ_CHECK(cond)                                                                      \
    do {                                                                                      \
        if (!(cond)) {                                                                        \
            fprintf(stderr, "%s:%d: contract broken: %s\n", __FILE__, __LINE__, #cond);       \
            abort();                                                                          \
        }                                                                                     \
    } while (0)

#endif
