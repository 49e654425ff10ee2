// Least-squares fitted geometry images (see fit.h). The closest-point queries go through SurfaceQuery
// (surface_distance.cpp holds CGAL); the solve is Eigen's conjugate gradients (sparse LDLT as the fallback).
#include "gimage/fit.h"

#include "gimage/surface_distance.h"
#include "gimage/uniform_remesh.h"
#include "mesh/errors.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <cmath>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

namespace geomip {
namespace {

constexpr const char* kFunction = "fit_geometry_images";
/// Queries per unit of work: fixed chunks, results stored per query and summed in order, so the result does
/// not depend on the number of threads.
constexpr std::size_t kChunk = 4096;
/// Rounds of the flip guard (each halves the offsets of the flipped triangles' vertices) before they are reset.
constexpr int kFlipRounds = 8;
/// The normal equations' solve: conjugate gradients to this residual, relative to the right-hand side (the
/// offsets then agree with an exact solve to far below a float's precision of the samples), in at most this
/// many iterations, else a sparse LDLT.
constexpr double kSolveTolerance = 1e-10;
constexpr int kSolveMaxIterations = 1000;
/// Points on each remesh triangle for the remesh→original direction: Dunavant's 6-point rule (exact for degree 4,
/// i.e. for the square of a quadratic deviation from the plane); barycentric coordinates and weights.
constexpr double kA = 0.445948490915965, kB = 0.091576213509771;
constexpr std::array<std::array<double, 4>, 6> kTriangleRule{{{kA, kA, 1 - 2 * kA, 0.223381589678011},
                                                             {kA, 1 - 2 * kA, kA, 0.223381589678011},
                                                             {1 - 2 * kA, kA, kA, 0.223381589678011},
                                                             {kB, kB, 1 - 2 * kB, 0.109951743655322},
                                                             {kB, 1 - 2 * kB, kB, 0.109951743655322},
                                                             {1 - 2 * kB, kB, kB, 0.109951743655322}}};
/// Metro (and measure_surface_distance()) samples a surface's vertices besides its faces (10 per face by
/// default), each vertex with the weight of a face sample: the vertices' share of the remesh→original average.
constexpr double kMetroFaceSamplesPerTriangle = 10;

/// A point of the remesh, fixed in barycentric coordinates of one triangle, with its weight in the average.
struct RemeshPoint {
  std::size_t triangle = 0;
  std::array<double, 3> b{};
  double weight = 0;
};

[[noreturn]] void fail(const std::string& what) { throw InvalidInput(std::string(kFunction) + ": " + what); }

/// One linearized residual: r = Σ_k coef[k]·δ[vertex[k]] − rhs, weighted.
struct Equation {
  std::size_t triangle = 0;  // index into the active triangles
  std::array<double, 3> coef{};
  double rhs = 0;
  double distance2 = 0;  // squared distance of the sample (for the reported RMS)
};

/// Runs `fn(i)` for i in [0, n) over `threads` threads in fixed chunks. The threads are joined on every
/// way out (if a thread cannot be started, fewer do the work); an exception from `fn` stops the remaining
/// chunks and is rethrown here, so none leaves a worker thread.
template <class Fn>
void parallel_for(std::size_t n, unsigned threads, const Fn& fn) {
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    try {
      for (std::size_t c = next++; c < chunks; c = next++) {
        const std::size_t end = std::min(n, (c + 1) * kChunk);
        for (std::size_t i = c * kChunk; i < end; ++i) fn(i);
      }
    } catch (...) {
      next = chunks;
      const std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
    }
  };
  const unsigned pool = static_cast<unsigned>(std::min<std::size_t>(std::max(1u, threads), chunks));
  std::vector<std::thread> workers;
  workers.reserve(pool);  // before any thread runs: emplace_back below cannot throw bad_alloc
  try {
    for (unsigned t = 1; t < pool; ++t) workers.emplace_back(work);
  } catch (const std::system_error&) {
    // No more threads to be had: the ones started and this one share the chunks.
  }
  work();
  for (auto& w : workers) w.join();
  if (error) std::rethrow_exception(error);
}

Eigen::Vector3d face_normal(const std::vector<Eigen::Vector3d>& x, const std::array<int, 3>& t) {
  return (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
}

/// Barycentric coordinates of q (on or near triangle abc) by sub-triangle areas, clamped to the triangle.
std::array<double, 3> barycentric(const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  double wb = (q - a).cross(c - a).dot(n) / area2, wc = (b - a).cross(q - a).dot(n) / area2;
  wb = std::clamp(wb, 0.0, 1.0);
  wc = std::clamp(wc, 0.0, 1.0 - wb);
  return {1 - wb - wc, wb, wc};
}

void validate(const TriMesh& original, const GeometryImages& images, const FitOptions& options) {
  if (images.geometry.empty()) fail("the images have no patches");
  for (const auto& g : images.geometry) {
    if (g.level != images.geometry.front().level) fail("the patches differ in level");
  }
  if (original.triangles.empty()) fail("the original has no triangles");
  if (options.iterations < 0) fail("iterations " + std::to_string(options.iterations) + " < 0");
  if (!(options.samples_per_triangle > 0)) fail("samples_per_triangle must be > 0");
  if (!(options.smoothness >= 0)) fail("smoothness must be >= 0");
  if (!(options.damping > 0)) fail("damping must be > 0");
  if (!(options.max_offset > 0 && options.max_offset <= 1)) fail("max_offset must be in (0, 1]");
  if (!options.hole_quads.empty()) {
    const int level = images.geometry.front().level;
    const std::size_t quads = std::size_t{1} << (2 * level);
    if (options.hole_quads.size() != images.geometry.size()) fail("the hole mask has the wrong number of patches");
    for (const auto& q : options.hole_quads) {
      if (q.size() != quads) fail("a hole mask patch has the wrong number of quads");
    }
  }
}

}  // namespace

FitResult fit_geometry_images(const TriMesh& original, const GeometryImages& images, const FitOptions& options) {
  validate(original, images, options);
  const unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  const int level = images.geometry.front().level;
  const int size = images.geometry.front().size();
  UniformRemeshResult remesh = uniform_remesh(images, level);
  if (options.quad_split == QuadSplit::kShorter)
    split_along_shorter_diagonals(remesh, level, {&remesh.mesh.positions});
  const std::vector<Eigen::Vector3d>& p0 = remesh.mesh.positions;
  const std::size_t nv = p0.size();

  // Active triangles: all but those of masked quads (2 triangles per quad, patch by patch, rows j, columns i,
  // as uniform_remesh_connectivity() emits them).
  const std::size_t quads_per_patch = std::size_t{1} << (2 * level);
  std::vector<std::array<int, 3>> triangles;
  for (std::size_t f = 0; f < remesh.mesh.triangles.size(); ++f) {
    const std::size_t patch = f / (2 * quads_per_patch), quad = (f / 2) % quads_per_patch;
    if (!options.hole_quads.empty() && options.hole_quads[patch][quad]) continue;
    triangles.push_back(remesh.mesh.triangles[f]);
  }
  FitResult result;
  result.images = images;
  if (options.iterations == 0 || triangles.empty()) {
    result.offsets.assign(images.geometry.size(), std::vector<float>(static_cast<std::size_t>(size) * size, 0.f));
    result.directions.assign(images.geometry.size(),
                             std::vector<Eigen::Vector3f>(static_cast<std::size_t>(size) * size,
                                                          Eigen::Vector3f::Zero()));
    return result;
  }

  // Directions, free vertices, offset bounds, edges.
  const std::vector<Eigen::Vector3d> normals = area_weighted_vertex_normals(remesh.mesh);
  std::vector<int> unknown(nv, -1);
  std::vector<double> edge_sum(nv, 0), bound(nv, 0);
  std::vector<int> edge_count(nv, 0);
  std::vector<std::pair<int, int>> edges;
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  for (const auto& [a, b] : edges) {
    const double length = (p0[a] - p0[b]).norm();
    edge_sum[a] += length;
    edge_sum[b] += length;
    ++edge_count[a];
    ++edge_count[b];
  }
  int unknowns = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    if (edge_count[v] > 0) {
      unknown[v] = unknowns++;
      bound[v] = options.max_offset * edge_sum[v] / edge_count[v];
    }
  }
  std::vector<Eigen::Vector3d> unfitted_normals(triangles.size());
  double remesh_area = 0;
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    unfitted_normals[f] = face_normal(p0, triangles[f]);
    remesh_area += 0.5 * unfitted_normals[f].norm();
  }

  const std::size_t face_samples =
      static_cast<std::size_t>(std::ceil(options.samples_per_triangle * static_cast<double>(triangles.size())));
  const std::vector<Eigen::Vector3d> original_points = sample_surface_points(original, face_samples, options.seed);
  const SurfaceQuery original_query(original);
  std::vector<Eigen::Vector3d> original_normals(original.triangles.size());
  for (std::size_t f = 0; f < original.triangles.size(); ++f) {
    const Eigen::Vector3d n = face_normal(original.positions, original.triangles[f]);
    original_normals[f] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
  }

  std::vector<double> delta(nv, 0);
  std::vector<Eigen::Vector3d> x = p0;
  std::vector<Equation> to_remesh(original_points.size());
  std::vector<RemeshPoint> remesh_points;
  {
    std::vector<std::pair<std::size_t, int>> corner_of(nv, {0, -1});  // a triangle and slot per vertex
    std::size_t active_vertices = 0;
    for (std::size_t f = 0; f < triangles.size(); ++f) {
      for (int k = 0; k < 3; ++k) {
        if (corner_of[triangles[f][k]].second < 0) {
          corner_of[triangles[f][k]] = {f, k};
          ++active_vertices;
        }
      }
    }
    const double face_share = kMetroFaceSamplesPerTriangle * static_cast<double>(triangles.size());
    const double total = face_share + static_cast<double>(active_vertices);
    for (std::size_t f = 0; f < triangles.size(); ++f) {
      const double area_share = 0.5 * unfitted_normals[f].norm() / remesh_area;
      for (const auto& r : kTriangleRule) {
        remesh_points.push_back({f, {r[0], r[1], r[2]}, r[3] * area_share * face_share / total});
      }
    }
    for (std::size_t v = 0; v < nv; ++v) {
      if (corner_of[v].second < 0) continue;
      RemeshPoint point{corner_of[v].first, {0, 0, 0}, 1 / total};
      point.b[corner_of[v].second] = 1;
      remesh_points.push_back(point);
    }
  }
  std::vector<Equation> to_original(remesh_points.size());
  // The previous pass's closest triangles of the original, per remesh point (to_original's hints; the
  // remesh's own are in to_remesh[i].triangle); none before the first pass.
  std::vector<std::size_t> original_hit(remesh_points.size());
  bool hinted = false;

  // Linearizes both directions at the current positions x; returns the two sampled RMS distances.
  auto linearize = [&]() -> std::pair<double, double> {
    TriMesh current;
    current.positions = x;
    current.triangles = triangles;
    const SurfaceQuery remesh_query(current);
    parallel_for(original_points.size(), threads, [&](std::size_t i) {
      const Eigen::Vector3d& q = original_points[i];
      // From the second pass on, each query starts from its previous answer: the surfaces move little between
      // passes, and the traversal then prunes almost everything (the distances are exact either way).
      const SurfaceQuery::Closest hit =
          hinted ? remesh_query.closest(q, to_remesh[i].triangle) : remesh_query.closest(q);
      const auto& t = triangles[hit.triangle];
      const Eigen::Vector3d n = face_normal(x, t).normalized();
      const auto b = barycentric(hit.point, x[t[0]], x[t[1]], x[t[2]]);
      Equation& e = to_remesh[i];
      e.triangle = hit.triangle;
      Eigen::Vector3d base = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        e.coef[k] = b[k] * n.dot(normals[t[k]]);
        base += b[k] * p0[t[k]];
      }
      e.rhs = n.dot(q - base);
      e.distance2 = (hit.point - q).squaredNorm();
    });
    parallel_for(to_original.size(), threads, [&](std::size_t i) {
      const auto& t = triangles[remesh_points[i].triangle];
      const auto& b = remesh_points[i].b;
      Eigen::Vector3d y = Eigen::Vector3d::Zero(), base = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        y += b[k] * x[t[k]];
        base += b[k] * p0[t[k]];
      }
      const SurfaceQuery::Closest hit =
          hinted ? original_query.closest(y, original_hit[i]) : original_query.closest(y);
      original_hit[i] = hit.triangle;
      const Eigen::Vector3d& m = original_normals[hit.triangle];
      Equation& e = to_original[i];
      e.triangle = remesh_points[i].triangle;
      for (int k = 0; k < 3; ++k) e.coef[k] = b[k] * m.dot(normals[t[k]]);
      e.rhs = m.dot(hit.point - base);
      e.distance2 = (hit.point - y).squaredNorm();
    });
    hinted = true;
    double sum1 = 0, sum2 = 0;
    for (const Equation& e : to_remesh) sum1 += e.distance2;
    for (std::size_t i = 0; i < to_original.size(); ++i) sum2 += remesh_points[i].weight * to_original[i].distance2;
    return {std::sqrt(sum1 / static_cast<double>(to_remesh.size())), std::sqrt(sum2)};
  };

  using SparseMatrix = Eigen::SparseMatrix<double>;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const auto [rms1, rms2] = linearize();
    if (iteration == 0) {
      result.rms_to_remesh_before = rms1;
      result.rms_to_original_before = rms2;
    }
    // Normal equations, summed in a fixed order: per triangle first (3×3 blocks), then into the matrix.
    std::vector<std::array<double, 9>> block(triangles.size(), std::array<double, 9>{});
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns);
    auto add = [&](const Equation& e, double w) {
      const auto& t = triangles[e.triangle];
      auto& m = block[e.triangle];
      for (int a = 0; a < 3; ++a) {
        rhs[unknown[t[a]]] += w * e.coef[a] * e.rhs;
        for (int b = 0; b < 3; ++b) m[3 * a + b] += w * e.coef[a] * e.coef[b];
      }
    };
    const double w1 = 1.0 / static_cast<double>(to_remesh.size());
    for (const Equation& e : to_remesh) add(e, w1);
    for (std::size_t i = 0; i < to_original.size(); ++i) add(to_original[i], remesh_points[i].weight);
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(9 * triangles.size() + 4 * edges.size() + static_cast<std::size_t>(unknowns));
    for (std::size_t f = 0; f < triangles.size(); ++f) {
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b)
          triplets.emplace_back(unknown[triangles[f][a]], unknown[triangles[f][b]], block[f][3 * a + b]);
      }
    }
    block = {};
    // Regularizers, relative to a data term of one average sample per vertex.
    const double per_vertex = 1.0 / static_cast<double>(unknowns);
    const double ws = options.smoothness * per_vertex;
    for (const auto& [a, b] : edges) {
      const int ia = unknown[a], ib = unknown[b];
      triplets.emplace_back(ia, ia, ws);
      triplets.emplace_back(ib, ib, ws);
      triplets.emplace_back(ia, ib, -ws);
      triplets.emplace_back(ib, ia, -ws);
    }
    for (int i = 0; i < unknowns; ++i) triplets.emplace_back(i, i, options.damping * per_vertex);
    SparseMatrix system(unknowns, unknowns);
    system.setFromTriplets(triplets.begin(), triplets.end());
    triplets = {};
    // Conjugate gradients from the previous pass's offsets: the data terms give every unknown a strong
    // diagonal, so few iterations reach kSolveTolerance (the bunny at level 8: 17-19; the sparse LDLT's
    // factorization was 15 % of its conversion's time). The LDLT stays for a system CG does not settle.
    Eigen::VectorXd guess(unknowns);
    for (std::size_t v = 0; v < nv; ++v) {
      if (unknown[v] >= 0) guess[unknown[v]] = delta[v];
    }
    Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper> iterative(system);
    iterative.setTolerance(kSolveTolerance);
    iterative.setMaxIterations(kSolveMaxIterations);
    Eigen::VectorXd solution = iterative.solveWithGuess(rhs, guess);
    if (iterative.info() != Eigen::Success || !solution.allFinite()) {
      const Eigen::SimplicialLDLT<SparseMatrix> solver(system);
      if (solver.info() != Eigen::Success)
        throw SolverFailure(std::string(kFunction) + ": LDLT factorization failed");
      solution = solver.solve(rhs);
      if (solver.info() != Eigen::Success || !solution.allFinite())
        throw SolverFailure(std::string(kFunction) + ": LDLT solve failed");
    }

    // Bound, then the flip guard.
    result.clamped = 0;
    for (std::size_t v = 0; v < nv; ++v) {
      if (unknown[v] < 0) continue;
      double d = solution[unknown[v]];
      if (std::abs(d) > bound[v]) {
        d = std::copysign(bound[v], d);
        ++result.clamped;
      }
      delta[v] = d;
    }
    result.flip_guarded = 0;
    // After kFlipRounds halvings the offsets are reset to 0; that ends, since with every offset 0 the remesh is
    // the unfitted one (its zero-area triangles are not checked: they have no normal to turn).
    for (int round = 0;; ++round) {
      for (std::size_t v = 0; v < nv; ++v) x[v] = p0[v] + delta[v] * normals[v];
      std::vector<int> flipped;
      for (std::size_t f = 0; f < triangles.size(); ++f) {
        if (unfitted_normals[f].squaredNorm() > 0 && !(face_normal(x, triangles[f]).dot(unfitted_normals[f]) > 0)) {
          for (int v : triangles[f]) {
            if (delta[v] != 0) flipped.push_back(v);
          }
        }
      }
      if (flipped.empty()) break;
      std::sort(flipped.begin(), flipped.end());
      flipped.erase(std::unique(flipped.begin(), flipped.end()), flipped.end());
      result.flip_guarded += flipped.size();
      for (int v : flipped) delta[v] = round < kFlipRounds ? 0.5 * delta[v] : 0.0;
    }
    for (std::size_t v = 0; v < nv; ++v) x[v] = p0[v] + delta[v] * normals[v];
  }
  if (options.measure_after) {
    const auto [rms1, rms2] = linearize();
    result.rms_to_remesh_after = rms1;
    result.rms_to_original_after = rms2;
  }

  // Write back: each vertex's float position computed once, copied into every sample that holds it.
  const std::size_t samples = static_cast<std::size_t>(size) * size;
  result.offsets.assign(images.geometry.size(), std::vector<float>(samples, 0.f));
  result.directions.assign(images.geometry.size(), std::vector<Eigen::Vector3f>(samples, Eigen::Vector3f::Zero()));
  for (std::size_t p = 0; p < images.geometry.size(); ++p) {
    for (std::size_t s = 0; s < samples; ++s) {
      const int v = remesh.grid_vertex[p][s];
      result.directions[p][s] = normals[v].cast<float>();
      if (delta[v] == 0) continue;  // keeps the exact sample
      result.offsets[p][s] = static_cast<float>(delta[v]);
      float* out = result.images.geometry[p].values.data() + 3 * s;
      for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(x[v][k]);
    }
  }
  return result;
}

}  // namespace geomip
