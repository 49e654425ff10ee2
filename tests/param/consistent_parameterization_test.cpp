// Properties of the whole parameterization (issue #3's "done means"): valid square embeddings, seams that
// agree, stretch below the MVC baseline, aligned features across models, clean errors.
#include "param/consistent_parameterization.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "param/partition_points.h"
#include "param/quad_layout.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace geomip {
namespace {

const Eigen::Vector2d kCorner[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

// Position of a side's vertex along the side, measured from corner k (0 at corner k, 1 at corner k+1).
double along_side(const Eigen::Vector2d& uv, int side) {
  switch (side) {
    case 0: return uv.x();
    case 1: return uv.y();
    case 2: return 1.0 - uv.x();
    default: return 1.0 - uv.y();
  }
}

// Every property a patch must have, whatever the model.
void expect_valid_patch(const PatchParameterization& p, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(count_flipped(p.triangles, p.uv), 0u);
  std::map<int, int> local;  // mesh id → local id
  for (std::size_t i = 0; i < p.vertices.size(); ++i) local[p.vertices[i]] = static_cast<int>(i);
  std::vector<char> on_boundary(p.vertices.size(), 0);
  for (int k = 0; k < 4; ++k) {
    ASSERT_EQ(p.uv[local.at(p.corners[k])], kCorner[k]) << "corner " << k;
    double last = -1.0;
    for (std::size_t j = 0; j < p.sides[k].size(); ++j) {
      const int v = local.at(p.sides[k][j]);
      on_boundary[v] = 1;
      const Eigen::Vector2d& uv = p.uv[v];
      // On the side: the fixed coordinate exactly 0 or 1.
      const double fixed = (k == 0) ? uv.y() : (k == 1) ? uv.x() : (k == 2) ? uv.y() : uv.x();
      EXPECT_EQ(fixed, (k == 0 || k == 3) ? 0.0 : 1.0) << "side " << k << " vertex " << j;
      const double s = along_side(uv, k);
      EXPECT_GT(s, last) << "side " << k << " not monotone at vertex " << j;
      last = s;
    }
  }
  for (std::size_t v = 0; v < p.uv.size(); ++v) {
    if (on_boundary[v]) continue;
    const Eigen::Vector2d& uv = p.uv[v];
    EXPECT_TRUE(uv.x() > 0 && uv.x() < 1 && uv.y() > 0 && uv.y() < 1) << "interior vertex " << v << " at " << uv.transpose();
  }
}

// A vertex on a shared side sits at the same distance from the shared corner in both patches.
void expect_seams_agree(const ModelParameterization& m) {
  std::vector<std::map<int, int>> local(m.patches.size());
  for (std::size_t p = 0; p < m.patches.size(); ++p) {
    for (std::size_t i = 0; i < m.patches[p].vertices.size(); ++i) local[p][m.patches[p].vertices[i]] = static_cast<int>(i);
  }
  for (const SideLink& link : m.adjacency) {
    const auto& a = m.patches[link.patch];
    const auto& b = m.patches[link.other_patch];
    const auto& side = a.sides[link.side];
    for (int v : side) {
      const double sa = along_side(a.uv[local[link.patch].at(v)], link.side);
      const double sb = along_side(b.uv[local[link.other_patch].at(v)], link.other_side);
      EXPECT_NEAR(sa, link.reversed ? 1.0 - sb : sb, 1e-12)
          << "vertex " << v << " on side " << link.side << " of patch " << link.patch;
    }
  }
}

void expect_valid(const ModelParameterization& m, const std::string& name) {
  EXPECT_EQ(m.seam_mismatches, 0u) << name;
  for (std::size_t p = 0; p < m.patches.size(); ++p) expect_valid_patch(m.patches[p], name + " patch " + std::to_string(p));
  expect_seams_agree(m);
  // Every triangle of the mesh is in exactly one patch.
  std::size_t triangles = 0;
  for (const auto& p : m.patches) triangles += p.triangles.size();
  EXPECT_EQ(triangles, m.mesh.triangles.size());
}

TEST(ConsistentParameterization, SphereGivesTwoValidSquares) {
  const auto result = parameterize_consistently({test::automatic_input(test::sphere(4), "sphere")});
  ASSERT_EQ(result.size(), 1u);
  ASSERT_EQ(result[0].patches.size(), 2u);
  expect_valid(result[0], "sphere");
  for (const auto& p : result[0].patches) EXPECT_LT(p.stretch.l2, p.mvc_stretch.l2);
}

TEST(ConsistentParameterization, TorusGivesFourValidSquares) {
  const auto result = parameterize_consistently({test::automatic_input(test::torus(48, 24), "torus")});
  ASSERT_EQ(result[0].patches.size(), 4u);
  expect_valid(result[0], "torus");
}

// Two differently deformed spheres with corresponding partition points and features: after the warp the
// features sit at identical (u,v).
// A sphere and a deformation of it (same vertex ids), with 4 corresponding partition points on the equator
// and 4 corresponding features off it.
std::vector<ParameterizationInput> deformed_sphere_pair() {
  const TriMesh a = test::sphere(4);
  TriMesh b = a;
  for (auto& p : b.positions) p = Eigen::Vector3d(1.6 * p.x() + 0.2 * p.y() * p.y(), p.y(), 0.7 * p.z() + 0.3 * p.x() * p.y());
  std::vector<ParameterizationInput> models(2);
  models[0].mesh = a;
  models[1].mesh = b;
  models[0].name = "a";
  models[1].name = "b";
  const Eigen::Vector3d corners[4] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  const Eigen::Vector3d features[4] = {{0.5, 0.5, 0.7}, {-0.5, 0.3, 0.8}, {0.2, -0.6, -0.75}, {-0.4, -0.4, -0.8}};
  for (auto& m : models) {
    for (const auto& c : corners) m.partition_points.push_back(test::nearest_vertex(a, c.normalized()));
    for (const auto& f : features) m.features.push_back(test::nearest_vertex(a, f.normalized()));
  }
  return models;
}

TEST(ConsistentParameterization, FeaturesAlignAcrossModels) {
  const std::vector<ParameterizationInput> models = deformed_sphere_pair();
  const auto result = parameterize_consistently(models);
  ASSERT_EQ(result.size(), 2u);
  expect_valid(result[0], "a");
  expect_valid(result[1], "b");
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(result[0].features[k].patch, result[1].features[k].patch);
    EXPECT_LE((result[0].features[k].uv - result[1].features[k].uv).norm(), 1e-9) << "feature " << k;
  }
}

TEST(ConsistentParameterization, RejectsBadInput) {
  const TriMesh s = test::sphere(3);
  ParameterizationInput in = test::automatic_input(s, "s");
  {
    ParameterizationInput bad = in;
    bad.partition_points[1] = bad.partition_points[0];
    EXPECT_THROW(parameterize_consistently({bad}), InvalidInput);  // not distinct
  }
  {
    ParameterizationInput bad = in;
    bad.partition_points[2] = static_cast<int>(s.positions.size()) + 5;
    EXPECT_THROW(parameterize_consistently({bad}), InvalidInput);  // out of range
  }
  {
    ParameterizationInput a = in, b = in;
    b.features = {in.partition_points[0] == 0 ? 1 : 0};
    EXPECT_THROW(parameterize_consistently({a, b}), InvalidInput);  // feature counts differ
  }
  {
    ParameterizationInput bad = in;
    bad.features = {bad.partition_points[0]};
    EXPECT_THROW(parameterize_consistently({bad}), InvalidInput);  // a feature on the cut
  }
  {
    ParameterizationInput bad = in;
    bad.mesh = test::join(test::torus(16, 8), test::torus(16, 8));  // two components
    EXPECT_THROW(parameterize_consistently({bad}), InvalidInput);
  }
}

// The patches run on several threads (ParameterizationOptions::threads), each with its own seeds: the result
// is bit-identical whatever the thread count, and a failure is the one a sequential run reports.
TEST(ConsistentParameterization, ThreadCountDoesNotChangeTheResult) {
  const std::vector<ParameterizationInput> models = {test::automatic_input(test::torus(48, 24), "torus")};
  ParameterizationOptions options;
  options.threads = 1;
  const auto one = parameterize_consistently(models, options);
  ASSERT_EQ(one[0].patches.size(), 4u);
  for (unsigned threads : {2u, 3u, 0u}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    options.threads = threads;
    const auto many = parameterize_consistently(models, options);
    ASSERT_EQ(many[0].patches.size(), one[0].patches.size());
    for (std::size_t p = 0; p < one[0].patches.size(); ++p) {
      const PatchParameterization &a = one[0].patches[p], &b = many[0].patches[p];
      EXPECT_EQ(a.vertices, b.vertices) << "patch " << p;
      EXPECT_EQ(a.triangles, b.triangles) << "patch " << p;
      ASSERT_EQ(a.uv.size(), b.uv.size()) << "patch " << p;
      for (std::size_t v = 0; v < a.uv.size(); ++v) {
        ASSERT_EQ(a.uv[v].x(), b.uv[v].x()) << "patch " << p << " vertex " << v;
        ASSERT_EQ(a.uv[v].y(), b.uv[v].y()) << "patch " << p << " vertex " << v;
      }
      EXPECT_EQ(a.stretch.l2, b.stretch.l2) << "patch " << p;
      EXPECT_EQ(a.stretch.linf, b.stretch.linf) << "patch " << p;
    }
  }
}

// Two models with features: what the patch threads write besides the uv (features, MVC figures, seams) is
// the same for 1, 2 and more threads than patches.
TEST(ConsistentParameterization, ThreadCountDoesNotChangeFeaturesOrFigures) {
  const std::vector<ParameterizationInput> models = deformed_sphere_pair();
  ParameterizationOptions options;
  options.threads = 1;
  const auto one = parameterize_consistently(models, options);
  ASSERT_EQ(one.size(), 2u);
  for (unsigned threads : {2u, 16u}) {
    options.threads = threads;
    const auto many = parameterize_consistently(models, options);
    ASSERT_EQ(many.size(), 2u);
    for (std::size_t m = 0; m < 2; ++m) {
      SCOPED_TRACE("threads " + std::to_string(threads) + ", model " + std::to_string(m));
      ASSERT_EQ(many[m].features.size(), one[m].features.size());
      for (std::size_t k = 0; k < one[m].features.size(); ++k) {
        EXPECT_EQ(many[m].features[k].vertex, one[m].features[k].vertex) << "feature " << k;
        EXPECT_EQ(many[m].features[k].patch, one[m].features[k].patch) << "feature " << k;
        EXPECT_EQ(many[m].features[k].uv.x(), one[m].features[k].uv.x()) << "feature " << k;
        EXPECT_EQ(many[m].features[k].uv.y(), one[m].features[k].uv.y()) << "feature " << k;
      }
      EXPECT_EQ(many[m].seam_mismatches, one[m].seam_mismatches);
      EXPECT_EQ(many[m].warp_events, one[m].warp_events);
      ASSERT_EQ(many[m].patches.size(), one[m].patches.size());
      for (std::size_t p = 0; p < one[m].patches.size(); ++p) {
        const PatchParameterization &a = one[m].patches[p], &b = many[m].patches[p];
        EXPECT_EQ(a.uv, b.uv) << "patch " << p;
        EXPECT_EQ(a.mvc_stretch.l2, b.mvc_stretch.l2) << "patch " << p;
        EXPECT_EQ(a.mvc_stretch.linf, b.mvc_stretch.linf) << "patch " << p;
        EXPECT_EQ(a.mvc_fallback, b.mvc_fallback) << "patch " << p;
        EXPECT_EQ(a.boundary_off_chord, b.boundary_off_chord) << "patch " << p;
        EXPECT_EQ(a.base_vertices, b.base_vertices) << "patch " << p;
      }
    }
  }
}

// Both patches of the sphere fail (the features lie on the cut, which every patch touches): the error is the
// lowest patch's, as in a sequential run, whichever thread fails first.
TEST(ConsistentParameterization, ThreadCountDoesNotChangeTheError) {
  ParameterizationInput bad = test::automatic_input(test::sphere(3), "s");
  bad.features = {bad.partition_points[2], bad.partition_points[0]};  // on the cut, in every patch
  std::string sequential, parallel;
  ParameterizationOptions options;
  options.threads = 1;
  try {
    parameterize_consistently({bad}, options);
  } catch (const InvalidInput& e) {
    sequential = e.what();
  }
  options.threads = 2;
  try {
    parameterize_consistently({bad}, options);
  } catch (const InvalidInput& e) {
    parallel = e.what();
  }
  EXPECT_NE(sequential.find("lies on the partition cut (patch 0)"), std::string::npos) << sequential;
  EXPECT_EQ(parallel, sequential);
}

class SharedMeshParameterization : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedMeshParameterization, EveryPatchIsAValidSquareAndSeamsAgree) {
  GEOMIP_REQUIRE_SHARED_MESH(path, GetParam());
  TriMesh mesh = read_mesh(path);
  const TopologyReport r = analyze_topology(mesh);
  if (r.boundary_loops > 0 || !r.manifold) mesh = repair_mesh(mesh).mesh;
  const auto result = parameterize_consistently({test::automatic_input(mesh, GetParam())});
  expect_valid(result[0], GetParam());
}

