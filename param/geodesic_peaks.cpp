#include "param/geodesic_peaks.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>

namespace geomip {

std::vector<std::vector<int>> vertex_neighbours(const TriMesh& mesh) {
  std::vector<std::vector<int>> neighbours(mesh.positions.size());
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) neighbours[t[k]].push_back(t[(k + 1) % 3]);
  }
  return neighbours;
}

GeodesicDistance geodesic_distance(const TriMesh& mesh, const std::vector<std::vector<int>>& neighbours,
                                   const std::vector<int>& sources) {
  const std::size_t nv = mesh.positions.size();
  GeodesicDistance g;
  g.dist.assign(nv, std::numeric_limits<double>::infinity());
  g.nearest.assign(nv, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const int v = sources[i];
    if (g.dist[v] > 0.0) {
      g.dist[v] = 0.0;
      g.nearest[v] = static_cast<int>(i);
      heap.push({0.0, v});
    }
  }
  while (!heap.empty()) {
    const auto [d, v] = heap.top();
    heap.pop();
    if (d > g.dist[v]) continue;
    for (int u : neighbours[v]) {
      const double du = d + (mesh.positions[u] - mesh.positions[v]).norm();
      if (du < g.dist[u]) {
        g.dist[u] = du;
        g.nearest[u] = g.nearest[v];
        heap.push({du, u});
      }
    }
  }
  return g;
}

std::vector<std::pair<double, int>> persistent_peaks(const std::vector<std::vector<int>>& neighbours,
                                                     const std::vector<double>& f) {
  const int nv = static_cast<int>(neighbours.size());
  std::vector<int> order;
  for (int v = 0; v < nv; ++v) {
    if (!neighbours[v].empty() && std::isfinite(f[v])) order.push_back(v);
  }
  std::sort(order.begin(), order.end(), [&](int a, int b) { return f[a] != f[b] ? f[a] > f[b] : a < b; });
  std::vector<int> parent(nv, -1), peak(nv, -1);
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  std::vector<std::pair<double, int>> peaks;
  for (int v : order) {
    parent[v] = v;
    peak[v] = v;
    for (int u : neighbours[v]) {
      if (parent[u] < 0) continue;
      const int a = find(u), b = find(v);
      if (a == b) continue;
      const bool a_higher = f[peak[a]] > f[peak[b]] || (f[peak[a]] == f[peak[b]] && peak[a] < peak[b]);
      const int keep = a_higher ? a : b, end = a_higher ? b : a;
      if (peak[end] != v) peaks.push_back({f[peak[end]] - f[v], peak[end]});
      parent[end] = keep;
    }
  }
  if (!order.empty()) peaks.push_back({f[order.front()], order.front()});
  return peaks;
}

}  // namespace geomip
