#include "param/consistent_parameterization.h"

#include "mesh/errors.h"
#include "mesh/mesh_topology.h"
#include "mesh/predicates.h"
#include "param/coarse_to_fine.h"
#include "param/feature_warp.h"
#include "param/unit_square.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <system_error>
#include <thread>

namespace geomip {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A patch cut out of the partitioned mesh with local vertex ids, and everything the later stages need.
struct PatchWork {
  TriMesh local;                   // positions and CCW triangles in local ids
  std::vector<int> to_mesh;        // local id → mesh id
  std::array<int, 4> corners{};    // local ids
  PatchSides sides;                // local ids
  std::vector<int> features;       // local ids, in the order of `feature_index`
  std::vector<int> feature_index;  // index of each of `features` in the model's feature list
  ProgressiveMesh pm;
  std::vector<Eigen::Vector2d> uv;  // per local vertex (base vertices valid after the base embedding)
  std::vector<double> weights;      // per local vertex: sampling weights (empty: uniform)
  std::vector<Eigen::Matrix3d> metrics;  // per local vertex: metric tensors (empty: Euclidean)
};

struct ModelWork {
  PartitionResult partition;
  std::vector<PatchWork> patches;
  std::vector<int> feature_patch;  // patch of each feature
  std::vector<Eigen::Matrix3d> metrics;  // per partition-mesh vertex (empty: Euclidean)
};

void report(const ParameterizationOptions& o, const char* stage, double f) {
  if (o.progress) o.progress(stage, f);
}

// Calls task(p) once for every patch p in [0, n), on up to `threads` threads (0 = one per hardware thread;
// the caller's thread is one of them). Patches are independent (each has its own seeds and writes only its
// own slots), so the results do not depend on the thread count or the schedule. After a task throws, no
// patch with a higher index starts; once all threads are joined the exception of the lowest failing patch is
// rethrown, which is the one a sequential run throws. (codec::parallel_for is the codec's loop; codec builds
// from its own folder, so param cannot share it.)
template <typename Task>
void for_each_patch(std::size_t n, unsigned threads, const Task& task) {
  std::vector<std::exception_ptr> errors(n);
  std::atomic<std::size_t> next{0}, first_error{n};
  const auto worker = [&] {
    for (std::size_t p = next++; p < n && p < first_error; p = next++) {
      try {
        task(p);
      } catch (...) {
        errors[p] = std::current_exception();
        for (std::size_t e = first_error; p < e && !first_error.compare_exchange_weak(e, p);) {
        }
      }
    }
  };
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t count = std::min<std::size_t>(threads > 0 ? threads : hardware, n);
  std::vector<std::thread> pool;
  // Joins every started thread on every way out, so none is left joinable (std::terminate) or running on
  // this frame's locals.
  struct JoinAll {
    std::vector<std::thread>& pool;
    ~JoinAll() {
      for (auto& thread : pool) {
        if (thread.joinable()) thread.join();
      }
    }
  } join_all{pool};
  try {
    pool.reserve(count - 1);
    for (std::size_t t = 1; t < count; ++t) pool.emplace_back(worker);
  } catch (const std::exception&) {  // no more threads (system_error, bad_alloc): those started and this one do the rest
  }
  worker();
  for (auto& thread : pool) thread.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

void add_seconds(StageSeconds& to, const StageSeconds& s) {
  to.partition += s.partition;
  to.progressive_mesh += s.progressive_mesh;
  to.base_embedding += s.base_embedding;
  to.feature_warp += s.feature_warp;
  to.coarse_to_fine += s.coarse_to_fine;
  to.final_optimization += s.final_optimization;
  to.mvc_baseline += s.mvc_baseline;
}

PatchWork extract_patch(const PartitionResult& partition, const Patch& patch) {
  PatchWork w;
  std::vector<int> to_local(partition.mesh.positions.size(), -1);
  for (int f : patch.faces) {
    for (int v : partition.mesh.triangles[f]) {
      if (to_local[v] < 0) {
        to_local[v] = 0;  // mark; ids assigned in ascending mesh order below
      }
    }
  }
  for (std::size_t v = 0; v < to_local.size(); ++v) {
    if (to_local[v] == 0) {
      to_local[v] = static_cast<int>(w.to_mesh.size());
      w.to_mesh.push_back(static_cast<int>(v));
      w.local.positions.push_back(partition.mesh.positions[v]);
    }
  }
  for (int f : patch.faces) {
    const auto& t = partition.mesh.triangles[f];
    w.local.triangles.push_back({to_local[t[0]], to_local[t[1]], to_local[t[2]]});
  }
  for (int k = 0; k < 4; ++k) {
    w.corners[k] = to_local[patch.corners[k]];
    for (int v : patch.sides[k].vertices) w.sides[k].push_back(to_local[v]);
  }
  return w;
}

std::vector<char> boundary_mask(const PatchWork& w) {
  std::vector<char> mask(w.local.positions.size(), 0);
  for (const auto& side : w.sides) {
    for (int v : side) mask[v] = 1;
  }
  return mask;
}

// Compact copy of the base mesh (only base vertices) for the optimizer and the warp, which want every
// vertex referenced and every uv finite.
struct BaseMesh {
  std::vector<int> to_patch;  // base id → local patch id
  std::vector<int> to_base;   // local patch id → base id or -1
  std::vector<Eigen::Vector3d> positions;
  std::vector<std::array<int, 3>> triangles;
  std::vector<Eigen::Vector2d> uv;
};

BaseMesh base_mesh(const PatchWork& w) {
  BaseMesh b;
  b.to_base.assign(w.local.positions.size(), -1);
  for (int v : w.pm.base_vertices) {
    b.to_base[v] = static_cast<int>(b.to_patch.size());
    b.to_patch.push_back(v);
    b.positions.push_back(w.local.positions[v]);
    b.uv.push_back(w.uv[v]);
  }
  for (const auto& t : w.pm.base_triangles)
    b.triangles.push_back({b.to_base[t[0]], b.to_base[t[1]], b.to_base[t[2]]});
  return b;
}

void store_base(const BaseMesh& b, PatchWork& w) {
  for (std::size_t i = 0; i < b.to_patch.size(); ++i) w.uv[b.to_patch[i]] = b.uv[i];
}

// Σ of triangle_l2_energy() over a patch, each triangle in the mean of its corners' tensors: what the stretch
// optimization lowers when it runs in the metric, to compare two parameterizations of the same patch.
double metric_l2_energy(const std::vector<Eigen::Vector3d>& positions,
                        const std::vector<std::array<int, 3>>& triangles,
                        const std::vector<Eigen::Vector2d>& uv, const std::vector<Eigen::Matrix3d>& metrics) {
  double e = 0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d q[3] = {positions[t[0]], positions[t[1]], positions[t[2]]};
    const Eigen::Vector2d p[3] = {uv[t[0]], uv[t[1]], uv[t[2]]};
    e += triangle_l2_energy(q, p, (metrics[t[0]] + metrics[t[1]] + metrics[t[2]]) / 3.0);
  }
  return e;
}

// A few global stretch sweeps over the current level of a coarse-to-fine pass (Sander et al. 2002 optimize
// every level of the hierarchy; local moves alone leave clusters of vertices squeezed into tiny kernels,
// e.g. L2 stretch 96 instead of 1.3 on one of fandisk's patches).
void optimize_level(const std::vector<Eigen::Vector3d>& positions, CoarseToFine& c2f,
                    const std::vector<char>& locked, const ParameterizationOptions& options, unsigned seed,
                    const std::vector<double>* weights, const std::vector<Eigen::Matrix3d>* metrics) {
  std::vector<std::array<int, 3>> triangles;
  std::vector<char> present(positions.size(), 0);
  for (const auto& t : c2f.current_triangles()) {
    if (t[0] < 0) continue;
    triangles.push_back(t);
    present[t[0]] = present[t[1]] = present[t[2]] = 1;
  }
  std::vector<Eigen::Vector2d> uv = c2f.uv();
  for (std::size_t v = 0; v < uv.size(); ++v) {
    if (!present[v]) uv[v].setZero();  // not referenced: the optimizer only needs finite values
  }
  StretchOptimizationOptions level_options = options.base_optimization;
  level_options.max_sweeps = options.level_sweeps;
  level_options.seed = options.seed + seed;
  level_options.vertex.vertex_weights = weights;
  level_options.vertex.vertex_metrics = metrics;
  optimize_stretch(positions, triangles, uv, locked, level_options);
  for (std::size_t v = 0; v < uv.size(); ++v) {
    if (present[v]) c2f.uv()[v] = uv[v];
  }
}

// Per patch: local id of each mesh vertex (−1 outside the patch) and the triangles around each local vertex.
struct PatchIndex {
  std::vector<std::vector<int>> local;             // [patch][mesh vertex]
  std::vector<std::vector<std::vector<int>>> star;  // [patch][local vertex]: triangle ids
};

PatchIndex index_patches(const ModelParameterization& m) {
  PatchIndex index;
  index.local.assign(m.patches.size(), std::vector<int>(m.mesh.positions.size(), -1));
  index.star.resize(m.patches.size());
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    const auto& patch = m.patches[p];
    for (std::size_t i = 0; i < patch.vertices.size(); ++i) index.local[p][patch.vertices[i]] = static_cast<int>(i);
    index.star[p].assign(patch.vertices.size(), {});
    for (std::size_t t = 0; t < patch.triangles.size(); ++t) {
      for (int v : patch.triangles[t]) index.star[p][v].push_back(static_cast<int>(t));
    }
  }
  return index;
}

