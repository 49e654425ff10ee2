#include "param/partition_points.h"

#include "mesh/errors.h"
#include "param/geodesic_peaks.h"
#include "param/mesh_partition.h"
#include "mesh/mesh_topology.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <string>
#include <tuple>

namespace geomip {
namespace {

const char* const kFn = "choose_partition_points: ";

int he_from(const TriMesh& m, int h) {
  return m.triangles[h / 3][h % 3];
}
int he_to(const TriMesh& m, int h) {
  return m.triangles[h / 3][(h + 1) % 3];
}

// Opposite half-edge of each half-edge (h = 3·f + k runs from corner k to corner k+1 of triangle f) of a
// closed, consistently oriented mesh; partition_mesh() has already checked that.
std::vector<int> opposite_halfedges(const TriMesh& m) {
  const int nv = static_cast<int>(m.positions.size());
  const int nh = static_cast<int>(3 * m.triangles.size());
  std::vector<int> begin(nv + 1, 0), out(nh);
  for (int h = 0; h < nh; ++h) ++begin[he_from(m, h) + 1];
  std::partial_sum(begin.begin(), begin.end(), begin.begin());
  std::vector<int> fill(begin.begin(), begin.end() - 1);
  for (int h = 0; h < nh; ++h) out[fill[he_from(m, h)]++] = h;
  std::vector<int> opp(nh, -1);
  for (int h = 0; h < nh; ++h) {
    const int a = he_from(m, h), b = he_to(m, h);
    for (int i = begin[b]; i < begin[b + 1]; ++i) {
      if (he_to(m, out[i]) == a) opp[h] = out[i];
    }
    if (opp[h] < 0) throw InvalidInput(std::string(kFn) + "the mesh is not closed and consistently oriented");
  }
  return opp;
}

Eigen::Vector3d face_normal(const TriMesh& m, int f) {  // length = 2 × area
  const auto& t = m.triangles[f];
  return (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]);
}

// ---------------------------------------------------------------------------------------------- genus 0

// The longest closed curve where the plane {x·n = offset} cuts the mesh, as the ordered crossing edges
// (one half-edge each), oriented CCW around n. Vertices with x·n <= offset count as below the plane.
struct Outline {
  std::vector<int> vertex;             // per crossing edge: its endpoint nearer to the plane
  std::vector<Eigen::Vector3d> point;  // per crossing edge: where it crosses the plane
  std::vector<double> arc;             // arc length from entry 0 to entry k
  double length = 0.0;
};

Outline longest_outline(const TriMesh& m, const std::vector<int>& opp, const Eigen::Vector3d& n,
                        const Eigen::Vector3d& a, const Eigen::Vector3d& b, double offset) {
  const int nh = static_cast<int>(opp.size());
  auto height = [&](int v) { return m.positions[v].dot(n) - offset; };
  auto crosses = [&](int h) { return (height(he_from(m, h)) <= 0.0) != (height(he_to(m, h)) <= 0.0); };
  std::vector<char> visited(nh, 0);
  Outline best;
  for (int h0 = 0; h0 < nh; ++h0) {
    if (visited[h0] || !crosses(h0)) continue;
    Outline o;
    int h = h0;
    do {  // enter the face of h through h, leave through its other crossing edge
      visited[h] = visited[opp[h]] = 1;
      const int u = he_from(m, h), v = he_to(m, h);
      const double su = height(u), sv = height(v);
      o.vertex.push_back(std::abs(su) <= std::abs(sv) ? u : v);
      o.point.push_back(m.positions[u] + su / (su - sv) * (m.positions[v] - m.positions[u]));
      int next = -1;
      for (int k = 0; k < 3; ++k) {
        const int g = 3 * (h / 3) + k;
        if (g != h && crosses(g)) next = g;
      }
      h = opp[next];
    } while (h != h0);
    double area2 = 0.0;
    for (std::size_t k = 0; k < o.point.size(); ++k) {
      const Eigen::Vector3d& p = o.point[k];
      const Eigen::Vector3d& q = o.point[(k + 1) % o.point.size()];
      o.length += (q - p).norm();
      area2 += p.dot(a) * q.dot(b) - q.dot(a) * p.dot(b);
    }
    if (o.length <= best.length) continue;
    if (area2 < 0.0) {
      std::reverse(o.vertex.begin(), o.vertex.end());
      std::reverse(o.point.begin(), o.point.end());
    }
    best = std::move(o);
  }
  best.arc.assign(best.point.size(), 0.0);
  for (std::size_t k = 1; k < best.point.size(); ++k) {
    best.arc[k] = best.arc[k - 1] + (best.point[k] - best.point[k - 1]).norm();
  }
  return best;
}

// Corners at the outline's extremes in +a, +b, −a, −b (or, if those are not in that order along it, at
// quarters of its length from the +a extreme), auxiliary points half way along the outline between them.
PartitionPoints outline_points(const TriMesh& m, const std::vector<int>& opp, const Eigen::Vector3d& n,
                               const Eigen::Vector3d& a, const Eigen::Vector3d& b, double offset) {
  const Outline o = longest_outline(m, opp, n, a, b, offset);
  const int count = static_cast<int>(o.vertex.size());
  PartitionPoints pts;
  if (count < 4) return pts;
  std::array<int, 4> at;  // outline entries of the corners
  const std::array<Eigen::Vector3d, 4> dirs = {a, b, -a, -b};
  for (int k = 0; k < 4; ++k) {
    at[k] = 0;
    for (int i = 1; i < count; ++i) {
      if (m.positions[o.vertex[i]].dot(dirs[k]) > m.positions[o.vertex[at[k]]].dot(dirs[k])) at[k] = i;
    }
  }
  auto ahead = [&](int from, int to) { return (to - from + count) % count; };
  if (!(ahead(at[0], at[1]) < ahead(at[0], at[2]) && ahead(at[0], at[2]) < ahead(at[0], at[3]) &&
        ahead(at[0], at[1]) > 0)) {
    for (int k = 1; k < 4; ++k) {  // quarters of the length from the +a extreme
      const double target = std::fmod(o.arc[at[0]] + k * o.length / 4.0, o.length);
      at[k] = static_cast<int>(std::lower_bound(o.arc.begin(), o.arc.end(), target) - o.arc.begin()) % count;
    }
  }
  auto distinct = [&](int v) {
    return std::find(pts.partition_points.begin(), pts.partition_points.end(), v) ==
               pts.partition_points.end() &&
           std::find(pts.auxiliary_points.begin(), pts.auxiliary_points.end(), v) ==
               pts.auxiliary_points.end();
  };
  for (int k = 0; k < 4; ++k) {
    if (!distinct(o.vertex[at[k]])) break;
    pts.partition_points.push_back(o.vertex[at[k]]);
  }
  if (pts.partition_points.size() < 4) {
    // Coarse mesh: neighbouring entries share vertices. Spread the corners over the outline's distinct
    // vertices, in order from the +a extreme, and let the paths go unguided.
    std::vector<int> ring;
    for (int i = 0; i < count; ++i) {
      const int v = o.vertex[(at[0] + i) % count];
      if (std::find(ring.begin(), ring.end(), v) == ring.end()) ring.push_back(v);
    }
    pts.partition_points.clear();
    if (ring.size() < 4) return pts;
    for (std::size_t k = 0; k < 4; ++k) pts.partition_points.push_back(ring[k * ring.size() / 4]);
    return pts;
  }
  for (int k = 0; k < 4; ++k) {
    // Entry half way (by arc length) from corner k to corner k+1, or the nearest entry between them whose
    // vertex is still free.
    const int first = at[k], span = ahead(first, at[(k + 1) % 4]);
    const double start = o.arc[first];
    double len = o.arc[at[(k + 1) % 4]] - start;
    if (len <= 0.0) len += o.length;
    int mid = 0;
    for (int i = 1; i < span; ++i) {
      const double along = std::fmod(o.arc[(first + i) % count] - start + o.length, o.length);
      if (along <= 0.5 * len) mid = i;
    }
    int chosen = -1;
    for (int d = 0; d < span && chosen < 0; ++d) {
      for (int i : {mid + d, mid - d}) {
        if (i > 0 && i < span && distinct(o.vertex[(first + i) % count])) {
          chosen = o.vertex[(first + i) % count];
          break;
        }
      }
    }
    if (chosen < 0) {  // too short an arc for a guide: let the paths go freely
      pts.auxiliary_points.clear();
      return pts;
    }
    pts.auxiliary_points.push_back(chosen);
  }
  return pts;
}

// Tips: vertices at the end of protrusions, found as the prominent peaks of the geodesic distance d from
// the outline (multi-source Dijkstra over the edges). Vertices are added in decreasing d; a vertex with no
// added neighbour starts a component (its peak); where components meet, all but the one with the highest
// peak end, with prominence d(peak) − d(meeting vertex) (0-dimensional persistence of the superlevel sets).
// The highest peak has prominence d(peak). Returned: peaks of prominence >= min_prominence, most prominent
// first, at most max_tips, with d and the outline entry nearest to each vertex (its foot).
struct Tips {
  std::vector<int> vertex;
  std::vector<double> prominence;
  std::vector<double> dist;  // per mesh vertex
  std::vector<int> foot;     // per mesh vertex: outline entry
};

// The corners' split of the loop may miss quarters by loop / kCornerSlack.
const double kCornerSlack = 16.0;

// tube_ratio: largest area / depth² half way down a tip's protrusion (PartitionPointsOptions::tube_ratio).
Tips find_tips(const TriMesh& m, const Outline& o, double min_prominence, int max_tips, double tube_ratio) {
  const int nv = static_cast<int>(m.positions.size());
  const std::vector<std::vector<int>> adj = vertex_neighbours(m);
  Tips tips;
  GeodesicDistance g = geodesic_distance(m, adj, o.vertex);
  tips.dist = std::move(g.dist);
  tips.foot = std::move(g.nearest);
  std::vector<std::pair<double, int>> peaks = persistent_peaks(adj, tips.dist);  // (prominence, peak vertex)
  std::sort(peaks.begin(), peaks.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  // A protrusion is a tube: half way down from its tip, the part above has an area of about its girth times
  // that depth. The deepest point of a rounded half (a dome, the middle of a face) has a cap there instead,
  // of area about π·depth²; those are not protrusions.
  std::vector<double> vertex_area(nv, 0.0);
  for (const auto& t : m.triangles) {
    const double a = (m.positions[t[1]] - m.positions[t[0]]).cross(m.positions[t[2]] - m.positions[t[0]]).norm() / 6.0;
    for (int v : t) vertex_area[v] += a;
  }
  std::vector<int> seen(nv, -1), stack;
  for (const auto& [prominence, v] : peaks) {
    if (prominence < min_prominence || static_cast<int>(tips.vertex.size()) >= max_tips) break;
    const double depth = 0.5 * prominence, level = tips.dist[v] - depth;
    double area = 0.0;
    stack.assign(1, v);
    seen[v] = v;
    while (!stack.empty()) {
      const int w = stack.back();
      stack.pop_back();
      area += vertex_area[w];
      for (int u : adj[w]) {
        if (seen[u] != v && tips.dist[u] >= level) {
          seen[u] = v;
          stack.push_back(u);
        }
      }
    }
    if (area > tube_ratio * depth * depth) continue;
    tips.vertex.push_back(v);
    tips.prominence.push_back(prominence);
  }
  return tips;
}

// The outline `o` rerouted through the tips of the shape's protrusions: the loop follows the outline from
// entry `start` (the +a extreme) through guides spaced o.length / outline_guides apart, and at the outline
// entry nearest to a tip it runs down to the tip and back up another way, which splits the protrusion
// lengthwise between the two patches. Corners: see below. Empty when there is no tip or the loop does not
// partition.
PartitionPoints tip_loop_points(const TriMesh& m, const Outline& o, int start,
                                const PartitionPointsOptions& options, double total_area) {
  PartitionPoints none;
  const int count = static_cast<int>(o.vertex.size());
  if (count < 16 || !options.tip_loop) return none;
  const Tips tips =
      find_tips(m, o, options.tip_prominence * std::sqrt(total_area), options.max_tips, options.tube_ratio);
  if (tips.vertex.empty()) return none;
  // Waypoints in loop order, starting at the +a extreme: (position along the outline, vertex, is a tip).
  struct Way {
    double along;  // arc length along the outline from entry `start` (a tip: that of its foot)
    int vertex;
    bool tip;
    double extra;  // a tip: estimated length of its detour (twice its distance from the outline); else 0
  };
  std::vector<Way> ways;
  auto along = [&](int entry) { return std::fmod(o.arc[entry] - o.arc[start] + 2.0 * o.length, o.length); };
  std::vector<char> used(m.positions.size(), 0);
  const int samples = std::max(4, options.outline_guides);
  int next = 0;
  for (int i = 0; i < count; ++i) {
    const int entry = (start + i) % count;
    const double a = along(entry);
    if (a + 1e-12 < next * o.length / samples) continue;
    while (next * o.length / samples <= a + 1e-12) ++next;
    const int v = o.vertex[entry];
    if (used[v]) continue;
    used[v] = 1;
    ways.push_back({a, v, false, 0.0});
  }
  for (std::size_t k = 0; k < tips.vertex.size(); ++k) {
    const int v = tips.vertex[k];
    if (used[v]) continue;
    used[v] = 1;
    ways.push_back({along(tips.foot[v]) + 1e-9 * (1 + k), v, true, 2.0 * tips.dist[v]});
  }
  std::stable_sort(ways.begin(), ways.end(), [](const Way& a, const Way& b) { return a.along < b.along; });
  // Estimated loop length at each waypoint: outline arc plus the detours before it (a tip is half way down
  // its own detour).
  const std::size_t nw = ways.size();
  std::vector<double> at_length(nw);
  double detours = 0.0;
  for (std::size_t i = 0; i < nw; ++i) {
    at_length[i] = ways[i].along + detours + 0.5 * ways[i].extra;
    detours += ways[i].extra;
  }
  const double loop = o.length + detours;
  // Corners: the 4 waypoints that split the loop into quarters within loop / 16 each, with as many tips among
  // them as possible (a corner turns the boundary by 90° in the square, which a protrusion's U-turn at its
  // tip needs), the evenest split among those; if no 4 waypoints are that even, the evenest split.
  std::array<std::size_t, 4> corner = {0, 0, 0, 0};
  const double tolerance = loop / kCornerSlack;
  // Smaller is better: even splits first, then more tips among the even ones, then the evener split.
  auto rank = [&](double score, int tip_count) {
    const bool even = score <= tolerance;
    return std::make_tuple(!even, even ? -tip_count : 0, score);
  };
  int best_tips = -1;
  double best_score = std::numeric_limits<double>::infinity();
  for (std::size_t i0 = 0; i0 < nw; ++i0) {
    for (std::size_t i1 = i0 + 1; i1 < nw; ++i1) {
      const double g0 = std::abs(at_length[i1] - at_length[i0] - 0.25 * loop);
      if (g0 > std::max(tolerance, best_score) && best_tips >= 0) continue;
      for (std::size_t i2 = i1 + 1; i2 < nw; ++i2) {
        const double g1 = std::abs(at_length[i2] - at_length[i1] - 0.25 * loop);
        if (std::max(g0, g1) > std::max(tolerance, best_score) && best_tips >= 0) continue;
        for (std::size_t i3 = i2 + 1; i3 < nw; ++i3) {
          const double score = std::max({g0, g1, std::abs(at_length[i3] - at_length[i2] - 0.25 * loop),
                                         std::abs(at_length[i0] + loop - at_length[i3] - 0.25 * loop)});
          const int tip_count = ways[i0].tip + ways[i1].tip + ways[i2].tip + ways[i3].tip;
          if (best_tips < 0 || rank(score, tip_count) < rank(best_score, best_tips)) {
            best_tips = tip_count;
            best_score = score;
            corner = {i0, i1, i2, i3};
          }
        }
      }
    }
  }
  if (best_tips < 0) return none;
  PartitionPoints pts;
  pts.side_guides.assign(4, {});
  for (int k = 0; k < 4; ++k) {
    pts.partition_points.push_back(ways[corner[k]].vertex);
    for (std::size_t i = (corner[k] + 1) % nw; i != corner[(k + 1) % 4]; i = (i + 1) % nw) {
      pts.side_guides[k].push_back(ways[i].vertex);
    }
  }
  try {
    partition_mesh_guided(m, pts.partition_points, pts.side_guides);
  } catch (const Error&) {
    return none;
  }
  return pts;
}

PartitionPoints genus0_points(const TriMesh& m, const PartitionPointsOptions& options) {
  const int nf = static_cast<int>(m.triangles.size());
  std::vector<double> area(nf);
  std::vector<Eigen::Vector3d> centroid(nf);
  double total = 0.0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int f = 0; f < nf; ++f) {
    const auto& t = m.triangles[f];
    area[f] = 0.5 * face_normal(m, f).norm();
    centroid[f] = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.0;
    total += area[f];
    c += area[f] * centroid[f];
  }
  c /= total;
  // ∫ (x−c)(x−c)ᵀ dA over a triangle = A/12 · (Σ dᵢdᵢᵀ + (Σ dᵢ)(Σ dᵢ)ᵀ), dᵢ = corner − c.
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int f = 0; f < nf; ++f) {
    const auto& t = m.triangles[f];
    Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = m.positions[t[k]] - c;
      s += d * d.transpose();
      sum += d;
    }
    cov += area[f] / 12.0 * (s + sum * sum.transpose());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d e1 = eig.eigenvectors().col(2), e2 = eig.eigenvectors().col(1);
  const Eigen::Vector3d e3 = e1.cross(e2);
  // (normal, a, b) with a × b = normal: thinnest direction first.
  std::vector<std::array<Eigen::Vector3d, 3>> planes = {{e3, e1, e2}, {e2, e3, e1}, {e1, e2, e3}};
  // The plane with normal e_cut_axis first, the others thinnest first.
  const int first = 3 - options.cut_axis;
  std::rotate(planes.begin(), planes.begin() + first, planes.begin() + first + 1);