INSTANTIATE_TEST_SUITE_P(Shared, SharedMeshParameterization,
                         ::testing::Values("bunny.obj", "bunny-small.obj", "horse.obj", "cow.obj", "spot.obj",
                                           "pig.obj", "armadillo.obj", "max-planck.obj", "venus.obj",
                                           "fandisk.obj", "rocker-arm.obj", "bob.obj", "camelhead.obj", "igea.ply"),
                         [](const ::testing::TestParamInfo<const char*>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(ConsistentParameterizationReal, StretchOptimizationBeatsMvcOnTheBunny) {
  GEOMIP_REQUIRE_SHARED_MESH(path, "bunny.obj");
  const TriMesh bunny = repair_mesh(read_mesh(path)).mesh;
  const auto result = parameterize_consistently({test::automatic_input(bunny, "bunny")});
  for (const auto& p : result[0].patches) {
    EXPECT_LE(p.stretch.l2, 0.8 * p.mvc_stretch.l2) << "MVC " << p.mvc_stretch.l2 << " → " << p.stretch.l2;
  }
}

// The L∞ pass (ParameterizationOptions::linf_sweeps) runs after everything else, so a run without it is the
// "before": with it no patch's L∞ stretch rises, none folds, the locked vertices (boundary, features) keep
// their uv bit for bit, and some patch's L∞ drops. Two models with features over two squares, and an
// automatic 8-quad layout of one of them.
// The pair of deformed spheres (features, two squares) and the second of them on an automatic 8-quad layout.
std::vector<std::vector<ParameterizationInput>> pair_and_eight_quads() {
  ParameterizationInput in;
  in.mesh = deformed_sphere_pair()[1].mesh;
  in.name = "b, 8 quads";
  QuadLayoutOptions layout_options;
  layout_options.patches = 8;
  const QuadLayoutChoice layout = choose_quad_layout(in.mesh, layout_options);
  in.partition_points = layout.layout.corners;
  in.layout_quads = layout.layout.quads;
  return {deformed_sphere_pair(), {in}};
}

// The same uv, bit for bit, on 1 and on 3 threads.
void expect_same_on_one_and_three_threads(const std::vector<ParameterizationInput>& models,
                                          ParameterizationOptions options) {
  options.threads = 1;
  const auto one = parameterize_consistently(models, options);
  options.threads = 3;
  const auto three = parameterize_consistently(models, options);
  for (std::size_t m = 0; m < one.size(); ++m) {
    for (std::size_t p = 0; p < one[m].patches.size(); ++p) {
      const auto &x = one[m].patches[p].uv, &y = three[m].patches[p].uv;
      ASSERT_EQ(x.size(), y.size());
      for (std::size_t v = 0; v < x.size(); ++v) {
        ASSERT_EQ(x[v].x(), y[v].x()) << "model " << m << " patch " << p << " vertex " << v;
        ASSERT_EQ(x[v].y(), y[v].y()) << "model " << m << " patch " << p << " vertex " << v;
      }
    }
  }
}

TEST(ConsistentParameterization, LinfPassNeverRaisesLinfNorFolds) {
  std::vector<std::vector<ParameterizationInput>> cases = pair_and_eight_quads();
  for (const auto& models : cases) {
    SCOPED_TRACE(models[0].name);
    ParameterizationOptions options;
    options.measure_mvc_baseline = false;
    const auto before = parameterize_consistently(models, options);
    options.linf_sweeps = 30;
    options.linf_floor = 0;
    const auto after = parameterize_consistently(models, options);
    ASSERT_EQ(after.size(), before.size());
    bool lowered = false;
    for (std::size_t m = 0; m < after.size(); ++m) {
      ASSERT_EQ(after[m].patches.size(), before[m].patches.size());
      std::vector<char> feature(after[m].mesh.positions.size(), 0);
      for (const FeatureLocation& f : after[m].features) feature[f.vertex] = 1;
      for (std::size_t p = 0; p < after[m].patches.size(); ++p) {
        const PatchParameterization &a = after[m].patches[p], &b = before[m].patches[p];
        SCOPED_TRACE("model " + std::to_string(m) + " patch " + std::to_string(p));
        EXPECT_LE(a.stretch.linf, b.stretch.linf);
        lowered = lowered || a.stretch.linf < b.stretch.linf;
        EXPECT_EQ(a.flipped, 0u);
        EXPECT_EQ(count_flipped(a.triangles, a.uv), 0u);
        ASSERT_EQ(a.triangles, b.triangles);
        // The figures describe the output (taken after the seams are reconciled).
        std::vector<Eigen::Vector3d> positions;
        for (int v : a.vertices) positions.push_back(after[m].mesh.positions[v]);
        const StretchValues measured = mesh_stretch(positions, a.triangles, a.uv);
        EXPECT_EQ(a.stretch.linf, measured.linf);
        EXPECT_EQ(a.stretch.l2, measured.l2);
        const std::vector<char> boundary = boundary_vertex_mask(a.uv.size(), a.triangles);
        for (std::size_t v = 0; v < a.uv.size(); ++v) {
          if (!boundary[v] && !feature[a.vertices[v]]) continue;
          ASSERT_EQ(a.uv[v].x(), b.uv[v].x()) << "locked vertex " << v;
          ASSERT_EQ(a.uv[v].y(), b.uv[v].y()) << "locked vertex " << v;
        }
      }
      EXPECT_EQ(after[m].seam_mismatches, 0u);
    }
    EXPECT_TRUE(lowered);
    // Bit-identical for any thread count with the pass on, too.
    expect_same_on_one_and_three_threads(models, options);
  }
}

// The anisotropic curvature metric (ParameterizationOptions::curvature_metric) changes where the samples go,
// not what a parameterization guarantees: valid squares, seams that agree, no flips; a negative or NaN λ is
// refused.
TEST(ConsistentParameterization, CurvatureMetricKeepsValidSquares) {
  const TriMesh spiked = test::spiked_ellipsoid(4, 0.3);
  ParameterizationOptions options;
  options.measure_mvc_baseline = false;
  const auto plain = parameterize_consistently({test::automatic_input(spiked, "spiked")}, options);
  options.curvature_metric = 0.05;
  const auto metric = parameterize_consistently({test::automatic_input(spiked, "spiked")}, options);
  ASSERT_EQ(metric.size(), 1u);
  expect_valid(metric[0], "spiked, curvature metric");
  double moved = 0;
  for (std::size_t p = 0; p < metric[0].patches.size(); ++p) {
    ASSERT_EQ(metric[0].patches[p].uv.size(), plain[0].patches[p].uv.size());
    for (std::size_t v = 0; v < metric[0].patches[p].uv.size(); ++v)
      moved = std::max(moved, (metric[0].patches[p].uv[v] - plain[0].patches[p].uv[v]).norm());
  }
  EXPECT_GT(moved, 1e-3) << "the metric moves samples";
  // with sliding seams (compared in the metric) and the L∞ pass (Euclidean) on top: still valid
  options.seam_slide_rounds = 2;
  options.linf_sweeps = 20;
  const auto both = parameterize_consistently({test::automatic_input(spiked, "spiked")}, options);
  ASSERT_EQ(both.size(), 1u);
  expect_valid(both[0], "spiked, curvature metric, sliding seams, L-infinity pass");
  options.seam_slide_rounds = 0;
  options.linf_sweeps = 0;
  options.curvature_metric = -0.1;
  EXPECT_THROW(parameterize_consistently({test::automatic_input(spiked, "spiked")}, options), InvalidInput);
  options.curvature_metric = std::nan("");
  EXPECT_THROW(parameterize_consistently({test::automatic_input(spiked, "spiked")}, options), InvalidInput);
}

TEST(ConsistentParameterization, RejectsLinfFloorsOutOfRange) {
  ParameterizationOptions options;
  options.linf_floor = -1;
  EXPECT_THROW(parameterize_consistently(deformed_sphere_pair(), options), InvalidInput);
  options.linf_floor = 2;
  options.linf_relative_floor = 1.5;
  EXPECT_THROW(parameterize_consistently(deformed_sphere_pair(), options), InvalidInput);
}


// Σ A3·L2² over every patch of a model (each patch's uv square has area 1, so this is what a geometry image
// with one grid per patch pays for stretch; the quantity every stretch sweep and seam slide lowers).
double stretch_energy(const ModelParameterization& m) {
  double e = 0;
  for (const PatchParameterization& p : m.patches) {
    for (const auto& t : p.triangles) {
      const Eigen::Vector3d q[3] = {m.mesh.positions[p.vertices[t[0]]], m.mesh.positions[p.vertices[t[1]]],
                                    m.mesh.positions[p.vertices[t[2]]]};
      const Eigen::Vector2d uv[3] = {p.uv[t[0]], p.uv[t[1]], p.uv[t[2]]};
      const double l2 = triangle_stretch(q, uv).l2;
      e += 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm() * l2 * l2;
    }
  }
  return e;
}

// Sliding seams move seam vertices along their sides (away from their chord-length places) only where that
// lowers the stretch of both patches together, and sweep the interiors after: the total stretch energy never
// rises, nothing folds, both copies of every seam vertex stay at the same place on their sides (in order),
// features and corners stay where they were, and the result is the same on any number of threads. Cases: a
// consistent pair with features, an 8-quad layout, and a tip loop (sides with many guides).
TEST(ConsistentParameterization, SlidingSeamsLowerTheStretchAndKeepTheSeams) {
  std::vector<std::vector<ParameterizationInput>> cases = pair_and_eight_quads();
  {
    ParameterizationInput in;
    in.mesh = test::spiked_ellipsoid(4, 0.15);
    in.name = "spiked, tip loop";
    PartitionPointsOptions points;
    points.tip_loop = true;
    const PartitionPoints chosen = choose_partition_points(in.mesh, points);
    ASSERT_FALSE(chosen.side_guides.empty());
    in.partition_points = chosen.partition_points;
    in.side_guides = chosen.side_guides;
    cases.push_back({in});
  }
  for (const auto& models : cases) {
    SCOPED_TRACE(models[0].name);
    ParameterizationOptions options;
    options.measure_mvc_baseline = false;
    options.curvature_sampling = false;  // the plain energy stretch_energy() measures
    const auto before = parameterize_consistently(models, options);
    options.seam_slide_rounds = 3;
    const auto after = parameterize_consistently(models, options);
    ASSERT_EQ(after.size(), before.size());
    for (std::size_t m = 0; m < after.size(); ++m) {
      expect_valid(after[m], models[m].name);
      EXPECT_LE(stretch_energy(after[m]), stretch_energy(before[m]) * (1 + 1e-12));
      std::size_t moved = 0;
      for (std::size_t p = 0; p < after[m].patches.size(); ++p) {
        const PatchParameterization &a = after[m].patches[p], &b = before[m].patches[p];
        ASSERT_EQ(a.triangles, b.triangles);
        for (int k = 0; k < 4; ++k) {
          for (std::size_t j = 1; j + 1 < a.sides[k].size(); ++j) {
            const auto it = std::find(a.vertices.begin(), a.vertices.end(), a.sides[k][j]);
            const std::size_t v = static_cast<std::size_t>(it - a.vertices.begin());
            moved += (a.uv[v] - b.uv[v]).norm() > 1e-6;
          }
        }
      }
      EXPECT_GT(moved, 0u) << "no seam vertex slid: the test does not exercise the slide";
      for (std::size_t f = 0; f < after[m].features.size(); ++f) {
        EXPECT_EQ(after[m].features[f].uv, before[m].features[f].uv) << "feature " << f;
        const PatchParameterization& patch = after[m].patches[after[m].features[f].patch];
        const auto it = std::find(patch.vertices.begin(), patch.vertices.end(), after[m].features[f].vertex);
        ASSERT_NE(it, patch.vertices.end());
        EXPECT_EQ(patch.uv[static_cast<std::size_t>(it - patch.vertices.begin())], after[m].features[f].uv);
      }
    }
    expect_same_on_one_and_three_threads(models, options);
  }
}

}  // namespace
}  // namespace geomip
