#pragma once
// A geometric multigrid preconditioner for the implicit step's matrix-free CG on lattice bodies
// (docs/implicit.md, "Multigrid on lattices"): one V-cycle per CG iteration.
//
// Levels: the particles of every body whose rest positions fill a whole grid in grid order (the
// cube and the box) form level 0; level l + 1 keeps every other grid point along each axis (and
// the last one), down to at most 3 points per axis. Transfers are trilinear (P, built once per
// pattern); the coarse operators are Galerkin products P^T A_l P, computed one axis at a time
// on 27-point stencils of 3x3 blocks. To keep level 0's stencil at 27 points, each bending
// spring (a, c) with middle particle m enters it as two springs (a, m) and (m, c) of twice its
// block: exact for the linear fields the coarse levels carry, never softer (so level 1 is still
// P^T of a positive definite matrix, P).
//
// Contact rows and pins as in the fine solve: with S the free-direction projectors and C the
// sliding friction of the fine filter (ProductFilter), level 0's transfers are S P and level 1
// is P^T (S A S + C) P, the Galerkin product of the filtered operator restricted to the free
// directions; the constrained directions are the smoother's (their rows are the identity).
//
// Smoother: block Jacobi damped by omega, one sweep before and one after the coarse
// correction (the same sweep: the V-cycle is a symmetric operator); omega = 2/3 on level 0
// (lambda_max(D^-1 A) <= 2 there: A is the mass plus positive semi-definite spring blocks) and
// 4 / (3 lambda) on coarse levels, lambda a power-iteration estimate times 1.1. The coarsest
// level is solved by a dense Cholesky factor. Every loop is a gather over rows on a static
// split: the same bits for any thread count. The V-cycle is symmetric positive definite
// whatever coarse operator it holds, so the coarse operators may lag behind the fine one
// (implicit_euler rebuilds them every few steps and when the contacts' set changes).
#include <array>
#include <functional>
#include <vector>

#include <Eigen/Cholesky>

#include <jelly/core/detail/band_system.hpp>
#include <jelly/core/model.hpp>
#include <jelly/solvers/linear/detail/linear_solver.hpp>

namespace jelly {

class LatticeMultigrid {
 public:
  using Product = std::function<void(const VecX& in, VecX& out)>;
  using DiagonalBlock = std::function<void(int i, Real out[9])>;

  // The lattice bodies of `model` with their springs in `bands`: levels, transfers and the map
  // from band slots to level 0's stencil (allocates; once per pattern). False when no body is
  // a lattice with a coarser level (then nothing is held).
  bool build(const Model& model, const SpringBands& bands);
  bool built_for(const SpringBands& bands, int particles) const {
    return bands_ == &bands && particles_ == particles;
  }
  // The coarse operators from `band`'s current matrix filtered by `filter` (slot null: none).
  void set_operator(const BandSystem& band, const ProductFilter& filter, int threads);
  // Level 0's smoother: the inverses of the (filtered) diagonal blocks of all particles, as
  // block Jacobi; a singular block or a non-positive diagonal entry is a kNotPositiveDefinite
  // failure naming it. Keeps `filter` (valid until the next call) for the transfers.
  LinearResult set_diagonal_blocks(int particles, const DiagonalBlock& block,
                                   const ProductFilter& filter, int threads);
  // z = B r, one V-cycle from zero, with level 0's operator given by `product`.
  void apply(const Product& product, const VecX& r, VecX& z, int threads);

  int levels() const { return static_cast<int>(levels_.size()); }
  // Unknowns of level 1.
  int coarse_unknowns() const { return levels_.size() > 1 ? 3 * levels_[1].nodes : 0; }

 private:
  // The transfer along one axis between n fine and m coarse points.
  struct Axis {
    int n = 0, m = 0;
    std::vector<int> coarse_point;           // [m]: fine index of coarse point I
    std::vector<std::array<int, 2>> parent;  // [n]: coarse parents (-1: none)
    std::vector<std::array<Real, 2>> parent_weight;
    std::vector<std::array<int, 3>> child;  // [m]: fine children (-1: none)
    std::vector<std::array<Real, 3>> child_weight;
    // Galerkin terms of coarse point I and offset D (index 3 I + D + 1): fine child i, fine
    // offset d and weight P(i, I) P(i + d, I + D).
    struct Term {
      int i, d;
      Real w;
    };
    std::vector<std::vector<Term>> terms;
    Real weight(int i, int coarse) const;  // P(i, coarse)
  };
  struct Grid {
    std::array<int, 3> n{1, 1, 1};
    int offset = 0;   // first node of the grid in the level's vectors
    int stencil = 0;  // first node of the grid in the level's stencil array
    int nodes() const { return n[0] * n[1] * n[2]; }
  };
  struct Level {
    std::vector<Grid> grids;
    int nodes = 0;              // vector length / 3
    int stencil_nodes = 0;      // nodes with a stencil (level 0: the lattice particles)
    std::vector<Real> a;        // [stencil_nodes][27][9], row-major blocks
    std::vector<Real> inverse;  // [nodes][9] the smoother's block inverses
    Real omega = 2.0 / 3;
    VecX r, x, t;
    std::vector<std::array<Axis, 3>> down;  // per grid: the transfer to the next level
  };
  // Level 0's stencil from the band system, filtered.
  void fine_stencil(const BandSystem& band, const ProductFilter& filter, int threads);
  // Level l + 1's stencil from level l's.
  void galerkin(int l, int threads);
  // Symmetrizes level l's stencil, regularizes its diagonal blocks, inverts them and
  // estimates its smoother's damping.
  void finish_level(int l, int threads);
  void multiply(int l, const VecX& x, VecX& y, int threads) const;            // coarse levels
  void smooth(int l, const VecX& r, VecX& x, Real scale, int threads) const;  // x += w D^-1 r
  void restrict_to(int l, const VecX& fine, VecX& coarse, int threads) const;
  void prolong_add(int l, const VecX& coarse, VecX& fine, int threads) const;
  void cycle(int l, const Product& product, int threads);

  const SpringBands* bands_ = nullptr;
  int particles_ = 0;
  std::vector<Level> levels_;
  // Level 0's stencil from the springs: per lattice particle its edges [edge_start_[k],
  // edge_start_[k + 1]): stencil offset, band, slot and factor (2 for bending halves).
  struct Edge {
    int offset, band, slot;
    Real factor;
  };
  std::vector<int> edge_start_;
  std::vector<Edge> edges_;
  std::vector<int> lattice_particle_;  // [stencil nodes of level 0]: particle index
  ProductFilter filter_;
  Eigen::LLT<Eigen::MatrixXd> coarsest_;
  bool coarsest_factored_ = false;
  std::vector<Real> scratch_;  // Galerkin sweeps' intermediate stencils
};

}  // namespace jelly