  const std::vector<int> opp = opposite_halfedges(m);
  std::vector<int> order(nf);
  std::string failures;
  for (const auto& [n, a, b] : planes) {
    // Area median along n.
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](int f, int g) { return centroid[f].dot(n) < centroid[g].dot(n); });
    double acc = 0.0, offset = centroid[order.back()].dot(n);
    for (int f : order) {
      acc += area[f];
      if (acc >= 0.5 * total) {
        offset = centroid[f].dot(n);
        break;
      }
    }
    const PartitionPoints pts = outline_points(m, opp, n, a, b, offset);
    if (pts.partition_points.size() != 4) {
      failures += " an outline with fewer than 4 vertices;";
      continue;
    }
    try {
      partition_mesh(m, pts.partition_points, pts.auxiliary_points);
      if (options.tip_loop) {
        const Outline o = longest_outline(m, opp, n, a, b, offset);
        const auto start = std::find(o.vertex.begin(), o.vertex.end(), pts.partition_points[0]);
        if (start != o.vertex.end()) {
          PartitionPoints tipped = tip_loop_points(m, o, static_cast<int>(start - o.vertex.begin()), options, total);
          if (!tipped.partition_points.empty()) return tipped;
        }
      }
      return pts;
    } catch (const Error& e) {
      failures += std::string(" ") + e.what() + ";";
    }
  }
  // Last resort (a handful of triangles): the vertices extreme in ±a, ±b of the first plane.
  PartitionPoints pts;
  const Eigen::Vector3d a0 = planes.front()[1], b0 = planes.front()[2];
  for (const Eigen::Vector3d& dir : {a0, b0, Eigen::Vector3d(-a0), Eigen::Vector3d(-b0)}) {
    int best = -1;
    for (const auto& t : m.triangles) {
      for (int v : t) {
        const auto& chosen = pts.partition_points;
        if (std::find(chosen.begin(), chosen.end(), v) != chosen.end()) continue;
        if (best < 0 || m.positions[v].dot(dir) > m.positions[best].dot(dir)) best = v;
      }
    }
    pts.partition_points.push_back(best);
  }
  try {
    partition_mesh(m, pts.partition_points, {});
    return pts;
  } catch (const Error& e) {
    failures += std::string(" extreme vertices: ") + e.what() + ";";
  }
  throw SolverFailure(std::string(kFn) + "no principal plane gave a valid loop:" + failures);
}

