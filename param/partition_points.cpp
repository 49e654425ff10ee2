#include "param/partition_points.h"

#include "param/errors.h"
#include "param/mesh_partition.h"
#include "param/mesh_topology.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace geomip {
namespace {

const char* const kFn = "choose_partition_points: ";

int he_from(const TriMesh& m, int h) { return m.triangles[h / 3][h % 3]; }
int he_to(const TriMesh& m, int h) { return m.triangles[h / 3][(h + 1) % 3]; }

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

PartitionPoints genus0_points(const TriMesh& m) {
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
  const std::array<std::array<Eigen::Vector3d, 3>, 3> planes = {{{e3, e1, e2}, {e2, e3, e1}, {e1, e2, e3}}};

  std::vector<int> order(nf);
  std::string failures;
  for (const auto& [n, a, b] : planes) {
    // Area median along n.
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int f, int g) { return centroid[f].dot(n) < centroid[g].dot(n); });
    double acc = 0.0, offset = centroid[order.back()].dot(n);
    for (int f : order) {
      acc += area[f];
      if (acc >= 0.5 * total) {
        offset = centroid[f].dot(n);
        break;
      }
    }
    // Section vertices: of each edge crossing the plane, the endpoint nearer to it.
    std::vector<int> section;
    for (int h = 0; h < 3 * nf; ++h) {
      const int u = he_from(m, h), v = he_to(m, h);
      if (u > v) continue;  // each edge of a closed mesh has both directions: take one
      const double su = m.positions[u].dot(n) - offset, sv = m.positions[v].dot(n) - offset;
      if ((su <= 0.0) != (sv <= 0.0)) section.push_back(std::abs(su) <= std::abs(sv) ? u : v);
    }
    std::sort(section.begin(), section.end());
    section.erase(std::unique(section.begin(), section.end()), section.end());
    PartitionPoints pts;
    for (const Eigen::Vector3d& dir : {a, b, Eigen::Vector3d(-a), Eigen::Vector3d(-b)}) {
      int best = -1;
      for (int v : section) {
        if (std::find(pts.partition_points.begin(), pts.partition_points.end(), v) != pts.partition_points.end()) {
          continue;
        }
        if (best < 0 || m.positions[v].dot(dir) > m.positions[best].dot(dir)) best = v;
      }
      if (best >= 0) pts.partition_points.push_back(best);
    }
    if (pts.partition_points.size() != 4) continue;
    try {
      partition_mesh(m, pts.partition_points, {});
      return pts;
    } catch (const Error& e) {
      failures += std::string(" ") + e.what() + ";";
    }
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

  // Cotangent weights per half-edge (half the cotangent of the angle opposite it; an edge's weight is the sum).
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
  if (solver.info() != Eigen::Success) throw SolverFailure(std::string(kFn) + "cotangent Laplacian is singular");
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
  // Corners P0..P3, then the midpoints of edges e0..e7 (partition_mesh()'s order), in grid units of ¼.
  const std::array<std::array<int, 2>, 12> targets = {{{0, 0}, {2, 0}, {0, 2}, {2, 2},  // P0..P3
                                                       {1, 0}, {3, 0}, {1, 2}, {3, 2},  // e0..e3
                                                       {0, 1}, {0, 3}, {2, 1}, {2, 3}}};  // e4..e7
  const int steps = std::max(1, options.offsets);
  PartitionPoints best;
  double best_balance = -1.0;
  std::string last_failure;
  for (int i = 0; i < steps; ++i) {
    for (int j = 0; j < steps; ++j) {
      const Eigen::Vector2d offset(0.5 * i / steps, 0.5 * j / steps);
      std::vector<int> ids;
      for (const auto& t : targets) ids.push_back(nearest(offset + 0.25 * Eigen::Vector2d(t[0], t[1])));
      PartitionPoints pts;
      pts.partition_points.assign(ids.begin(), ids.begin() + 4);
      pts.auxiliary_points.assign(ids.begin() + 4, ids.end());
      try {
        const double balance = partition_stats(partition_mesh(m, pts.partition_points, pts.auxiliary_points))
                                   .area_balance;
        if (balance > best_balance) {
          best_balance = balance;
          best = pts;
        }
      } catch (const Error& e) {
        last_failure = e.what();
      }
    }
  }
  if (best_balance < 0.0) {
    throw SolverFailure(std::string(kFn) + "no placement on the flat torus partitioned the mesh (last: " +
                        last_failure + ")");
  }
  return best;
}

}  // namespace

PartitionPoints choose_partition_points(const TriMesh& closed_manifold, const PartitionPointsOptions& options) {
  const TopologyReport topo = analyze_topology(closed_manifold);
  if (!topo.manifold || topo.boundary_edges > 0 || topo.components != 1 || topo.degenerate_faces > 0 ||
      !topo.genus) {
    throw InvalidInput(std::string(kFn) +
                       "the mesh must be one closed, manifold, orientable component without degenerate "
                       "triangles; run repair_mesh first");
  }
  if (*topo.genus == 0) return genus0_points(closed_manifold);
  if (*topo.genus == 1) return genus1_points(closed_manifold, options);
  throw InvalidInput(std::string(kFn) + "the mesh has genus " + std::to_string(*topo.genus) +
                     "; only genus 0 and 1 are supported");
}

}  // namespace geomip
