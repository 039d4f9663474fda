/* MODEL_HOT marks the model's streaming loops (separable B-spline passes, spring stencil, CG
 * vectors) for gcc's -O3 vectoriser; gcc's -O2 cost model leaves loops of unknown trip count
 * scalar. Clang has no per-function optimize attribute (it would warn), so there it is empty.
 * The Makefile's -O2 without -march is kept: the binary runs on any x86-64. */
#ifndef ARGIL_MODEL_HOT_H
#define ARGIL_MODEL_HOT_H

#if defined(__GNUC__) && !defined(__clang__)
#define MODEL_HOT __attribute__((optimize("O3")))
#else
#define MODEL_HOT
#endif

/* MODEL_HOT_SIMD also builds an AVX2 copy chosen at load time (gcc's target_clones, an ifunc),
 * twice the floats per instruction where the CPU has AVX2. The copies do the same float
 * operations in the same order (AVX2 does not imply FMA, and -std=c11 keeps contraction off),
 * so results are bit-identical on every CPU. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define MODEL_HOT_SIMD __attribute__((optimize("O3"), target_clones("avx2", "default")))
#else
#define MODEL_HOT_SIMD MODEL_HOT
#endif

#endif
