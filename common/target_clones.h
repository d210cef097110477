// Function multiversioning for hot loops: GCC compiles the function once per ISA listed and picks
// one when the library loads (an ifunc), so one binary runs everywhere and uses AVX2/AVX-512
// where the CPU has them. Windows has no ifuncs and Clang's rules differ; the ASan build keeps
// the baseline. The clones' arithmetic must be the same (integer, or floating point without
// contraction), so every clone gives the same result.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(_WIN32) && \
    !defined(__SANITIZE_ADDRESS__)
#define VT_TARGET_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define VT_TARGET_CLONES
#endif
