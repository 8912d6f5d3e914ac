#pragma once
// What the band loops of the force loop (core/detail/spring_bands.hpp) and of the matrix-free
// system (core/detail/band_system.hpp) share: the attribute that gives a loop one copy per
// instruction set, chosen when the library is loaded (GCC's function multi-versioning: AVX2
// where the CPU has it, the x86-64 baseline SSE2 elsewhere; AVX-512 is not among them:
// docs/benchmarks.md, "The force loop"), and the loops that add a band's per-slot terms to the
// particles at the slots' first or second ends.
#include <jelly/core/types.hpp>

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define JELLY_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define JELLY_VECTOR_CLONES
#endif

namespace jelly::band_kernels {

// a[j] += t[j] for j in [0, n), for the three coordinates.
void add(int n, const Real* tx, const Real* ty, const Real* tz, Real* ax, Real* ay, Real* az);
// a[j] -= t[j] for j in [0, n), for the three coordinates.
void subtract(int n, const Real* tx, const Real* ty, const Real* tz, Real* ax, Real* ay, Real* az);

}  // namespace jelly::band_kernels