// Seam vertices sit at their chord-length position in both patches, so the two positions agree; where
// coarse-to-fine could not put one there (a boundary vertex boxed in by long triangles), this moves the
// vertex in the other patch to the same position if that flips nothing there, and copies the value bit for
// bit. Returns the vertices whose positions still differ.
std::size_t reconcile_seams(ModelParameterization& m) {
  const PatchIndex index = index_patches(m);
  const auto& local = index.local;
  const auto& star = index.star;
  auto star_valid = [&](std::size_t p, int v) {
    for (int t : star[p][v]) {
      const auto& tri = m.patches[p].triangles[t];
      const auto& uv = m.patches[p].uv;
      if (orient2d(uv[tri[0]], uv[tri[1]], uv[tri[2]]) <= 0) return false;
    }
    return true;
  };
  std::size_t mismatches = 0;
  for (const SideLink& link : m.adjacency) {
    if (link.patch > link.other_patch) continue;  // each seam once
    auto& a = m.patches[link.patch];
    auto& b = m.patches[link.other_patch];
    const auto& side = a.sides[link.side];
    for (std::size_t j = 1; j + 1 < side.size(); ++j) {
      const int va = local[link.patch][side[j]], vb = local[link.other_patch][side[j]];
      const double sa = position_on_side(a.uv[va], link.side);
      const double sb_as_a = link.reversed ? 1.0 - position_on_side(b.uv[vb], link.other_side)
                                           : position_on_side(b.uv[vb], link.other_side);
      if (sa == sb_as_a) continue;
      // Move b's copy to a's position; failing that, a's copy to b's.
      const Eigen::Vector2d old_b = b.uv[vb];
      b.uv[vb] = point_on_side(link.other_side, link.reversed ? 1.0 - sa : sa);
      if (star_valid(link.other_patch, vb)) continue;
      b.uv[vb] = old_b;
      const Eigen::Vector2d old_a = a.uv[va];
      a.uv[va] = point_on_side(link.side, sb_as_a);
      if (star_valid(link.patch, va)) continue;
      a.uv[va] = old_a;
      ++mismatches;
    }
  }
  return mismatches;
}

