#include <jelly/solvers/integrators/detail/vertex_colouring.hpp>

#include <algorithm>

namespace jelly {

int VertexColouring::largest_colour() const {
  int largest = 0;
  for (int c = 0; c < colours(); ++c)
    largest = std::max(largest, colour_start[c + 1] - colour_start[c]);
  return largest;
}

VertexColouring colour_vertices(int num_particles, const Springs& springs) {
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
  // Greedy colouring: `seen[c] == i` marks colour c as taken by a neighbour of particle i.
  std::vector<int> colour(n, -1), seen;
  int colours = 0;
  for (int i = 0; i < n; ++i) {
    for (int e = g.spring_start[i]; e < g.spring_start[i + 1]; ++e) {
      const int c = colour[g.other[e]];
      if (c >= 0) {
        if (c >= static_cast<int>(seen.size())) seen.resize(c + 1, -1);
        seen[c] = i;
      }
    }
    int c = 0;
    while (c < static_cast<int>(seen.size()) && seen[c] == i) ++c;
    colour[i] = c;
    colours = std::max(colours, c + 1);
  }
  g.colour_start.assign(colours + 1, 0);
  for (int i = 0; i < n; ++i) ++g.colour_start[colour[i] + 1];
  for (int c = 0; c < colours; ++c) g.colour_start[c + 1] += g.colour_start[c];
  g.particles.resize(n);
  std::vector<int> next(g.colour_start.begin(), g.colour_start.end() - 1);
  for (int i = 0; i < n; ++i) g.particles[next[colour[i]]++] = i;
  return g;
}

}  // namespace jelly