// ---------------------------------------------------------------------------------------------- genus 1

// Flat-torus coordinates θ ∈ R²/Z² of each vertex from two harmonic 1-forms (see the header), and the flat
// metric in those coordinates (the inverse Gram matrix of the forms).
struct FlatTorus {
  std::vector<Eigen::Vector2d> theta;  // per vertex, unreferenced vertices: NaN
  Eigen::Matrix2d metric;
};

FlatTorus flat_torus(const TriMesh& m) {
  const int nv = static_cast<int>(m.positions.size());
  const int nf = static_cast<int>(m.triangles.size());
  const int nh = 3 * nf;
  const std::vector<int> opp = opposite_halfedges(m);
  std::vector<std::vector<int>> out(nv);
  for (int h = 0; h < nh; ++h) out[he_from(m, h)].push_back(h);

  // Tree–cotree: BFS tree of vertices, BFS tree of faces across the other edges, the rest generate homology.
  const int root = m.triangles[0][0];
  std::vector<int> parent_he(nv, -1), vorder = {root};
  std::vector<char> seen(nv, 0), in_tree(nh, 0);
  seen[root] = 1;
  for (std::size_t i = 0; i < vorder.size(); ++i) {
    for (int h : out[vorder[i]]) {
      const int u = he_to(m, h);
      if (seen[u]) continue;
      seen[u] = 1;
      parent_he[u] = h;
      in_tree[h] = in_tree[opp[h]] = 1;
      vorder.push_back(u);
    }
  }
  std::vector<int> fparent_he(nf, -1), forder = {0};  // half-edge of the face on the edge to its parent
  std::vector<char> fseen(nf, 0), in_cotree(nh, 0);
  fseen[0] = 1;
  for (std::size_t i = 0; i < forder.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const int h = 3 * forder[i] + k;
      const int g = opp[h] / 3;
      if (in_tree[h] || fseen[g]) continue;
      fseen[g] = 1;
      fparent_he[g] = opp[h];
      in_cotree[h] = in_cotree[opp[h]] = 1;
      forder.push_back(g);
    }
  }
  std::vector<int> generators;
  for (int h = 0; h < nh; ++h) {
    if (h < opp[h] && !in_tree[h] && !in_cotree[h]) generators.push_back(h);
  }
  if (generators.size() != 2) {
    throw SolverFailure(std::string(kFn) + "tree-cotree found " + std::to_string(generators.size()) +
                        " generators on a genus-1 mesh instead of 2");
  }

  // Closed 1-forms ω_i: δ_ij on generator j, 0 on the tree, cotree edges from face closure, leaves first.
  std::array<std::vector<double>, 2> omega;
  for (int i = 0; i < 2; ++i) {
    auto& w = omega[i];
    w.assign(nh, 0.0);
    w[generators[i]] = 1.0;
    w[opp[generators[i]]] = -1.0;
    for (auto it = forder.rbegin(); it != forder.rend(); ++it) {
      const int hp = fparent_he[*it];
      if (hp < 0) continue;
      double rest = 0.0;
      for (int k = 0; k < 3; ++k) {
        if (3 * *it + k != hp) rest += w[3 * *it + k];
      }
      w[hp] = -rest;
      w[opp[hp]] = rest;
    }
  }

  // Cotangent weights per half-edge (half the cotangent of the angle opposite it; an edge's weight is the
  // sum).
  std::vector<double> cot(nh);
  for (int h = 0; h < nh; ++h) {
    const auto& t = m.triangles[h / 3];
    const Eigen::Vector3d& o = m.positions[t[(h % 3 + 2) % 3]];
    const Eigen::Vector3d a = m.positions[he_from(m, h)] - o, b = m.positions[he_to(m, h)] - o;
    cot[h] = 0.5 * a.dot(b) / std::max(a.cross(b).norm(), std::numeric_limits<double>::min());
  }
  auto weight = [&](int h) { return cot[h] + cot[opp[h]]; };

  // Harmonic parts η_i = ω_i − d f_i with L f_i = −δω_i; root pinned (f = 0).
  std::vector<int> index(nv, -1);
  int n = 0;
  for (int v : vorder) {
    if (v != root) index[v] = n++;
  }
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 2);
  for (int h = 0; h < nh; ++h) {
    const int a = index[he_from(m, h)], b = index[he_to(m, h)];
    if (a < 0) continue;
    const double w = weight(h);
    triplets.emplace_back(a, a, w);
    if (b >= 0) triplets.emplace_back(a, b, -w);
    for (int i = 0; i < 2; ++i) rhs(a, i) -= w * omega[i][h];
  }
  Eigen::SparseMatrix<double> lap(n, n);
  lap.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(lap);
  if (solver.info() != Eigen::Success)
    throw SolverFailure(std::string(kFn) + "cotangent Laplacian is singular");
  const Eigen::MatrixXd f = solver.solve(rhs);
  auto potential = [&](int v, int i) { return index[v] < 0 ? 0.0 : f(index[v], i); };
  std::array<std::vector<double>, 2> eta = omega;
  for (int i = 0; i < 2; ++i) {
    for (int h = 0; h < nh; ++h) eta[i][h] -= potential(he_to(m, h), i) - potential(he_from(m, h), i);
  }

  // Gram matrix (Dirichlet inner products) and Gauss reduction of the basis (integer unimodular changes keep
  // the periods integral).
  Eigen::Matrix2d gram = Eigen::Matrix2d::Zero();
  for (int h = 0; h < nh; ++h) {
    if (h > opp[h]) continue;
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) gram(i, j) += weight(h) * eta[i][h] * eta[j][h];
    }
  }
  Eigen::Matrix2d basis = Eigen::Matrix2d::Identity();  // rows: reduced forms in terms of η
  for (int iter = 0; iter < 64; ++iter) {
    if (gram(0, 0) > gram(1, 1)) {
      std::swap(gram(0, 0), gram(1, 1));
      basis.row(0).swap(basis.row(1));
    }
    const double mu = std::round(gram(0, 1) / gram(0, 0));
    if (mu == 0.0) break;
    // form1 -= mu·form0
    gram(1, 1) += mu * mu * gram(0, 0) - 2.0 * mu * gram(0, 1);
    gram(0, 1) -= mu * gram(0, 0);
    gram(1, 0) = gram(0, 1);
    basis.row(1) -= mu * basis.row(0);
  }

  FlatTorus torus;
  torus.theta.assign(nv, Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN()));
  torus.theta[root] = Eigen::Vector2d::Zero();
  for (std::size_t i = 1; i < vorder.size(); ++i) {
    const int v = vorder[i], h = parent_he[v];
    const Eigen::Vector2d step(eta[0][h], eta[1][h]);
    torus.theta[v] = torus.theta[he_from(m, h)] + basis * step;
  }
  torus.metric = gram.inverse();
  return torus;
}

