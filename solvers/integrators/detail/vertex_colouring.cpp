#include <jelly/solvers/integrators/detail/vertex_colouring.hpp>

#include <algorithm>
#include <numeric>

namespace jelly {

int VertexColouring::largest_colour() const {
  int largest = 0;
  for (int c = 0; c < colours(); ++c)
    largest = std::max(largest, colour_start[c + 1] - colour_start[c]);
  return largest;
}

int VertexColouring::classes() const {
  int count = 0;
  for (int k : particle_class) count = std::max(count, k + 1);
  return count;
}

namespace {

// One round of colour refinement: each particle's signature is its class and the sorted classes
// of its neighbours (one per spring); the new classes number the distinct signatures in
// lexicographic order, so that they depend on the graph only, not on the numbering of the
// particles. Returns the number of classes.
int refine_classes(const VertexColouring& g, std::vector<int>& particle_class,
                   std::vector<int>& signature, std::vector<int>& order) {
  const int n = static_cast<int>(particle_class.size());
  signature.resize(g.other.size());
  for (int i = 0; i < n; ++i) {
    const int begin = g.spring_start[i], end = g.spring_start[i + 1];
    for (int e = begin; e < end; ++e) signature[e] = particle_class[g.other[e]];
    std::sort(signature.begin() + begin, signature.begin() + end);
  }
  const auto less = [&](int i, int j) {
    if (particle_class[i] != particle_class[j]) return particle_class[i] < particle_class[j];
    return std::lexicographical_compare(
        signature.begin() + g.spring_start[i], signature.begin() + g.spring_start[i + 1],
        signature.begin() + g.spring_start[j], signature.begin() + g.spring_start[j + 1]);
  };
  order.resize(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), less);
  std::vector<int> refined(n);
  int classes = 0;
  for (int p = 0; p < n; ++p) {
    if (p > 0 && less(order[p - 1], order[p])) ++classes;
    refined[order[p]] = classes;
  }
  particle_class.swap(refined);
  return n > 0 ? classes + 1 : 0;
}

}  // namespace

VertexColouring colour_vertices(int num_particles, const Springs& springs, int refinement_rounds) {
  VertexColouring g;
  const int n = num_particles, m = springs.size();
  g.spring_start.assign(n + 1, 0);
  for (int k = 0; k < m; ++k) {
    ++g.spring_start[springs.a[k] + 1];
    ++g.spring_start[springs.b[k] + 1];
  }
  for (int i = 0; i < n; ++i) g.spring_start[i + 1] += g.spring_start[i];
  g.spring.resize(2 * m);
  g.other.resize(2 * m);
  std::vector<int> fill(g.spring_start.begin(), g.spring_start.end() - 1);
  for (int k = 0; k < m; ++k) {
    const int a = springs.a[k], b = springs.b[k];
    g.spring[fill[a]] = k;
    g.other[fill[a]++] = b;
    g.spring[fill[b]] = k;
    g.other[fill[b]++] = a;
  }
  // Classes: refined until a round splits none (the stable partition) or the rounds run out
  // (a coarser partition, as invariant).
  g.particle_class.assign(n, 0);
  std::vector<int> signature, order;
  int classes = n > 0 ? 1 : 0;
  for (int round = 0; round < refinement_rounds; ++round) {
    const int refined = refine_classes(g, g.particle_class, signature, order);
    if (refined == classes) break;
    classes = refined;
  }
  // The members of each class (`order` from the last round lists the particles by class).
  std::vector<int> class_start(classes + 1, 0);
  for (int i = 0; i < n; ++i) ++class_start[g.particle_class[i] + 1];
  for (int k = 0; k < classes; ++k) class_start[k + 1] += class_start[k];
  std::vector<int> members(n);
  {
    std::vector<int> next(class_start.begin(), class_start.end() - 1);
    for (int i = 0; i < n; ++i) members[next[g.particle_class[i]]++] = i;
  }
  // Greedy colours over the classes in their order: each class takes the smallest colour that no
  // neighbour in an earlier class has; `seen[c] == k` marks colour c as taken for class k.
  std::vector<int> class_colour(classes, -1), seen;
  int colours = 0;
  for (int k = 0; k < classes; ++k) {
    for (int p = class_start[k]; p < class_start[k + 1]; ++p) {
      const int i = members[p];
      for (int e = g.spring_start[i]; e < g.spring_start[i + 1]; ++e) {
        const int c = class_colour[g.particle_class[g.other[e]]];
        if (c >= 0) {
          if (c >= static_cast<int>(seen.size())) seen.resize(c + 1, -1);
          seen[c] = k;
        }
      }
    }
    int c = 0;
    while (c < static_cast<int>(seen.size()) && seen[c] == k) ++c;
    class_colour[k] = c;
    colours = std::max(colours, c + 1);
  }
  g.colour_start.assign(colours + 1, 0);
  for (int i = 0; i < n; ++i) ++g.colour_start[class_colour[g.particle_class[i]] + 1];
  for (int c = 0; c < colours; ++c) g.colour_start[c + 1] += g.colour_start[c];
  g.particles.resize(n);
  std::vector<int> next(g.colour_start.begin(), g.colour_start.end() - 1);
  for (int i = 0; i < n; ++i) g.particles[next[class_colour[g.particle_class[i]]]++] = i;
  g.coupled.assign(colours, 0);
  for (int k = 0; k < m; ++k) {
    const int a = springs.a[k], b = springs.b[k];
    if (g.particle_class[a] == g.particle_class[b])
      g.coupled[class_colour[g.particle_class[a]]] = 1;
  }
  return g;
}

}  // namespace jelly