// Sliding seams: the sides are parameterized by chord length in each patch, which fixes how much of a side
// each stretch of seam gets before either patch's interior is known. Each round moves every seam vertex along
// its side, to where the L2 stretch energy Σ A3·L2² of its triangles in *both* patches is least (golden
// section between its two side neighbours, never flipping a triangle on either side), then runs `sweeps`
// global stretch sweeps over every patch with its boundary and features locked. Both copies of a seam vertex
// get the same parameter, so the seams still agree (reconcile_seams() makes them bit-identical).
void slide_seams(ModelParameterization& m, const std::vector<std::vector<double>>& weights,
                 const std::vector<std::vector<Eigen::Matrix3d>>& metrics,
                 const ParameterizationOptions& options) {
  const std::size_t np = m.patches.size();
  const PatchIndex index = index_patches(m);
  const auto& local = index.local;
  const auto& star = index.star;
  std::vector<std::vector<Eigen::Vector3d>> positions(np);
  for (std::size_t p = 0; p < np; ++p) {
    for (int v : m.patches[p].vertices) positions[p].push_back(m.mesh.positions[v]);
  }
  // Σ A3·L2² over the star of v in patch p (+inf when a triangle is flipped or degenerate), in the patch's
  // metric when it has one (the energy its sweeps lower).
  auto star_energy = [&](std::size_t p, int v) {
    double e = 0.0;
    const auto& patch = m.patches[p];
    for (int t : star[p][v]) {
      const auto& tri = patch.triangles[t];
      const Eigen::Vector3d q[3] = {positions[p][tri[0]], positions[p][tri[1]], positions[p][tri[2]]};
      const Eigen::Vector2d uv[3] = {patch.uv[tri[0]], patch.uv[tri[1]], patch.uv[tri[2]]};
      if (orient2d(uv[0], uv[1], uv[2]) <= 0) return std::numeric_limits<double>::infinity();
      double w = 1.0;
      if (!weights[p].empty()) w = (weights[p][tri[0]] + weights[p][tri[1]] + weights[p][tri[2]]) / 3.0;
      if (!metrics[p].empty()) {
        const Eigen::Matrix3d mt = (metrics[p][tri[0]] + metrics[p][tri[1]] + metrics[p][tri[2]]) / 3.0;
        e += w * triangle_l2_energy(q, uv, mt);  // A3·(Γ²+γ²)/2 = A3·L2² in the metric
        continue;
      }
      const double l2 = triangle_stretch(q, uv).l2;
      const double a3 = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
      e += w * a3 * l2 * l2;
    }
    return e;
  };
  for (int round = 0; round < options.seam_slide_rounds; ++round) {
    for (const SideLink& link : m.adjacency) {
      if (link.patch == link.other_patch) continue;
      if (std::make_pair(link.patch, link.side) > std::make_pair(link.other_patch, link.other_side)) continue;
      auto& a = m.patches[link.patch];
      auto& b = m.patches[link.other_patch];
      const auto& side = a.sides[link.side];
      for (std::size_t j = 1; j + 1 < side.size(); ++j) {
        const int va = local[link.patch][side[j]], vb = local[link.other_patch][side[j]];
        if (va < 0 || vb < 0) continue;
        const Eigen::Vector2d old_a = a.uv[va], old_b = b.uv[vb];
        auto place = [&](double s) {
          a.uv[va] = point_on_side(link.side, s);
          b.uv[vb] = point_on_side(link.other_side, link.reversed ? 1.0 - s : s);
        };
        auto energy = [&](double s) {
          place(s);
          return star_energy(link.patch, va) + star_energy(link.other_patch, vb);
        };
        const double lo = position_on_side(a.uv[local[link.patch][side[j - 1]]], link.side);
        const double hi = position_on_side(a.uv[local[link.patch][side[j + 1]]], link.side);
        const double e0 = star_energy(link.patch, va) + star_energy(link.other_patch, vb);
        // Golden section on [lo, hi], kept a little inside so that no seam edge collapses.
        const double margin = 0.02 * (hi - lo);
        double x0 = lo + margin, x3 = hi - margin;
        if (!(x3 > x0)) continue;
        constexpr double kGolden = 0.6180339887498949;
        double x1 = x3 - kGolden * (x3 - x0), x2 = x0 + kGolden * (x3 - x0);
        double f1 = energy(x1), f2 = energy(x2);
        for (int it = 0; it < options.seam_slide_iterations; ++it) {
          if (f1 <= f2) {
            x3 = x2; x2 = x1; f2 = f1;
            x1 = x3 - kGolden * (x3 - x0);
            f1 = energy(x1);
          } else {
            x0 = x1; x1 = x2; f1 = f2;
            x2 = x0 + kGolden * (x3 - x0);
            f2 = energy(x2);
          }
        }
        const double best = f1 <= f2 ? x1 : x2;
        const double fbest = std::min(f1, f2);
        if (fbest < e0 && std::isfinite(fbest)) {
          place(best);
        } else {  // back where it was (the search left it at its last trial)
          a.uv[va] = old_a;
          b.uv[vb] = old_b;
        }
      }
    }
    if (options.seam_slide_sweeps == 0) continue;
    for_each_patch(np, options.threads, [&](std::size_t p) {
      auto& patch = m.patches[p];
      std::vector<char> locked(patch.vertices.size(), 0);
      for (const auto& sd : patch.sides) {
        for (int v : sd) locked[local[p][v]] = 1;
      }
      for (const FeatureLocation& f : m.features) {
        if (f.patch == static_cast<int>(p) && f.vertex >= 0 && local[p][f.vertex] >= 0) locked[local[p][f.vertex]] = 1;
      }
      StretchOptimizationOptions o = options.base_optimization;
      o.max_sweeps = options.seam_slide_sweeps;
      o.seed = options.seed + 977u * static_cast<unsigned>(round + 1) + 13u * static_cast<unsigned>(p);
      o.vertex.vertex_weights = weights[p].empty() ? nullptr : &weights[p];
      o.vertex.vertex_metrics = metrics[p].empty() ? nullptr : &metrics[p];
      optimize_stretch(positions[p], patch.triangles, patch.uv, locked, o);
    });
  }
}