PartitionPoints genus1_points(const TriMesh& m, const PartitionPointsOptions& options) {
  const FlatTorus torus = flat_torus(m);
  const int nv = static_cast<int>(m.positions.size());
  const int nf = static_cast<int>(m.triangles.size());
  auto wrap = [](double x) { return x - std::floor(x); };

  // Area and flat coordinates (mod 1) of each triangle's centroid.
  std::vector<double> area(nf);
  std::vector<Eigen::Vector2d> centre(nf);
  double total = 0.0;
  for (int f = 0; f < nf; ++f) {
    const auto& t = m.triangles[f];
    area[f] = 0.5 * face_normal(m, f).norm();
    total += area[f];
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int k = 1; k < 3; ++k) {
      Eigen::Vector2d d = torus.theta[t[k]] - torus.theta[t[0]];
      for (int i = 0; i < 2; ++i) d[i] -= std::round(d[i]);
      sum += d;
    }
    const Eigen::Vector2d c = torus.theta[t[0]] + sum / 3.0;
    centre[f] = Eigen::Vector2d(wrap(c.x()), wrap(c.y()));
  }
  // Per direction: triangles sorted by coordinate, with cumulative areas, to find area-halving bands.
  std::array<std::vector<double>, 2> coord, cumulative;
  for (int i = 0; i < 2; ++i) {
    std::vector<int> order(nf);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int f, int g) { return centre[f][i] < centre[g][i]; });
    double acc = 0.0;
    for (int f : order) {
      coord[i].push_back(centre[f][i]);
      acc += area[f];
      cumulative[i].push_back(acc);
    }
  }
  // Width s of the band [o, o+s) (mod 1) that holds half of the area.
  auto half_band = [&](int i, double o) {
    const std::size_t k0 = std::lower_bound(coord[i].begin(), coord[i].end(), o) - coord[i].begin();
    double target = (k0 > 0 ? cumulative[i][k0 - 1] : 0.0) + 0.5 * total;
    if (target > total) target -= total;
    const std::size_t k = std::min<std::size_t>(
        std::lower_bound(cumulative[i].begin(), cumulative[i].end(), target) - cumulative[i].begin(),
        coord[i].size() - 1);
    const double s = wrap(coord[i][k] - o);
    return std::clamp(s, 0.05, 0.95);
  };

  // Candidate grids: offsets o on a steps × steps lattice, band widths s halving the area in each direction;
  // predicted balance from the triangles' flat coordinates.
  struct Candidate {
    double predicted;
    Eigen::Vector2d o, s;
  };
  std::vector<Candidate> candidates;
  const int steps = std::max(1, options.offset_steps);
  for (int a = 0; a < steps; ++a) {
    for (int b = 0; b < steps; ++b) {
      const Eigen::Vector2d o(double(a) / steps, double(b) / steps);
      const Eigen::Vector2d s(half_band(0, o.x()), half_band(1, o.y()));
      std::array<double, 4> quad = {0, 0, 0, 0};
      for (int f = 0; f < nf; ++f) {
        quad[2 * (wrap(centre[f].x() - o.x()) >= s.x()) + (wrap(centre[f].y() - o.y()) >= s.y())] += area[f];
      }
      const auto [lo, hi] = std::minmax_element(quad.begin(), quad.end());
      candidates.push_back({*lo / *hi, o, s});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.predicted > y.predicted; });

  auto nearest = [&](const Eigen::Vector2d& target) {
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (int v = 0; v < nv; ++v) {
      if (std::isnan(torus.theta[v].x())) continue;
      Eigen::Vector2d d = torus.theta[v] - target;
      for (int i = 0; i < 2; ++i) d[i] -= std::round(d[i]);
      const double dist = d.dot(torus.metric * d);
      if (dist < best_d) {
        best_d = dist;
        best = v;
      }
    }
    return best;
  };
  PartitionPoints best;
  double best_balance = -1.0;
  int successes = 0;
  std::string last_failure;
  for (const Candidate& c : candidates) {
    if (successes >= std::max(1, options.tries)) break;
    // Corners at o + {0, s} per direction; auxiliary points at the middle of each grid edge, in
    // partition_mesh()'s order e0..e7.
    const double x0 = c.o.x(), x1 = x0 + c.s.x(), y0 = c.o.y(), y1 = y0 + c.s.y();
    const double xm0 = x0 + 0.5 * c.s.x(), xm1 = x1 + 0.5 * (1.0 - c.s.x());
    const double ym0 = y0 + 0.5 * c.s.y(), ym1 = y1 + 0.5 * (1.0 - c.s.y());
    const std::array<Eigen::Vector2d, 12> targets = {
        Eigen::Vector2d(x0, y0),  Eigen::Vector2d(x1, y0),  Eigen::Vector2d(x0, y1),
        Eigen::Vector2d(x1, y1),  Eigen::Vector2d(xm0, y0), Eigen::Vector2d(xm1, y0),
        Eigen::Vector2d(xm0, y1), Eigen::Vector2d(xm1, y1), Eigen::Vector2d(x0, ym0),
        Eigen::Vector2d(x0, ym1), Eigen::Vector2d(x1, ym0), Eigen::Vector2d(x1, ym1)};
    PartitionPoints pts;
    for (int k = 0; k < 12; ++k)
      (k < 4 ? pts.partition_points : pts.auxiliary_points).push_back(nearest(targets[k]));
    try {
      const double balance =
          partition_stats(partition_mesh(m, pts.partition_points, pts.auxiliary_points)).area_balance;
      ++successes;
      if (balance > best_balance) {
        best_balance = balance;
        best = pts;
      }
    } catch (const Error& e) {
      last_failure = e.what();
    }
  }
  if (best_balance < 0.0) {
    throw SolverFailure(std::string(kFn) +
                        "no placement on the flat torus partitioned the mesh (last: " + last_failure + ")");
  }
  return best;
}

}  // namespace

