#pragma once
// What CHOLMOD is asked to do (solvers/linear/cholmod_solver.hpp does it): the options of the
// integrators that factorize with it, apart from the solver, so that naming them does not bring
// in the sparse matrices.
#include <string_view>
#include <vector>

#include <jelly/core/enum_names.hpp>

namespace jelly {

enum class CholmodOrdering {
  kAmd,     // approximate minimum degree
  kMetis,   // METIS nested dissection of A + A^T
  kNesdis,  // CHOLMOD's own nested dissection (METIS bisection + constrained minimum degree)
  kBest,    // CHOLMOD's default: AMD, and METIS when AMD gives much fill
};
// "amd", "metis", "nesdis", "best".
const std::vector<EnumName<CholmodOrdering>>& cholmod_orderings();
std::string_view cholmod_ordering_name(CholmodOrdering ordering);

struct CholmodOptions {
  // METIS gives the least fill and the fastest factorization on the seed cube (docs/implicit.md).
  CholmodOrdering ordering = CholmodOrdering::kMetis;
  // Supernodal (BLAS-3) factorization from this many unknowns on; simplicial (no BLAS) below,
  // where BLAS calls, and OpenBLAS waking its threads on a busy machine, cost more than they
  // save (docs/implicit.md, "Measured speed"). 0 = always supernodal; a huge value = always
  // simplicial.
  int supernodal_min_rows = 1000;
};

}  // namespace jelly