// Progress of the whole run: 3 steps per model (one for phase A, two for phase C) plus phase B. Calls are
// serialized, so the user's callback never runs on two threads at once.
struct Progress {
  Progress(const ParameterizationOptions& o, double steps) : options(o), total_steps(steps) {}
  const ParameterizationOptions& options;
  double total_steps;
  mutable std::mutex mutex;
  void operator()(const char* stage, double f) const {
    const std::lock_guard<std::mutex> lock(mutex);
    report(options, stage, f / total_steps);
  }
};

// Progress of one stage that runs over the patches of a model, possibly several at once: the stage covers
// [start, start + span) and reports the mean of the patches' own fractions.
class PatchProgress {
 public:
  PatchProgress(const Progress& progress, const char* stage, double start, double span, std::size_t patches)
      : progress_(progress), stage_(stage), start_(start), span_(span), fractions_(patches, 0.0) {}
  void operator()(std::size_t patch, double fraction) {
    const std::lock_guard<std::mutex> lock(mutex_);  // held while reporting: the reports never go back
    fractions_[patch] = fraction;
    double sum = 0;
    for (double f : fractions_) sum += f;
    progress_(stage_, start_ + span_ * sum / static_cast<double>(fractions_.size()));
  }

 private:
  const Progress& progress_;
  const char* stage_;
  double start_, span_;
  std::mutex mutex_;
  std::vector<double> fractions_;
};

void check_feature_counts(const std::vector<ParameterizationInput>& models) {
  const std::size_t num_features = models[0].features.size();
  for (const auto& m : models) {
    if (m.features.size() != num_features) {
      throw InvalidInput("parameterize_consistently: model '" + m.name + "' has " +
                         std::to_string(m.features.size()) + " features, model '" + models[0].name +
                         "' has " + std::to_string(num_features) +
                         " (features correspond by order: the counts must agree)");
    }
  }
}

// vertex_feature[v] = k when vertex v of the (partitioned) mesh is feature k, else −1.
std::vector<int> feature_of_vertex(const ParameterizationInput& in, std::size_t num_vertices) {
  std::vector<int> vertex_feature(num_vertices, -1);
  for (std::size_t k = 0; k < in.features.size(); ++k) {
    const int v = in.features[k];
    if (v < 0 || static_cast<std::size_t>(v) >= in.mesh.positions.size()) {
      throw InvalidInput("parameterize_consistently: feature " + std::to_string(k) + " of model '" + in.name +
                         "' is vertex " + std::to_string(v) + ", out of range");
    }
    if (vertex_feature[v] >= 0) {
      throw InvalidInput("parameterize_consistently: features " + std::to_string(vertex_feature[v]) +
                         " and " + std::to_string(k) + " of model '" + in.name + "' are the same vertex");
    }
    vertex_feature[v] = static_cast<int>(k);
  }
  return vertex_feature;
}

// Phase A for one patch: its features, progressive mesh, MVC base embedding and the base's stretch
// optimization. Sets w.feature_patch for the patch's features.
PatchWork prepare_patch(const ParameterizationInput& in, ModelWork& w, std::size_t p,
                        const std::vector<int>& vertex_feature, const ParameterizationOptions& options,
                        StageSeconds& seconds) {
  PatchWork pw = extract_patch(w.partition, w.partition.patches[p]);
  const std::vector<char> on_boundary = boundary_mask(pw);
  for (std::size_t v = 0; v < pw.to_mesh.size(); ++v) {
    const int k = vertex_feature[pw.to_mesh[v]];
    if (k < 0) continue;
    if (on_boundary[v]) {
      throw InvalidInput("parameterize_consistently: feature " + std::to_string(k) + " of model '" + in.name +
                         "' (vertex " + std::to_string(in.features[k]) + ") lies on the partition cut (patch " +
                         std::to_string(p) + "); features must be inside a patch");
    }
    w.feature_patch[k] = static_cast<int>(p);
    pw.features.push_back(static_cast<int>(v));
    pw.feature_index.push_back(k);
  }
  auto t0 = Clock::now();
  pw.pm = progressive_mesh(pw.local, pw.sides, pw.features, options.progressive_mesh);
  seconds.progressive_mesh += seconds_since(t0);

  t0 = Clock::now();
  if (!w.metrics.empty()) {
    for (int v : pw.to_mesh) pw.metrics.push_back(w.metrics[v]);
  }
  const std::vector<Eigen::Matrix3d>* metrics = pw.metrics.empty() ? nullptr : &pw.metrics;
  const std::vector<FixedUv> boundary = square_boundary_uv(pw.local.positions, pw.pm.sides, metrics);
  pw.uv = mean_value_embedding(pw.local.positions, pw.pm.base_triangles, boundary).uv;
  BaseMesh base = base_mesh(pw);
  std::vector<char> locked(base.to_patch.size(), 0);
  for (std::size_t b = 0; b < locked.size(); ++b) locked[b] = on_boundary[base.to_patch[b]];
  StretchOptimizationOptions base_options = options.base_optimization;
  base_options.seed = options.seed + static_cast<unsigned>(p);
  std::vector<double> base_weights;
  if (options.curvature_sampling) {
    pw.weights = curvature_sampling_weights(pw.local.positions, pw.local.triangles, options.sampling_weights);
  }
  if (!pw.weights.empty()) {
    for (int v : base.to_patch) base_weights.push_back(pw.weights[v]);
    base_options.vertex.vertex_weights = &base_weights;
  }
  std::vector<Eigen::Matrix3d> base_metrics;
  if (metrics) {
    for (int v : base.to_patch) base_metrics.push_back(pw.metrics[v]);
    base_options.vertex.vertex_metrics = &base_metrics;
  }
  optimize_stretch(base.positions, base.triangles, base.uv, locked, base_options);
  store_base(base, pw);
  seconds.base_embedding += seconds_since(t0);
  return pw;
}

