#include <jelly/solvers/linear/detail/lattice_multigrid.hpp>

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include <jelly/core/detail/parallel.hpp>

namespace jelly {

namespace {

// Rows per thread below which another thread costs more than it saves.
constexpr long kMgRowsPerThread = 512;
// Points per axis at or below which a grid is not coarsened further.
constexpr int kMgCoarsestPoints = 3;

inline int mg_offset(int dx, int dy, int dz) { return (dx + 1) * 9 + (dy + 1) * 3 + (dz + 1); }
constexpr int kMgCentre = 13;

// The grid a body's rest positions fill in grid order ((i n_y + j) n_z + k at x0 + i ex + j ey +
// k ez), or dims {0, 0, 0} when they do not.
std::array<int, 3> mg_detect_grid(const Model& model, const Body& body) {
  const int first = body.first_particle, np = body.num_particles;
  const auto x = [&](int i) -> Vec3 { return model.rest_position.segment<3>(3 * (first + i)); };
  if (np < 8) return {0, 0, 0};
  // Collinear run of points from 0 with step x(step) - x(0).
  const auto run = [&](int step) {
    const Vec3 e = x(step) - x(0);
    const Real tol = 1e-6 * e.norm();
    int k = 1;
    while (k * step < np && (x(k * step) - x(0) - k * e).norm() <= tol) ++k;
    return k;
  };
  const int nz = run(1);
  if (nz < 2 || np % nz != 0) return {0, 0, 0};
  const int ny = nz < np ? run(nz) : 1;
  if (np % (ny * nz) != 0) return {0, 0, 0};
  const int nx = np / (ny * nz);
  const Vec3 ez = x(1) - x(0);
  const Vec3 ey = ny > 1 ? Vec3(x(nz) - x(0)) : Vec3::Zero();
  const Vec3 ex = nx > 1 ? Vec3(x(ny * nz) - x(0)) : Vec3::Zero();
  const Real tol = 1e-6 * ez.norm();
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        if ((x((i * ny + j) * nz + k) - x(0) - i * ex - j * ey - k * ez).norm() > tol)
          return {0, 0, 0};
  return {nx, ny, nz};
}

// out (row-major 3x3) = s (column-major 3x3, a ProductFilter's map) * out, or out * s.
void mg_left_multiply(const Real* s, Real* out) {
  Real t[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      t[3 * r + c] = s[r] * out[c] + s[3 + r] * out[3 + c] + s[6 + r] * out[6 + c];
  std::copy(t, t + 9, out);
}
void mg_right_multiply(const Real* s, Real* out) {
  Real t[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      t[3 * r + c] =
          out[3 * r] * s[3 * c] + out[3 * r + 1] * s[3 * c + 1] + out[3 * r + 2] * s[3 * c + 2];
  std::copy(t, t + 9, out);
}

// The 1D transfer of n fine points: coarse points at the even indices and the last one.
template <class Axis>
void mg_build_axis(int n, Axis& a) {
  a.n = n;
  a.coarse_point.clear();
  if (n <= kMgCoarsestPoints) {
    for (int i = 0; i < n; ++i) a.coarse_point.push_back(i);
  } else {
    for (int i = 0; i < n; i += 2) a.coarse_point.push_back(i);
    if (a.coarse_point.back() != n - 1) a.coarse_point.push_back(n - 1);
  }
  a.m = static_cast<int>(a.coarse_point.size());
  std::vector<int> coarse_of(n, -1);
  for (int I = 0; I < a.m; ++I) coarse_of[a.coarse_point[I]] = I;
  a.parent.assign(n, {-1, -1});
  a.parent_weight.assign(n, {0, 0});
  a.child.assign(a.m, {-1, -1, -1});
  a.child_weight.assign(a.m, {0, 0, 0});
  for (int i = 0; i < n; ++i) {
    if (coarse_of[i] >= 0) {
      a.parent[i] = {coarse_of[i], -1};
      a.parent_weight[i] = {1, 0};
    } else {  // a midpoint of two coarse points
      a.parent[i] = {coarse_of[i - 1], coarse_of[i + 1]};
      a.parent_weight[i] = {0.5, 0.5};
    }
  }
  for (int I = 0; I < a.m; ++I) {
    const int c = a.coarse_point[I];
    a.child[I][1] = c;
    a.child_weight[I][1] = 1;
    if (c > 0 && coarse_of[c - 1] < 0) {
      a.child[I][0] = c - 1;
      a.child_weight[I][0] = 0.5;
    }
    if (c + 1 < n && coarse_of[c + 1] < 0) {
      a.child[I][2] = c + 1;
      a.child_weight[I][2] = 0.5;
    }
  }
  a.terms.assign(3 * static_cast<size_t>(a.m), {});
  for (int I = 0; I < a.m; ++I)
    for (int D = -1; D <= 1; ++D) {
      if (I + D < 0 || I + D >= a.m) continue;
      for (int q = 0; q < 3; ++q) {
        const int i = a.child[I][q];
        if (i < 0) continue;
        for (int d = -1; d <= 1; ++d) {
          if (i + d < 0 || i + d >= n) continue;
          const Real w = a.child_weight[I][q] * a.weight(i + d, I + D);
          if (w != 0) a.terms[3 * I + D + 1].push_back({i, d, w});
        }
      }
    }
}

}  // namespace

Real LatticeMultigrid::Axis::weight(int i, int coarse) const {
  if (parent[i][0] == coarse) return parent_weight[i][0];
  if (parent[i][1] == coarse) return parent_weight[i][1];
  return 0;
}

bool LatticeMultigrid::build(const Model& model, const SpringBands& bands) {
  levels_.clear();
  edges_.clear();
  edge_start_.clear();
  lattice_particle_.clear();
  bands_ = nullptr;
  particles_ = model.num_particles();
  Level fine;
  fine.nodes = particles_;
  // Per particle: its grid and coordinates (grid -1: not in a lattice).
  std::vector<std::array<int, 4>> where(particles_, {-1, 0, 0, 0});
  for (const Body& body : model.bodies) {
    const std::array<int, 3> dims = mg_detect_grid(model, body);
    if (dims[0] == 0 || std::max({dims[0], dims[1], dims[2]}) <= kMgCoarsestPoints) continue;
    Grid g;
    g.n = dims;
    g.offset = body.first_particle;
    g.stencil = fine.stencil_nodes;
    const int index = static_cast<int>(fine.grids.size());
    for (int i = 0; i < dims[0]; ++i)
      for (int j = 0; j < dims[1]; ++j)
        for (int k = 0; k < dims[2]; ++k)
          where[g.offset + (i * dims[1] + j) * dims[2] + k] = {index, i, j, k};
    for (int p = 0; p < g.nodes(); ++p) lattice_particle_.push_back(g.offset + p);
    fine.stencil_nodes += g.nodes();
    fine.grids.push_back(g);
  }
  if (fine.grids.empty()) return false;
  // Level 0's edges: each spring within a grid at stencil distance 1, and each at distance 2
  // along an axis (bending) as two halves through its middle.
  std::vector<std::vector<Edge>> per_node(fine.stencil_nodes);
  const auto node_of = [&](int p) {
    const Grid& g = fine.grids[where[p][0]];
    return g.stencil + (p - g.offset);
  };
  const auto particle_at = [&](const Grid& g, int i, int j, int k) {
    return g.offset + (i * g.n[1] + j) * g.n[2] + k;
  };
  for (size_t k = 0; k < bands.bands().size(); ++k) {
    const SpringBands::Band& band = bands.bands()[k];
    for (int s = 0; s < band.slots(); ++s) {
      if (band.spring[s] < 0) continue;
      const int a = band.first + s, b = a + band.offset;
      if (where[a][0] < 0 || where[a][0] != where[b][0]) continue;
      const int d[3] = {where[b][1] - where[a][1], where[b][2] - where[a][2],
                        where[b][3] - where[a][3]};
      const int reach = std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
      const int axes = (d[0] != 0) + (d[1] != 0) + (d[2] != 0);
      const int ks = static_cast<int>(k);
      if (reach == 1) {
        per_node[node_of(a)].push_back({mg_offset(d[0], d[1], d[2]), ks, s, 1.0});
        per_node[node_of(b)].push_back({mg_offset(-d[0], -d[1], -d[2]), ks, s, 1.0});
      } else if (reach == 2 && axes == 1) {
        const int h[3] = {d[0] / 2, d[1] / 2, d[2] / 2};
        const Grid& g = fine.grids[where[a][0]];
        const int m = particle_at(g, where[a][1] + h[0], where[a][2] + h[1], where[a][3] + h[2]);
        const int up = mg_offset(h[0], h[1], h[2]), back = mg_offset(-h[0], -h[1], -h[2]);
        per_node[node_of(a)].push_back({up, ks, s, 2.0});
        per_node[node_of(m)].push_back({back, ks, s, 2.0});
        per_node[node_of(m)].push_back({up, ks, s, 2.0});
        per_node[node_of(b)].push_back({back, ks, s, 2.0});
      }
      // Other springs are left out of the coarse levels (which stay positive definite).
    }
  }
  edge_start_.assign(1, 0);
  for (const std::vector<Edge>& e : per_node) {
    edges_.insert(edges_.end(), e.begin(), e.end());
    edge_start_.push_back(static_cast<int>(edges_.size()));
  }
  fine.a.assign(static_cast<size_t>(fine.stencil_nodes) * 27 * 9, 0.0);
  levels_.push_back(std::move(fine));
  // Coarser levels until every grid has at most kMgCoarsestPoints per axis.
  for (;;) {
    Level& l = levels_.back();
    const bool coarsest = std::all_of(l.grids.begin(), l.grids.end(), [](const Grid& g) {
      return std::max({g.n[0], g.n[1], g.n[2]}) <= kMgCoarsestPoints;
    });
    if (coarsest) break;
    Level next;
    l.down.resize(l.grids.size());
    for (size_t gi = 0; gi < l.grids.size(); ++gi) {
      Grid c;
      for (int ax = 0; ax < 3; ++ax) {
        mg_build_axis(l.grids[gi].n[ax], l.down[gi][ax]);
        c.n[ax] = l.down[gi][ax].m;
      }
      c.offset = c.stencil = next.nodes;
      next.nodes += c.nodes();
      next.grids.push_back(c);
    }
    next.stencil_nodes = next.nodes;
    next.a.assign(static_cast<size_t>(next.nodes) * 27 * 9, 0.0);
    levels_.push_back(std::move(next));
  }
  for (Level& l : levels_) {
    l.r.setZero(3 * l.nodes);
    l.x.setZero(3 * l.nodes);
    l.t.setZero(3 * l.nodes);
    l.inverse.assign(9 * static_cast<size_t>(l.nodes), 0.0);
  }
  bands_ = &bands;
  return true;
}

void LatticeMultigrid::fine_stencil(const BandSystem& band, const ProductFilter& filter,
                                    int threads) {
  Level& l = levels_[0];
  const long nodes = l.stencil_nodes;
  parallel::for_ranges(
      threads, nodes,
      [&](long begin, long end) {
        for (long k = begin; k < end; ++k) {
          Real* a = l.a.data() + 27 * 9 * k;
          std::fill(a, a + 27 * 9, 0.0);
          const int p = lattice_particle_[k];
          const Real m = band.mass_term(p);
          Real* centre = a + 9 * kMgCentre;
          centre[0] = centre[4] = centre[8] = m;
          for (int e = edge_start_[k]; e < edge_start_[k + 1]; ++e) {
            const Edge& edge = edges_[e];
            Real b[6];
            band.slot_block(static_cast<size_t>(edge.band), edge.slot, b);
            const Real full[9] = {b[0], b[3], b[4], b[3], b[1], b[5], b[4], b[5], b[2]};
            Real* off = a + 9 * edge.offset;
            for (int q = 0; q < 9; ++q) {
              off[q] -= edge.factor * full[q];
              centre[q] += edge.factor * full[q];
            }
          }
          if (filter.slot == nullptr) continue;
          // S_p A_pq S_q over the row, then the sliding friction c S_p on the diagonal.
          const int sp = filter.slot[p];
          if (sp >= 0) {
            for (int o = 0; o < 27; ++o) mg_left_multiply(filter.map + 9 * sp, a + 9 * o);
          }
          int g = 0;
          while (g + 1 < static_cast<int>(l.grids.size()) && l.grids[g + 1].stencil <= k) ++g;
          const Grid& grid = l.grids[g];
          const int local = static_cast<int>(k) - grid.stencil;
          const int pi = local / (grid.n[1] * grid.n[2]), pj = (local / grid.n[2]) % grid.n[1],
                    pk = local % grid.n[2];
          for (int o = 0; o < 27; ++o) {  // the neighbours' projectors on the right
            const int i = pi + o / 9 - 1, j = pj + (o / 3) % 3 - 1, kk = pk + o % 3 - 1;
            if (i < 0 || j < 0 || kk < 0 || i >= grid.n[0] || j >= grid.n[1] || kk >= grid.n[2])
              continue;
            const int so = filter.slot[grid.offset + (i * grid.n[1] + j) * grid.n[2] + kk];
            if (so >= 0) mg_right_multiply(filter.map + 9 * so, a + 9 * o);
          }
          if (sp >= 0 && filter.scale != nullptr && filter.scale[sp] != 0) {
            const Real* s = filter.map + 9 * sp;
            for (int r = 0; r < 3; ++r)
              for (int c = 0; c < 3; ++c) centre[3 * r + c] += filter.scale[sp] * s[3 * c + r];
          }
        }
      },
      kMgRowsPerThread);
}

void LatticeMultigrid::galerkin(int l, int threads) {
  Level& fine = levels_[l];
  Level& coarse = levels_[l + 1];
  for (size_t gi = 0; gi < fine.grids.size(); ++gi) {
    const Grid& fg = fine.grids[gi];
    const Grid& cg = coarse.grids[gi];
    const std::array<Axis, 3>& axes = fine.down[gi];
    // Three sweeps: x, y, z coarsened in turn; dims of the input and output of each.
    std::array<int, 3> in_n = fg.n;
    const Real* in = fine.a.data() + static_cast<size_t>(fg.stencil) * 27 * 9;
    const size_t max_nodes = static_cast<size_t>(cg.n[0]) * fg.n[1] * fg.n[2] +
                             static_cast<size_t>(cg.n[0]) * cg.n[1] * fg.n[2];
    if (scratch_.size() < max_nodes * 27 * 9) scratch_.resize(max_nodes * 27 * 9);
    Real* buffers[2] = {scratch_.data(), scratch_.data() + static_cast<size_t>(cg.n[0]) * fg.n[1] *
                                                               fg.n[2] * 27 * 9};
    for (int ax = 0; ax < 3; ++ax) {
      std::array<int, 3> out_n = in_n;
      out_n[ax] = cg.n[ax];
      Real* out =
          ax == 2 ? coarse.a.data() + static_cast<size_t>(cg.stencil) * 27 * 9 : buffers[ax];
      const Axis& axis = axes[ax];
      // [d + 1][D + 1]: the value offsets of the 9 blocks with fine offset d and coarse offset
      // D along this axis (input, output).
      std::array<std::array<std::array<std::array<int, 2>, 9>, 3>, 3> offset_pairs;
      for (int d = -1; d <= 1; ++d)
        for (int D = -1; D <= 1; ++D) {
          int q = 0;
          for (int e = -1; e <= 1; ++e)
            for (int f = -1; f <= 1; ++f) {
              int din[3], dout[3];
              int other = 0;
              for (int a = 0; a < 3; ++a) {
                if (a == ax) {
                  din[a] = d;
                  dout[a] = D;
                } else {
                  din[a] = dout[a] = other++ == 0 ? e : f;
                }
              }
              offset_pairs[d + 1][D + 1][q++] = {9 * mg_offset(din[0], din[1], din[2]),
                                                 9 * mg_offset(dout[0], dout[1], dout[2])};
            }
        }
      const long count = static_cast<long>(out_n[0]) * out_n[1] * out_n[2];
      parallel::for_ranges(
          threads, count,
          [&](long begin, long end) {
            for (long node = begin; node < end; ++node) {
              int c[3] = {static_cast<int>(node / (out_n[1] * out_n[2])),
                          static_cast<int>((node / out_n[2]) % out_n[1]),
                          static_cast<int>(node % out_n[2])};
              Real* o = out + 27 * 9 * node;
              std::fill(o, o + 27 * 9, 0.0);
              const int I = c[ax];
              for (int D = -1; D <= 1; ++D) {
                for (const Axis::Term& term : axis.terms[3 * I + D + 1]) {
                  int ci[3] = {c[0], c[1], c[2]};
                  ci[ax] = term.i;
                  const long in_node =
                      (static_cast<long>(ci[0]) * in_n[1] + ci[1]) * in_n[2] + ci[2];
                  const Real* src = in + 27 * 9 * in_node;
                  // Every offset of the other two axes.
                  const std::array<std::array<int, 2>, 9>& pairs = offset_pairs[term.d + 1][D + 1];
                  const Real w = term.w;
                  for (const std::array<int, 2>& pr : pairs) {
                    const Real* s = src + pr[0];
                    Real* t = o + pr[1];
                    for (int q = 0; q < 9; ++q) t[q] += w * s[q];
                  }
                }
              }
            }
          },
          kMgRowsPerThread / 8);
      in = out;
      in_n = out_n;
    }
  }
}

void LatticeMultigrid::finish_level(int l, int threads) {
  Level& level = levels_[l];
  // Symmetric: A(I, J) = A(J, I)^T, the mean of the two (they differ by rounding).
  for (const Grid& g : level.grids) {
    parallel::for_ranges(
        threads, g.nodes(),
        [&](long begin, long end) {
          for (long local = begin; local < end; ++local) {
            const int i = static_cast<int>(local / (g.n[1] * g.n[2]));
            const int j = static_cast<int>((local / g.n[2]) % g.n[1]);
            const int k = static_cast<int>(local % g.n[2]);
            Real* row = level.a.data() + 27 * 9 * (g.stencil + local);
            for (int o = 0; o < 27; ++o) {
              const int dx = o / 9 - 1, dy = (o / 3) % 3 - 1, dz = o % 3 - 1;
              const int i2 = i + dx, j2 = j + dy, k2 = k + dz;
              if (i2 < 0 || j2 < 0 || k2 < 0 || i2 >= g.n[0] || j2 >= g.n[1] || k2 >= g.n[2])
                continue;
              const long other = (static_cast<long>(i2) * g.n[1] + j2) * g.n[2] + k2;
              if (other < local) continue;  // each pair once, by its lower node
              Real* mine = row + 9 * o;
              Real* theirs =
                  level.a.data() + 27 * 9 * (g.stencil + other) + 9 * mg_offset(-dx, -dy, -dz);
              for (int r = 0; r < 3; ++r)
                for (int c = r; c < 3; ++c) {
                  if (other == local && c == r) continue;
                  const Real mean = 0.5 * (mine[3 * r + c] + theirs[3 * c + r]);
                  const Real mean_t = 0.5 * (mine[3 * c + r] + theirs[3 * r + c]);
                  mine[3 * r + c] = theirs[3 * c + r] = mean;
                  mine[3 * c + r] = theirs[3 * r + c] = mean_t;
                }
            }
          }
        },
        kMgRowsPerThread);
  }
  // Diagonal blocks: a node whose children are all constrained has none (the identity then);
  // one constrained in some directions is singular there: a tiny multiple of its trace.
  parallel::for_ranges(
      threads, level.nodes,
      [&](long begin, long end) {
        for (long node = begin; node < end; ++node) {
          Real* d = level.a.data() + 27 * 9 * node + 9 * kMgCentre;
          const Real trace = d[0] + d[4] + d[8];
          if (!(trace > 0)) {
            std::fill(d, d + 9, 0.0);
            d[0] = d[4] = d[8] = 1;
          } else {
            for (int q = 0; q < 9; q += 4) d[q] += 1e-9 * trace;
          }
          Eigen::Matrix3d b = Eigen::Map<const Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>(d);
          Eigen::Matrix3d inv = b.inverse();
          inv = 0.5 * (inv + inv.transpose()).eval();
          Eigen::Map<Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>(level.inverse.data() + 9 * node) =
              inv;
        }
      },
      kMgRowsPerThread);
  // Damping: 4 / (3 lambda), lambda = 1.1 x a power-iteration estimate of lambda_max(D^-1 A).
  if (l + 1 == levels()) return;  // the coarsest level is solved directly
  VecX& v = level.x;
  VecX& w = level.t;
  // From an oscillating vector (near the top of the spectrum): a few iterations suffice.
  for (long q = 0; q < v.size(); ++q)
    v[q] = ((q / 3) % 2 == 0 ? 1.0 : -1.0) * (1.0 + 0.25 * std::sin(0.7 * static_cast<Real>(q)));
  Real lambda = 1;
  for (int it = 0; it < 6; ++it) {
    multiply(l, v, w, threads);
    v.setZero();
    smooth(l, w, v, 1.0, threads);  // v = D^-1 A v
    const Real norm = v.norm();
    if (!(norm > 0)) break;
    lambda = norm / std::sqrt(static_cast<Real>(v.size()));
    v /= norm;
    v *= std::sqrt(static_cast<Real>(v.size()));
  }
  level.omega = 4.0 / (3.0 * 1.1 * lambda);
}

void LatticeMultigrid::set_operator(const BandSystem& band, const ProductFilter& filter,
                                    int threads) {
  fine_stencil(band, filter, threads);
  for (int l = 0; l + 1 < levels(); ++l) {
    galerkin(l, threads);
    finish_level(l + 1, threads);
  }
  // The coarsest level, dense.
  Level& last = levels_.back();
  const int n = 3 * last.nodes;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  for (const Grid& g : last.grids)
    for (int local = 0; local < g.nodes(); ++local) {
      const int i = local / (g.n[1] * g.n[2]), j = (local / g.n[2]) % g.n[1], k = local % g.n[2];
      const Real* row = last.a.data() + 27 * 9 * (g.stencil + local);
      for (int o = 0; o < 27; ++o) {
        const int i2 = i + o / 9 - 1, j2 = j + (o / 3) % 3 - 1, k2 = k + o % 3 - 1;
        if (i2 < 0 || j2 < 0 || k2 < 0 || i2 >= g.n[0] || j2 >= g.n[1] || k2 >= g.n[2]) continue;
        const int other = g.offset + (i2 * g.n[1] + j2) * g.n[2] + k2;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            dense(3 * (g.offset + local) + r, 3 * other + c) = row[9 * o + 3 * r + c];
      }
    }
  coarsest_.compute(dense);
  // Not positive definite to rounding (it should be): its block Jacobi instead.
  coarsest_factored_ = coarsest_.info() == Eigen::Success;
}

LinearResult LatticeMultigrid::set_diagonal_blocks(int particles, const DiagonalBlock& block,
                                                   const ProductFilter& filter, int threads) {
  filter_ = filter;
  Level& l = levels_[0];
  std::vector<long> bad(parallel::team_size(threads, particles, kMgRowsPerThread), particles);
  parallel::run(static_cast<int>(bad.size()), [&](int part, int parts) {
    const parallel::Range range = parallel::split(particles, part, parts);
    for (long i = range.begin; i < range.end; ++i) {
      Real d[9];
      block(static_cast<int>(i), d);
      const Eigen::Matrix3d b = Eigen::Map<const Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>(d);
      Eigen::Matrix3d inv;
      bool invertible = false;
      b.computeInverseWithCheck(inv, invertible);
      if (!invertible || !(b(0, 0) > 0 && b(1, 1) > 0 && b(2, 2) > 0)) {
        bad[part] = std::min(bad[part], i);
        continue;
      }
      inv = 0.5 * (inv + inv.transpose()).eval();
      Eigen::Map<Eigen::Matrix<Real, 3, 3, Eigen::RowMajor>>(l.inverse.data() + 9 * i) = inv;
    }
  });
  const long first_bad = *std::min_element(bad.begin(), bad.end());
  if (first_bad < particles)
    return LinearResult::failure(
        LinearStatus::kNotPositiveDefinite,
        "multigrid: diagonal block " + std::to_string(first_bad + 1) + " is not positive definite");
  return {};
}

void LatticeMultigrid::multiply(int l, const VecX& x, VecX& y, int threads) const {
  const Level& level = levels_[l];
  for (const Grid& g : level.grids) {
    const int n1 = g.n[1], n2 = g.n[2];
    parallel::for_ranges(
        threads, g.nodes(),
        [&](long begin, long end) {
          for (long local = begin; local < end; ++local) {
            const int i = static_cast<int>(local / (n1 * n2));
            const int j = static_cast<int>((local / n2) % n1);
            const int k = static_cast<int>(local % n2);
            const Real* row = level.a.data() + 27 * 9 * (g.stencil + local);
            Real acc[3] = {0, 0, 0};
            for (int dx = -1; dx <= 1; ++dx) {
              if (i + dx < 0 || i + dx >= g.n[0]) continue;
              for (int dy = -1; dy <= 1; ++dy) {
                if (j + dy < 0 || j + dy >= n1) continue;
                const int k0 = std::max(-1, -k), k1 = std::min(1, n2 - 1 - k);
                const Real* v = x.data() + 3 * (g.offset + ((i + dx) * n1 + j + dy) * n2 + k);
                const Real* b = row + 9 * mg_offset(dx, dy, 0);
                for (int dz = k0; dz <= k1; ++dz) {
                  const Real* bb = b + 9 * dz;
                  const Real* vv = v + 3 * dz;
                  acc[0] += bb[0] * vv[0] + bb[1] * vv[1] + bb[2] * vv[2];
                  acc[1] += bb[3] * vv[0] + bb[4] * vv[1] + bb[5] * vv[2];
                  acc[2] += bb[6] * vv[0] + bb[7] * vv[1] + bb[8] * vv[2];
                }
              }
            }
            Real* out = y.data() + 3 * (g.offset + local);
            for (int r = 0; r < 3; ++r) out[r] = acc[r];
          }
        },
        kMgRowsPerThread);
  }
}

void LatticeMultigrid::smooth(int l, const VecX& r, VecX& x, Real scale, int threads) const {
  const Level& level = levels_[l];
  parallel::for_ranges(
      threads, level.nodes,
      [&](long begin, long end) {
        for (long node = begin; node < end; ++node) {
          const Real* inv = level.inverse.data() + 9 * node;
          const Real* rr = r.data() + 3 * node;
          Real* xx = x.data() + 3 * node;
          for (int q = 0; q < 3; ++q)
            xx[q] += scale * (inv[3 * q] * rr[0] + inv[3 * q + 1] * rr[1] + inv[3 * q + 2] * rr[2]);
        }
      },
      kMgRowsPerThread);
}

void LatticeMultigrid::restrict_to(int l, const VecX& fine, VecX& coarse, int threads) const {
  const Level& f = levels_[l];
  const Level& c = levels_[l + 1];
  const bool filtered = l == 0 && filter_.slot != nullptr;
  for (size_t gi = 0; gi < f.grids.size(); ++gi) {
    const Grid& fg = f.grids[gi];
    const Grid& cg = c.grids[gi];
    const std::array<Axis, 3>& ax = f.down[gi];
    parallel::for_ranges(
        threads, cg.nodes(),
        [&](long begin, long end) {
          for (long local = begin; local < end; ++local) {
            const int I = static_cast<int>(local / (cg.n[1] * cg.n[2]));
            const int J = static_cast<int>((local / cg.n[2]) % cg.n[1]);
            const int K = static_cast<int>(local % cg.n[2]);
            Real acc[3] = {0, 0, 0};
            for (int a = 0; a < 3; ++a) {
              const int i = ax[0].child[I][a];
              if (i < 0) continue;
              for (int b = 0; b < 3; ++b) {
                const int j = ax[1].child[J][b];
                if (j < 0) continue;
                for (int e = 0; e < 3; ++e) {
                  const int k = ax[2].child[K][e];
                  if (k < 0) continue;
                  const Real w = ax[0].child_weight[I][a] * ax[1].child_weight[J][b] *
                                 ax[2].child_weight[K][e];
                  const int p = fg.offset + (i * fg.n[1] + j) * fg.n[2] + k;
                  Real v[3] = {fine[3 * p], fine[3 * p + 1], fine[3 * p + 2]};
                  if (filtered && filter_.slot[p] >= 0) {
                    const Real* s = filter_.map + 9 * filter_.slot[p];
                    const Real v0 = v[0], v1 = v[1], v2 = v[2];
                    for (int q = 0; q < 3; ++q) v[q] = s[q] * v0 + s[3 + q] * v1 + s[6 + q] * v2;
                  }
                  for (int q = 0; q < 3; ++q) acc[q] += w * v[q];
                }
              }
            }
            Real* out = coarse.data() + 3 * (cg.offset + local);
            for (int q = 0; q < 3; ++q) out[q] = acc[q];
          }
        },
        kMgRowsPerThread);
  }
}

void LatticeMultigrid::prolong_add(int l, const VecX& coarse, VecX& fine, int threads) const {
  const Level& f = levels_[l];
  const Level& c = levels_[l + 1];
  const bool filtered = l == 0 && filter_.slot != nullptr;
  for (size_t gi = 0; gi < f.grids.size(); ++gi) {
    const Grid& fg = f.grids[gi];
    const Grid& cg = c.grids[gi];
    const std::array<Axis, 3>& ax = f.down[gi];
    parallel::for_ranges(
        threads, fg.nodes(),
        [&](long begin, long end) {
          for (long local = begin; local < end; ++local) {
            const int i = static_cast<int>(local / (fg.n[1] * fg.n[2]));
            const int j = static_cast<int>((local / fg.n[2]) % fg.n[1]);
            const int k = static_cast<int>(local % fg.n[2]);
            Real acc[3] = {0, 0, 0};
            for (int a = 0; a < 2; ++a) {
              const int I = ax[0].parent[i][a];
              if (I < 0) continue;
              for (int b = 0; b < 2; ++b) {
                const int J = ax[1].parent[j][b];
                if (J < 0) continue;
                for (int e = 0; e < 2; ++e) {
                  const int K = ax[2].parent[k][e];
                  if (K < 0) continue;
                  const Real w = ax[0].parent_weight[i][a] * ax[1].parent_weight[j][b] *
                                 ax[2].parent_weight[k][e];
                  const Real* v = coarse.data() + 3 * (cg.offset + (I * cg.n[1] + J) * cg.n[2] + K);
                  for (int q = 0; q < 3; ++q) acc[q] += w * v[q];
                }
              }
            }
            const int p = fg.offset + static_cast<int>(local);
            if (filtered && filter_.slot[p] >= 0) {
              const Real* s = filter_.map + 9 * filter_.slot[p];
              const Real v0 = acc[0], v1 = acc[1], v2 = acc[2];
              for (int q = 0; q < 3; ++q) acc[q] = s[q] * v0 + s[3 + q] * v1 + s[6 + q] * v2;
            }
            for (int q = 0; q < 3; ++q) fine[3 * p + q] += acc[q];
          }
        },
        kMgRowsPerThread);
  }
}

void LatticeMultigrid::cycle(int l, const Product& product, int threads) {
  Level& level = levels_[l];
  if (l + 1 == levels()) {  // the coarsest: solved
    if (coarsest_factored_) {
      level.x = level.r;
      coarsest_.solveInPlace(level.x);
    } else {
      level.x.setZero();
      smooth(l, level.r, level.x, 1.0, threads);
    }
    return;
  }
  Level& next = levels_[l + 1];
  const auto residual = [&] {  // t = r - A x
    if (l == 0) {
      product(level.x, level.t);
    } else {
      multiply(l, level.x, level.t, threads);
    }
    parallel::for_ranges(
        threads, level.t.size(),
        [&](long begin, long end) {
          for (long q = begin; q < end; ++q) level.t[q] = level.r[q] - level.t[q];
        },
        3 * kMgRowsPerThread, 3);
  };
  level.x.setZero();
  smooth(l, level.r, level.x, level.omega, threads);
  residual();
  restrict_to(l, level.t, next.r, threads);
  cycle(l + 1, product, threads);
  prolong_add(l, next.x, level.x, threads);
  residual();
  smooth(l, level.t, level.x, level.omega, threads);
}

void LatticeMultigrid::apply(const Product& product, const VecX& r, VecX& z, int threads) {
  Level& fine = levels_[0];
  fine.r = r;
  cycle(0, product, threads);
  z = fine.x;
}

}  // namespace jelly
