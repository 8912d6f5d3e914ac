#pragma once
// What the band loops of the force loop (core/detail/spring_bands.hpp) and of the matrix-free
// system (core/detail/band_system.hpp) share: the attribute that gives a loop one copy per
// instruction set, chosen when the library is loaded (GCC's function multi-versioning: AVX2
// where the CPU has it, the x86-64 baseline SSE2 elsewhere; AVX-512 is not among them: it
// measured no faster, `git show 38c2702:docs/benchmarks.md`, "The force loop"), and the loops
// that add a band's per-slot terms to the particles at the slots' first or second ends.
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
// A band's per-slot terms t (t[0] the term of the slot whose first end is particle a and
// second end particle b) added to particles: a[i] += t(slot with first end i) for i in
// [a0, a1) and a[i] -= t(slot with second end i) for i in [b0, b1), as a[i] += t_first - t_second
// where a particle is both (one pass; the same bits for any split of the particles).
void add_ends(int a, int b, int a0, int a1, int b0, int b1, const Real* tx, const Real* ty,
              const Real* tz, Real* ax, Real* ay, Real* az);
// As add_ends, but a[i] = (a[i] + t_first) - t_second where a particle is both: the same bits
// as adding at every first end and then subtracting at every second end (two passes).
void add_then_subtract_ends(int a, int b, int a0, int a1, int b0, int b1, const Real* tx,
                            const Real* ty, const Real* tz, Real* ax, Real* ay, Real* az);

}  // namespace jelly::band_kernels