// Phase A for model i: partition, patches, progressive meshes, base embeddings. `first` is model 0's work
// (null for model 0 itself): patch counts and feature patches must agree with it.
ModelWork prepare_model(const std::vector<ParameterizationInput>& models, std::size_t i,
                        const ModelWork* first, const ParameterizationOptions& options,
                        const Progress& progress, ModelParameterization& o) {
  const ParameterizationInput& in = models[i];
  ModelWork w;
  progress("partition", static_cast<double>(i));
  const auto t0 = Clock::now();
  if (first) {  // a set of different genus fails later with a message about auxiliary points: say why first
    const std::optional<int> genus = analyze_topology(in.mesh).genus;
    const std::optional<int> first_genus = analyze_topology(models[0].mesh).genus;
    if (genus && first_genus && *genus != *first_genus)
      throw InvalidInput("parameterize_consistently: model '" + in.name + "' has genus " +
                         std::to_string(*genus) + ", model '" + models[0].name + "' genus " +
                         std::to_string(*first_genus) + "; the models of a consistent set share one genus");
  }
  try {
    if (!in.side_guides.empty()) {
      if (!in.auxiliary_points.empty() || !in.layout_quads.empty()) {
        throw InvalidInput("parameterize_consistently: model '" + in.name +
                           "' has guide lists per path and auxiliary points or a layout; give one of them");
      }
      w.partition = partition_mesh_guided(in.mesh, in.partition_points, in.side_guides);
    } else if (in.layout_quads.empty()) {
      w.partition = partition_mesh(in.mesh, in.partition_points, in.auxiliary_points);
    } else {
      if (!in.auxiliary_points.empty()) {
        throw InvalidInput("parameterize_consistently: model '" + in.name +
                           "' has a quad layout and auxiliary points; a layout's paths take no guides");
      }
      if (i > 0 && in.layout_quads != models[0].layout_quads) {
        throw InvalidInput("parameterize_consistently: model '" + in.name +
                           "' has other layout quads than '" + models[0].name +
                           "'; a consistent set shares one layout");
      }
      w.partition = partition_mesh_layout(in.mesh, QuadLayout{in.partition_points, in.layout_quads});
    }
  } catch (const InvalidInput& e) {  // the partition's messages do not know which model they are about
    const std::string what = e.what();
    if (models.size() < 2 || what.find("model '") != std::string::npos) throw;
    throw InvalidInput("model '" + in.name + "': " + what);
  }
  o.seconds.partition = seconds_since(t0);
  if (first && w.partition.patches.size() != first->partition.patches.size()) {
    throw InvalidInput("parameterize_consistently: model '" + in.name + "' has " +
                       std::to_string(w.partition.patches.size()) + " patches, model '" + models[0].name +
                       "' has " + std::to_string(first->partition.patches.size()) + " (different genus)");
  }
  // Features: interior vertices of a patch, in the same patch in every model.
  const std::vector<int> vertex_feature = feature_of_vertex(in, w.partition.mesh.positions.size());
  w.feature_patch.assign(in.features.size(), -1);
  if (options.curvature_metric > 0) {
    w.metrics = curvature_metric_tensors(w.partition.mesh.positions, w.partition.mesh.triangles,
                                         options.curvature_metric);
  }
  // The patches in parallel; each writes only its own slots (and feature_patch of its own features).
  const std::size_t num_patches = w.partition.patches.size();
  w.patches.resize(num_patches);
  std::vector<StageSeconds> seconds(num_patches);
  PatchProgress patch_progress(progress, "progressive mesh", static_cast<double>(i), 1.0, num_patches);
  for_each_patch(num_patches, options.threads, [&](std::size_t p) {
    patch_progress(p, 0.0);  // names the stage
    w.patches[p] = prepare_patch(in, w, p, vertex_feature, options, seconds[p]);
    patch_progress(p, 1.0);
  });
  for (const StageSeconds& s : seconds) add_seconds(o.seconds, s);
  if (first) {
    for (std::size_t k = 0; k < in.features.size(); ++k) {
      if (w.feature_patch[k] != first->feature_patch[k]) {
        throw InvalidInput("parameterize_consistently: feature " + std::to_string(k) + " is in patch " +
                           std::to_string(w.feature_patch[k]) + " of model '" + in.name + "' but in patch " +
                           std::to_string(first->feature_patch[k]) + " of model '" + models[0].name +
                           "': corresponding features must lie in corresponding patches");
      }
    }
  }
  return w;
}