PartitionPoints choose_partition_points(const TriMesh& closed_manifold,
                                        const PartitionPointsOptions& options) {
  const TopologyReport topo = analyze_topology(closed_manifold);
  if (!topo.manifold || topo.boundary_edges > 0 || topo.components != 1 || topo.degenerate_faces > 0 ||
      !topo.genus) {
    throw InvalidInput(std::string(kFn) +
                       "the mesh must be one closed, manifold, orientable component without degenerate "
                       "triangles; run repair_mesh first");
  }
  if (options.cut_axis < 1 || options.cut_axis > 3) {
    throw InvalidInput(std::string(kFn) + "cut_axis must be 1, 2 or 3, got " +
                       std::to_string(options.cut_axis));
  }
  if (options.tip_loop && (!(options.tube_ratio > 0) || !std::isfinite(options.tube_ratio) ||
                           !(options.tip_prominence >= 0) || !std::isfinite(options.tip_prominence))) {
    throw InvalidInput(std::string(kFn) + "tube_ratio must be a positive number and tip_prominence >= 0");
  }
  if (*topo.genus == 0) return genus0_points(closed_manifold, options);
  if (*topo.genus == 1) return genus1_points(closed_manifold, options);
  throw InvalidInput(std::string(kFn) + "the mesh has genus " + std::to_string(*topo.genus) +
                     "; only genus 0 and 1 are supported");
}

}  // namespace geomip
