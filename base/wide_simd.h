// ISOLINK_WIDE_SIMD: a hot loop's function built twice on x86-64 by GCC, for AVX2 with FMA and
// for the baseline, the loader picking one for the machine (function multiversioning; other
// compilers and machines build the baseline alone): the same binary runs anywhere and uses four
// lanes where it can. The two may differ in the last bits (a fused multiply-add rounds once): a
// run is the same on every machine of one kind, and within rounding across kinds.
//
//   ISOLINK_WIDE_SIMD void March::advance(double h) { ... }
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ISOLINK_WIDE_SIMD __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define ISOLINK_WIDE_SIMD
#endif