// Phase B for patch p: moves corresponding features of every model to their average (u,v) (§3.4) by warping
// the base meshes.
void align_patch_features(std::vector<ModelWork>& work, std::size_t p,
                          const std::vector<ParameterizationInput>& models,
                          std::vector<ModelParameterization>& out) {
  // Features of a patch are in the same order in every model (ascending local id in model 0 would not be):
  // order each model's list by feature index.
  std::vector<std::vector<Eigen::Vector2d>> ordered(work.size());
  std::vector<int> feature_indices;  // the user's feature index of each target
  for (std::size_t i = 0; i < work.size(); ++i) {
    const auto& pw = work[i].patches[p];
    std::vector<std::pair<int, Eigen::Vector2d>> by_index;
    for (std::size_t j = 0; j < pw.features.size(); ++j)
      by_index.emplace_back(pw.feature_index[j], pw.uv[pw.features[j]]);
    std::sort(by_index.begin(), by_index.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& e : by_index) ordered[i].push_back(e.second);
    if (i == 0) {
      for (const auto& e : by_index) feature_indices.push_back(e.first);
    }
  }
  const std::vector<Eigen::Vector2d> targets = average_feature_targets(ordered);
  // Two features with the same common (u,v) cannot both be there (e.g. they lie the other way round on two
  // models): say which, before warp_features refuses it with patch-local indices.
  const double apart = FeatureWarpOptions{}.collision_distance;
  for (std::size_t k = 0; k < targets.size(); ++k) {
    for (std::size_t l = 0; l < k; ++l) {
      if ((targets[k] - targets[l]).norm() > apart) continue;
      char at[96];
      std::snprintf(at, sizeof at, " (%.3f, %.3f) in patch %zu", targets[k].x(), targets[k].y(), p);
      throw InvalidInput("parameterize_consistently: features " + std::to_string(feature_indices[l]) + " and " +
                         std::to_string(feature_indices[k]) + " get the same common (u,v)" + at +
                         " from the average over the models, so neither can be reached; corresponding features "
                         "must lie alike on every model: check the correspondence file");
    }
  }
  for (std::size_t i = 0; i < work.size(); ++i) {
    auto& pw = work[i].patches[p];
    const auto t0 = Clock::now();
    BaseMesh base = base_mesh(pw);
    std::vector<std::pair<int, int>> index_and_base;
    for (std::size_t j = 0; j < pw.features.size(); ++j) {
      index_and_base.emplace_back(pw.feature_index[j], base.to_base[pw.features[j]]);
    }
    std::sort(index_and_base.begin(), index_and_base.end());
    std::vector<int> features;
    for (const auto& e : index_and_base) features.push_back(e.second);
    const std::vector<Eigen::Vector2d> before = base.uv;
    const FeatureWarpResult r = warp_features(base.triangles, base.uv, features, targets);
    if (!r.unreached.empty()) {
      // Not a solver bug: the correspondences ask for a map that would fold (features of one model lie too
      // differently from the others', e.g. in another order around each other). Name the first one.
      const int k = r.unreached.front();
      const int feature = index_and_base[k].first;
      const Eigen::Vector2d& from = before[features[k]];
      char where[160];
      std::snprintf(where, sizeof where, " from (%.3f, %.3f) to the common (%.3f, %.3f) in patch %zu",
                    from.x(), from.y(), targets[k].x(), targets[k].y(), p);
      throw InvalidInput(
          "parameterize_consistently: feature " + std::to_string(feature) + " of model '" + models[i].name +
          "' (vertex " + std::to_string(models[i].features[feature]) + ") cannot move" + where +
          " without folding the parameterization: " + r.unreached_reasons.front() +
          (r.unreached.size() > 1 ? " (" + std::to_string(r.unreached.size() - 1) + " more)" : "") +
          "; corresponding features must lie alike on every model: check the correspondence file");
    }
    // Exact targets: the warp reaches them to rounding; store the common value itself.
    for (std::size_t j = 0; j < features.size(); ++j) base.uv[features[j]] = targets[j];
    store_base(base, pw);
    out[i].warp_events += r.events;
    out[i].seconds.feature_warp += seconds_since(t0);
  }
}

// Phase C, coarse to fine: inserts the patch's vertices one by one with local stretch optimization, and
// optimizes each level globally whenever it has grown by `level_growth`. Reports the patch's fraction done to
// `progress`.
CoarseToFineResult refine_patch(PatchWork& pw, std::size_t p, const std::vector<char>& locked,
                                const ParameterizationOptions& options, PatchProgress& progress) {
  CoarseToFineOptions c2f_options;
  c2f_options.side_metrics = pw.metrics.empty() ? nullptr : &pw.metrics;
  CoarseToFine c2f(pw.local, pw.pm, pw.uv, c2f_options);
  std::mt19937 rng(options.seed * 7919u + static_cast<unsigned>(p));
  const std::vector<double>* weights = pw.weights.empty() ? nullptr : &pw.weights;
  VertexOptimizationOptions local_options = options.local_optimization;
  local_options.vertex_weights = weights;
  const std::vector<Eigen::Matrix3d>* metrics = pw.metrics.empty() ? nullptr : &pw.metrics;
  local_options.vertex_metrics = metrics;
  const VertexOptimizer optimize = [&](int v, const std::vector<int>& ring) {
    if (locked[v]) return;
    for (int round = 0; round < options.local_rounds; ++round) {
      optimize_vertex(v, ring, pw.local.positions, c2f.current_triangles(), c2f.uv(), local_options, rng);
    }
  };
  std::size_t next_level = pw.pm.base_vertices.size();
  std::size_t level_vertices = next_level;
  while (!c2f.finished()) {
    c2f.split_next(optimize);
    ++level_vertices;
    if ((c2f.splits_done() & 1023u) == 0) {
      progress(p, static_cast<double>(c2f.splits_done()) / static_cast<double>(c2f.num_splits()));
    }
    if (options.level_sweeps > 0 && level_vertices >= next_level * options.level_growth && !c2f.finished()) {
      optimize_level(pw.local.positions, c2f, locked, options, static_cast<unsigned>(level_vertices), weights,
                     metrics);
      next_level = level_vertices;
    }
  }
  return c2f.result();
}

// The L∞ pass (ParameterizationOptions::linf_sweeps): StretchNorm::kLinf sweeps, each over the vertices
// whose ring holds a triangle with normalized L∞ stretch at least max(linf_floor, linf_relative_floor · the
// patch's L∞ before the sweep); stops early after a sweep that moved nothing. The boundary is locked, so
// Σ A2 (the unit square) and the normalization N = sqrt(Σ A2 / Σ A3) are constant, and a floor f is f / N in
// the optimizer's un-normalized units.
void linf_pass(const std::vector<Eigen::Vector3d>& positions, const std::vector<std::array<int, 3>>& triangles,
               std::vector<Eigen::Vector2d>& uv, const std::vector<char>& locked,
               const ParameterizationOptions& options, std::size_t p) {
  double area2 = 0, area3 = 0;
  for (const auto& t : triangles) {
    area3 += 0.5 * (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]).norm();
    area2 += 0.5 * signed_double_area(uv[t[0]], uv[t[1]], uv[t[2]]);
  }
  if (!(area2 > 0) || !(area3 > 0)) return;
  StretchOptimizationOptions o = options.base_optimization;
  o.max_sweeps = options.linf_sweeps;
  o.threshold = 0;  // the max term is not smooth: the sweep count bounds the pass (stretch_optimization.h)
  o.seed = options.seed + 313u * static_cast<unsigned>(p + 1);
  o.vertex.norm = StretchNorm::kLinf;
  o.vertex.vertex_weights = nullptr;  // the L∞ term is not weighted
  o.vertex.vertex_metrics = nullptr;  // and Euclidean: it lowers the reported (Euclidean) L∞ stretch
  const double n = std::sqrt(area2 / area3);
  o.max_sweeps = 1;
  for (std::size_t sweep = 0; sweep < options.linf_sweeps; ++sweep) {
    const double linf = mesh_stretch(positions, triangles, uv).linf;
    o.min_local_stretch = std::max(options.linf_floor, options.linf_relative_floor * linf) / n;
    o.seed = options.seed + 313u * static_cast<unsigned>(p + 1) + 7919u * static_cast<unsigned>(sweep);
    if (optimize_stretch(positions, triangles, uv, locked, o).vertex_moves == 0) break;
  }
}

// Phase C for patch p of model `name`: coarse-to-fine, final sweeps, the MVC baseline and fallback; returns
// the patch's parameterization in mesh ids. \throw SolverFailure when a triangle ends flipped.
PatchParameterization parameterize_patch(PatchWork& pw, std::size_t p, const std::string& name,
                                         const ParameterizationOptions& options, PatchProgress& progress,
                                         StageSeconds& seconds, std::vector<FeatureLocation>& features) {
  std::vector<char> locked = boundary_mask(pw);
  for (int v : pw.features) locked[v] = 1;
  const std::vector<double>* weights = pw.weights.empty() ? nullptr : &pw.weights;
  const std::vector<Eigen::Matrix3d>* metrics = pw.metrics.empty() ? nullptr : &pw.metrics;

  auto t0 = Clock::now();
  CoarseToFineResult r = refine_patch(pw, p, locked, options, progress);
  seconds.coarse_to_fine += seconds_since(t0);

  t0 = Clock::now();
  if (options.final_sweeps > 0) {
    StretchOptimizationOptions final_options = options.base_optimization;
    final_options.max_sweeps = options.final_sweeps;
    final_options.seed = options.seed + 101u * static_cast<unsigned>(p + 1);
    final_options.vertex.vertex_weights = weights;
    final_options.vertex.vertex_metrics = metrics;
    optimize_stretch(pw.local.positions, r.triangles, r.uv, locked, final_options);
  }
  seconds.final_optimization += seconds_since(t0);

  PatchParameterization pp;
  pp.vertices = pw.to_mesh;
  pp.triangles = r.triangles;
  pp.uv = r.uv;
  for (int k = 0; k < 4; ++k) {
    pp.corners[k] = pw.to_mesh[pw.corners[k]];
    for (int v : pw.pm.sides[k]) pp.sides[k].push_back(pw.to_mesh[v]);
  }
  pp.base_vertices = pw.pm.base_vertices.size();
  pp.stretch = mesh_stretch(pw.local.positions, pp.triangles, pp.uv);
  pp.flipped = count_flipped(pp.triangles, pp.uv);
  pp.boundary_off_chord = r.boundary_off_chord;
  if (pp.flipped != 0) {
    throw SolverFailure("parameterize_consistently: patch " + std::to_string(p) + " of model '" + name +
                        "' has " + std::to_string(pp.flipped) + " flipped triangles");
  }
  // The full patch's MVC embedding: the baseline the figures are reported against, and a fallback for a
  // patch without features where coarse-to-fine ends worse than MVC (it happens on CAD-like patches whose
  // long thin triangles leave vertices squeezed into tiny kernels).
  if (options.measure_mvc_baseline || pw.features.empty()) {
    t0 = Clock::now();
    auto mvc = mean_value_embedding(pw.local.positions, pw.local.triangles,
                                    square_boundary_uv(pw.local.positions, pw.pm.sides, metrics));
    pp.mvc_stretch = mesh_stretch(pw.local.positions, pw.local.triangles, mvc.uv);
    seconds.mvc_baseline += seconds_since(t0);
    // Which is better: by the reported (Euclidean) L2 stretch, or, when the stretch was optimized in a
    // curvature metric, by the energy that optimization lowered.
    const auto better = [&](const std::vector<std::array<int, 3>>& tris_a,
                            const std::vector<Eigen::Vector2d>& uv_a, double l2_a,
                            const std::vector<std::array<int, 3>>& tris_b,
                            const std::vector<Eigen::Vector2d>& uv_b, double l2_b) {
      if (!metrics) return l2_a < l2_b;
      return metric_l2_energy(pw.local.positions, tris_a, uv_a, *metrics) <
             metric_l2_energy(pw.local.positions, tris_b, uv_b, *metrics);
    };
    if (pw.features.empty() &&
        better(pw.local.triangles, mvc.uv, pp.mvc_stretch.l2, pp.triangles, pp.uv, pp.stretch.l2)) {
      t0 = Clock::now();
      StretchOptimizationOptions fallback = options.base_optimization;
      fallback.seed = options.seed + 31u * static_cast<unsigned>(p + 1);
      fallback.vertex.vertex_weights = weights;
      fallback.vertex.vertex_metrics = metrics;
      optimize_stretch(pw.local.positions, pw.local.triangles, mvc.uv, locked, fallback);
      const StretchValues s = mesh_stretch(pw.local.positions, pw.local.triangles, mvc.uv);
      if (better(pw.local.triangles, mvc.uv, s.l2, pp.triangles, pp.uv, pp.stretch.l2) &&
          count_flipped(pw.local.triangles, mvc.uv) == 0) {
        pp.triangles = pw.local.triangles;
        pp.uv = std::move(mvc.uv);
        pp.stretch = s;
        pp.boundary_off_chord = 0;
        pp.mvc_fallback = true;
      }
      seconds.final_optimization += seconds_since(t0);
    }
  }
  if (options.linf_sweeps > 0) {
    t0 = Clock::now();
    linf_pass(pw.local.positions, pp.triangles, pp.uv, locked, options, p);
    pp.stretch = mesh_stretch(pw.local.positions, pp.triangles, pp.uv);
    pp.flipped = count_flipped(pp.triangles, pp.uv);
    if (pp.flipped != 0) {  // optimize_stretch never folds: a bug if it happens
      throw SolverFailure("parameterize_consistently: the L-infinity pass left " + std::to_string(pp.flipped) +
                          " flipped triangles in patch " + std::to_string(p) + " of model '" + name + "'");
    }
    seconds.final_optimization += seconds_since(t0);
  }
  for (std::size_t j = 0; j < pw.features.size(); ++j) {
    FeatureLocation& f = features[pw.feature_index[j]];
    f.vertex = pw.to_mesh[pw.features[j]];
    f.patch = static_cast<int>(p);
    f.uv = pp.uv[pw.features[j]];
  }
  return pp;
}

}  // namespace

std::vector<ModelParameterization> parameterize_consistently(const std::vector<ParameterizationInput>& models,
                                                             const ParameterizationOptions& options) {
  if (models.empty()) throw InvalidInput("parameterize_consistently: no model");
  if (!(options.linf_floor >= 0) || !std::isfinite(options.linf_floor) || !(options.linf_relative_floor >= 0) ||
      !(options.linf_relative_floor <= 1))
    throw InvalidInput("parameterize_consistently: linf_floor must be finite and >= 0, linf_relative_floor in [0, 1]");
  if (!(options.curvature_metric >= 0) || !std::isfinite(options.curvature_metric))
    throw InvalidInput("parameterize_consistently: curvature_metric must be finite and >= 0");
  check_feature_counts(models);
  const std::size_t num_features = models[0].features.size();
  const double n = static_cast<double>(models.size());
  const Progress progress{options, 3.0 * n};
  std::vector<ModelWork> work;
  std::vector<ModelParameterization> out(models.size());

  // Phase A, per model: partition, patches, progressive meshes, base embeddings.
  for (std::size_t i = 0; i < models.size(); ++i) {
    work.push_back(prepare_model(models, i, i > 0 ? &work[0] : nullptr, options, progress, out[i]));
  }

  // Phase B, per patch: align corresponding features at their average (u,v) (§3.4).
  progress("feature alignment", n);
  if (num_features > 0) {
    for (std::size_t p = 0; p < work[0].patches.size(); ++p) {
      if (!work[0].patches[p].features.empty()) align_patch_features(work, p, models, out);
    }
  }

  // Phase C, per model and patch: coarse-to-fine with local stretch optimization, final sweeps.
  for (std::size_t i = 0; i < models.size(); ++i) {
    ModelWork& w = work[i];
    ModelParameterization& o = out[i];
    progress("coarse-to-fine", n + 2.0 * static_cast<double>(i));
    o.mesh = w.partition.mesh;
    o.adjacency = w.partition.adjacency;
    o.split_vertices = w.partition.split_vertices;
    o.features.assign(num_features, FeatureLocation{});
    // The patches in parallel; each writes only its own slots (and the features inside it).
    const std::size_t num_patches = w.patches.size();
    o.patches.resize(num_patches);
    std::vector<StageSeconds> seconds(num_patches);
    PatchProgress patch_progress(progress, "coarse-to-fine", n + 2.0 * static_cast<double>(i), 2.0,
                                 num_patches);
    for_each_patch(num_patches, options.threads, [&](std::size_t p) {
      o.patches[p] = parameterize_patch(w.patches[p], p, models[i].name, options, patch_progress, seconds[p],
                                        o.features);
      patch_progress(p, 1.0);
    });
    for (const StageSeconds& s : seconds) add_seconds(o.seconds, s);
    if (options.seam_slide_rounds > 0) {
      const auto t0 = Clock::now();
      std::vector<std::vector<double>> weights(num_patches);
      std::vector<std::vector<Eigen::Matrix3d>> metrics(num_patches);
      for (std::size_t p = 0; p < num_patches; ++p) weights[p] = w.patches[p].weights;
      for (std::size_t p = 0; p < num_patches; ++p) metrics[p] = w.patches[p].metrics;
      slide_seams(o, weights, metrics, options);
      o.seconds.final_optimization += seconds_since(t0);
    }
    o.seam_mismatches = reconcile_seams(o);
    // reconcile_seams may have moved seam vertices of a patch after its figures were taken (to a neighbour's
    // off-chord position): measure every patch again, so that `stretch` and `flipped` describe the output.
    for (PatchParameterization& patch : o.patches) {
      std::vector<Eigen::Vector3d> positions;
      positions.reserve(patch.vertices.size());
      for (int v : patch.vertices) positions.push_back(o.mesh.positions[v]);
      patch.stretch = mesh_stretch(positions, patch.triangles, patch.uv);
      patch.flipped = count_flipped(patch.triangles, patch.uv);
    }
  }
  report(options, "done", 1.0);
  return out;
}

}  // namespace geomip
