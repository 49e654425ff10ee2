// Properties of measure_surface_distance() on synthetic surfaces with known distances (label unit).
#include "gimage/surface_distance.h"

#include "mesh/errors.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace geomip {
namespace {

TriMesh transformed(TriMesh m, const Eigen::Affine3d& t) {
  for (auto& p : m.positions) p = t * p;
  return m;
}

// The unit square [0,1]² in z = 0 as an n×n grid, rotated by `r` (so that nothing is axis-aligned).
TriMesh square(int n, const Eigen::Matrix3d& r = Eigen::Matrix3d::Identity()) {
  return transformed(test::grid(n), Eigen::Affine3d(r));
}

Eigen::Matrix3d some_rotation() {
  return (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) *
          Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

void expect_identical(const SurfaceDistance& a, const SurfaceDistance& b) {
  for (const auto* pair : {&a.original_to_approx, &a.approx_to_original}) {
    const OneSidedDistance& x = *pair;
    const OneSidedDistance& y = pair == &a.original_to_approx ? b.original_to_approx : b.approx_to_original;
    EXPECT_EQ(x.max, y.max);
    EXPECT_EQ(x.mean, y.mean);
    EXPECT_EQ(x.rms, y.rms);
    EXPECT_EQ(x.samples(), y.samples());
  }
  EXPECT_EQ(a.psnr_db, b.psnr_db);
}

TEST(SurfaceDistance, IdenticalMeshesMeasureZeroAndInfinitePsnr) {
  for (const TriMesh& m : {test::sphere(3), test::torus(24, 12), square(6, some_rotation())}) {
    const SurfaceDistance d = measure_surface_distance(m, m);
    EXPECT_EQ(d.hausdorff, 0.0);
    EXPECT_EQ(d.rms, 0.0);
    EXPECT_EQ(d.original_to_approx.mean, 0.0);
    EXPECT_EQ(d.hausdorff_pct, 0.0);
    EXPECT_TRUE(std::isinf(d.psnr_db) && d.psnr_db > 0) << d.psnr_db;
    // Sampling: every vertex, plus the automatic count (10 per face, at least 10,000).
    EXPECT_EQ(d.original_to_approx.vertex_samples, m.num_vertices());
    EXPECT_EQ(d.original_to_approx.face_samples, std::max<std::size_t>(10000, 10 * m.num_triangles()));
    EXPECT_EQ(d.original_to_approx.edge_samples, 0u);
  }
}

TEST(SurfaceDistance, SquareTranslatedAlongItsNormalIsAtThatDistanceEverywhere) {
  const Eigen::Matrix3d r = some_rotation();
  const TriMesh a = square(8, r);
  for (double offset : {1e-4, 0.01, 0.3}) {
    // The copy has a different triangulation, so that samples do not fall on matching triangles.
    const TriMesh b = transformed(square(5, r), Eigen::Affine3d(Eigen::Translation3d(offset * r.col(2))));
    const SurfaceDistance d = measure_surface_distance(a, b);
    for (const OneSidedDistance& s : {d.original_to_approx, d.approx_to_original}) {
      EXPECT_NEAR(s.max, offset, 1e-12);
      EXPECT_NEAR(s.mean, offset, 1e-12);
      EXPECT_NEAR(s.rms, offset, 1e-12);
    }
    const double diagonal = referenced_bounding_box(a).diagonal();  // of the original, not of the copy
    EXPECT_EQ(d.bbox_diagonal, diagonal);
    EXPECT_NEAR(d.hausdorff_pct, 100 * offset / diagonal, 1e-9);
    EXPECT_NEAR(d.rms_pct, 100 * offset / diagonal, 1e-9);
    EXPECT_NEAR(d.psnr_db, 20 * std::log10(diagonal / offset), 1e-8);
  }
}

TEST(SurfaceDistance, SphereScaledByOnePlusEpsilonIsEpsilonAway) {
  // A polyhedral sphere and its copy scaled by 1+ε about the centre: every face moves along its normal by ε
  // times its distance to the centre (0.997..1 at this level), so all distances are within 1% of ε.
  const TriMesh inner = test::sphere(4);
  for (double eps : {1e-3, 1e-2}) {
    const TriMesh outer = transformed(inner, Eigen::Affine3d(Eigen::Scaling(1 + eps)));
    const SurfaceDistance d = measure_surface_distance(inner, outer);
    for (const OneSidedDistance& s : {d.original_to_approx, d.approx_to_original}) {
      EXPECT_NEAR(s.max, eps, 0.01 * eps);
      EXPECT_NEAR(s.rms, eps, 0.01 * eps);
      EXPECT_LE(s.mean, s.rms);
      EXPECT_GT(s.mean, 0.99 * eps);
    }
    EXPECT_NEAR(d.bbox_diagonal, 2 * std::sqrt(3.0), 1e-12);  // the axis points (±1,0,0)… are vertices
    EXPECT_NEAR(d.psnr_db, 20 * std::log10(2 * std::sqrt(3.0) / eps), 0.1);  // 1% of ε ≈ 0.09 dB
  }
}

TEST(SurfaceDistance, ErrorMapsLocateTheErrorAndAgreeWithTheTotals) {
  // The square z = 0 against the plane z = a·x (a square tilted about the y axis, beyond the first one so
  // that every closest point is interior): the distance of (x, y, 0) is a·x/√(1+a²), growing with x.
  const double a = 0.1;
  const TriMesh flat = square(9);
  TriMesh tilted = test::grid(4);
  for (auto& p : tilted.positions) p = Eigen::Vector3d(3 * p.x() - 1, 3 * p.y() - 1, 0);
  for (auto& p : tilted.positions) p.z() = a * p.x();
  auto distance = [&](const Eigen::Vector3d& p) { return a * p.x() / std::sqrt(1 + a * a); };

  SurfaceDistanceOptions options;
  options.error_maps = true;
  const SurfaceDistance d = measure_surface_distance(flat, tilted, options);
  const OneSidedDistance& s = d.original_to_approx;
  ASSERT_EQ(s.vertex_distance.size(), flat.num_vertices());
  ASSERT_EQ(s.face_rms.size(), flat.num_triangles());
  for (std::size_t v = 0; v < flat.num_vertices(); ++v)
    EXPECT_NEAR(s.vertex_distance[v], distance(flat.positions[v]), 1e-6) << v;
  // A face's RMS lies between the smallest and largest distance of its corners (the distance is linear on
  // it).
  double sum_squares = 0;
  std::size_t with_samples = 0;
  for (std::size_t f = 0; f < flat.num_triangles(); ++f) {
    ASSERT_TRUE(std::isfinite(s.face_rms[f])) << f;  // 10 samples per face on average over 128 faces
    double lo = 1e9, hi = -1e9;
    for (int v : flat.triangles[f]) {
      lo = std::min(lo, distance(flat.positions[v]));
      hi = std::max(hi, distance(flat.positions[v]));
    }
    EXPECT_GE(s.face_rms[f], lo - 1e-6) << f;
    EXPECT_LE(s.face_rms[f], hi + 1e-6) << f;
    sum_squares += double(s.face_rms[f]) * s.face_rms[f];
    ++with_samples;
  }
  EXPECT_GT(with_samples, 0u);
  // The maximum sits on the side x = 1 (where the distance is largest) and has the distance there.
  EXPECT_NEAR(s.max_at.x(), 1.0, 1e-9);
  EXPECT_NEAR(s.max, distance(s.max_at), 1e-9);
  EXPECT_NEAR(s.max, distance(Eigen::Vector3d(1, 0, 0)), 1e-9);
  // Maps do not change the totals.
  const SurfaceDistance plain = measure_surface_distance(flat, tilted);
  expect_identical(d, plain);
  EXPECT_TRUE(plain.original_to_approx.face_rms.empty());
  // The other side: tilted-plane vertices beyond the unit square are farther than any face of the square.
  const OneSidedDistance& back = d.approx_to_original;
  ASSERT_EQ(back.vertex_distance.size(), tilted.num_vertices());
  EXPECT_NEAR(back.max, *std::max_element(back.vertex_distance.begin(), back.vertex_distance.end()), 1e-6);
}

TEST(SurfaceDistance, PatchInsideSquareIsOneSided) {
  // A patch [¼,¾]² inside the unit square: every point of the patch lies on the square (distance 0), while
  // the square's corners are √2/4 from the patch. Area RMS of the square → patch distance: ∫d² = 1/48 over
  // area 1.
  const Eigen::Matrix3d r = some_rotation();
  const TriMesh big = square(8, r);
  const Eigen::Affine3d to_patch =
      Eigen::Affine3d(r) * Eigen::Translation3d(0.25, 0.25, 0) * Eigen::Scaling(0.5);
  const TriMesh patch = transformed(test::grid(3), to_patch);

  const SurfaceDistance d = measure_surface_distance(big, patch);
  EXPECT_EQ(d.approx_to_original.max, 0.0);
  EXPECT_EQ(d.approx_to_original.rms, 0.0);
  EXPECT_NEAR(d.original_to_approx.max, std::sqrt(2.0) / 4, 1e-12);  // a corner vertex, sampled exactly
  EXPECT_NEAR(d.hausdorff, std::sqrt(2.0) / 4, 1e-12);
  EXPECT_EQ(d.rms, d.original_to_approx.rms);

  // Swapping the roles swaps the directions (and the peak: the patch's diagonal).
  const SurfaceDistance swapped = measure_surface_distance(patch, big);
  EXPECT_EQ(swapped.original_to_approx.max, 0.0);
  EXPECT_NEAR(swapped.approx_to_original.max, std::sqrt(2.0) / 4, 1e-12);
  EXPECT_EQ(swapped.bbox_diagonal, referenced_bounding_box(patch).diagonal());
  EXPECT_LT(swapped.bbox_diagonal, d.bbox_diagonal);

  // Face samples alone estimate the area integral: RMS → √(1/48) = 0.1443, also when the square's triangles
  // have very different areas (grid lines at x², y²: face-uniform instead of area-uniform sampling would
  // crowd the corner at the origin and miss by ~20%).
  TriMesh warped = test::grid(16);
  for (auto& p : warped.positions) p = Eigen::Vector3d(p.x() * p.x(), p.y() * p.y(), 0);
  SurfaceDistanceOptions faces_only;
  faces_only.sample_vertices = false;
  faces_only.face_samples = 200000;
  const SurfaceDistance area =
      measure_surface_distance(transformed(warped, Eigen::Affine3d(r)), patch, faces_only);
  EXPECT_EQ(area.original_to_approx.vertex_samples, 0u);
  EXPECT_EQ(area.original_to_approx.samples(), 200000u);
  EXPECT_NEAR(area.original_to_approx.rms, std::sqrt(1.0 / 48), 0.005 * std::sqrt(1.0 / 48));
}

TEST(SurfaceDistance, EdgeSamplesFollowTheEdges) {
  // Samples along the big square's edges (spaced ~0.003 apart) come close to its corners, the farthest points
  // from the patch (√2/4), and never beyond; samples along the patch's edges all lie on the square.
  const TriMesh big = square(4);
  const TriMesh patch =
      transformed(test::grid(2), Eigen::Affine3d(Eigen::Translation3d(0.25, 0.25, 0) * Eigen::Scaling(0.5)));
  SurfaceDistanceOptions options;
  options.edge_samples = 5000;
  options.sample_vertices = false;
  options.face_samples = 1;
  const SurfaceDistance d = measure_surface_distance(big, patch, options);
  EXPECT_EQ(d.original_to_approx.edge_samples, 5000u);
  EXPECT_EQ(d.original_to_approx.face_samples, 1u);
  EXPECT_LE(d.original_to_approx.max, std::sqrt(2.0) / 4 + 1e-12);
  EXPECT_GT(d.original_to_approx.max, std::sqrt(2.0) / 4 - 0.01);
  EXPECT_EQ(d.approx_to_original.max, 0.0);
}

TEST(SurfaceDistance, PsnrIsInvariantToUniformScaling) {
  const TriMesh fine = test::sphere(4);
  const TriMesh coarse = test::sphere(2);
  const SurfaceDistance d = measure_surface_distance(fine, coarse);
  ASSERT_GT(d.rms, 0.0);
  for (double s : {1e-3, 7.3, 250.0}) {
    const Eigen::Affine3d t = Eigen::Translation3d(1, -2, 3) * Eigen::Scaling(s);
    const SurfaceDistance ds = measure_surface_distance(transformed(fine, t), transformed(coarse, t));
    EXPECT_NEAR(ds.psnr_db, d.psnr_db, 1e-6) << s;
    EXPECT_NEAR(ds.hausdorff_pct, d.hausdorff_pct, 1e-6 * d.hausdorff_pct) << s;
    EXPECT_NEAR(ds.rms_pct, d.rms_pct, 1e-6 * d.rms_pct) << s;
    EXPECT_NEAR(ds.rms, s * d.rms, 1e-6 * s * d.rms) << s;
  }
}

TEST(SurfaceDistance, DeterministicForASeedWhateverTheThreads) {
  const TriMesh fine = test::torus(40, 20);
  const TriMesh coarse = test::torus(10, 6);
  SurfaceDistanceOptions options;
  options.seed = 42;
  options.face_samples = 30000;  // several chunks of work
  options.threads = 1;
  const SurfaceDistance a = measure_surface_distance(fine, coarse, options);
  options.threads = 3;
  const SurfaceDistance b = measure_surface_distance(fine, coarse, options);
  expect_identical(a, b);
  const SurfaceDistance again = measure_surface_distance(fine, coarse, options);
  expect_identical(a, again);
  // Another seed draws other face samples: the estimates move, but by sampling noise only.
  options.seed = 43;
  const SurfaceDistance c = measure_surface_distance(fine, coarse, options);
  EXPECT_NE(c.original_to_approx.rms, a.original_to_approx.rms);
  EXPECT_NEAR(c.original_to_approx.rms, a.original_to_approx.rms, 0.02 * a.original_to_approx.rms);
  EXPECT_NEAR(c.psnr_db, a.psnr_db, 0.2);
}

TEST(SurfaceDistance, FaceSamplesHintedByTheirNeighboursMeasureTheUnhintedDistances) {
  // Consecutive face samples of one face start their query from the previous one's answer; the distances must
  // be those of plain closest-point queries (distances_to_surface()), sample for sample, so the RMS agrees to
  // rounding. A bumpy approximation, so that the closest triangle changes often between a face's samples.
  const TriMesh original = test::sphere(3);
  TriMesh bumpy = test::sphere(2);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> scale(0.97, 1.03);
  for (auto& p : bumpy.positions) p *= scale(random);
  SurfaceDistanceOptions options;
  options.face_samples = 20000;  // about 16 per face, over several chunks
  options.threads = 2;
  const SurfaceDistance d = measure_surface_distance(original, bumpy, options);
  const std::vector<Eigen::Vector3d> points =
      sample_surface_points(original, options.face_samples, options.seed);
  ASSERT_EQ(points.size(), d.original_to_approx.samples());
  double sum = 0;
  for (double x : distances_to_surface(bumpy, points)) sum += x * x;
  EXPECT_NEAR(d.original_to_approx.rms, std::sqrt(sum / static_cast<double>(points.size())),
              1e-12 * d.original_to_approx.rms);
}

TEST(SurfaceDistance, MoreSamplesConvergeOnTheSameRms) {
  const TriMesh fine = test::sphere(4);
  const TriMesh coarse = test::sphere(1);
  SurfaceDistanceOptions options;
  options.face_samples = 200000;
  const double reference = measure_surface_distance(fine, coarse, options).rms;
  for (std::size_t n : {20000u, 100000u}) {
    options.face_samples = n;
    options.seed = n;
    EXPECT_NEAR(measure_surface_distance(fine, coarse, options).rms, reference, 0.03 * reference) << n;
  }
}

TEST(SurfaceDistance, UnreferencedVerticesAndZeroAreaTrianglesAreIgnored) {
  const TriMesh a = test::sphere(3);
  const TriMesh b = test::sphere(2);
  const SurfaceDistance clean = measure_surface_distance(a, b);

  TriMesh a_noisy = a;
  a_noisy.positions.emplace_back(100, 100, 100);  // unreferenced: not sampled, not in the bounding box
  TriMesh b_noisy = b;
  const int v0 = b_noisy.triangles[0][0], v1 = b_noisy.triangles[0][1];
  b_noisy.triangles.push_back({v0, v1, v0});  // zero area: not searched, no face samples
  b_noisy.positions.push_back(0.5 * (b.positions[v0] + b.positions[v1]));
  b_noisy.triangles.push_back({v0, v1, static_cast<int>(b_noisy.positions.size()) - 1});  // collinear
  const SurfaceDistance noisy = measure_surface_distance(a_noisy, b_noisy);

  EXPECT_EQ(noisy.bbox_diagonal, clean.bbox_diagonal);
  EXPECT_EQ(noisy.original_to_approx.vertex_samples, clean.original_to_approx.vertex_samples);
  EXPECT_EQ(noisy.original_to_approx.max, clean.original_to_approx.max);
  EXPECT_EQ(noisy.original_to_approx.rms, clean.original_to_approx.rms);
  EXPECT_TRUE(std::isfinite(noisy.approx_to_original.rms));
  // The midpoint is sampled as a vertex (it lies on b's edge, inside the sphere): max cannot shrink.
  EXPECT_GE(noisy.approx_to_original.max, clean.approx_to_original.max);
}

TEST(SurfaceDistance, BadInputThrowsInvalidInput) {
  const TriMesh good = test::tetrahedron();
  auto expect_invalid = [&](const TriMesh& bad, const std::string& needle) {
    for (bool bad_is_original : {true, false}) {
      try {
        if (bad_is_original) {
          measure_surface_distance(bad, good);
        } else {
          measure_surface_distance(good, bad);
        }
        ADD_FAILURE() << "no exception for " << needle;
      } catch (const InvalidInput& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("measure_surface_distance"), std::string::npos) << what;
        EXPECT_NE(what.find(bad_is_original ? "original" : "approx"), std::string::npos) << what;
        EXPECT_NE(what.find(needle), std::string::npos) << what;
      }
    }
  };
  expect_invalid(TriMesh{}, "no triangles");
  TriMesh points_only = good;
  points_only.triangles.clear();
  expect_invalid(points_only, "no triangles");
  TriMesh out_of_range = good;
  out_of_range.triangles[1][2] = 4;
  expect_invalid(out_of_range, "out of range");
  TriMesh negative = good;
  negative.triangles[0][0] = -1;
  expect_invalid(negative, "out of range");
  TriMesh nan = good;
  nan.positions[2].y() = std::numeric_limits<double>::quiet_NaN();
  expect_invalid(nan, "non-finite");
  TriMesh flat;
  flat.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}, {0, 0, 1}};
  expect_invalid(flat, "nonzero area");
}

TEST(SurfaceQuery, CrossingNearestTheHintWithinReach) {
  const TriMesh unit_sphere = test::sphere(3);  // vertices on the unit sphere, flat faces inside it
  const SurfaceQuery lines(unit_sphere);
  const Eigen::Vector3d origin(0.01, 0.02, 0), direction(0, 0, 3);  // any length
  const auto top = lines.crossing_near(origin, direction, Eigen::Vector3d(0, 0, 0.9), 0.3);
  ASSERT_TRUE(top.has_value());
  EXPECT_NEAR(top->x(), 0.01, 1e-12);
  EXPECT_NEAR(top->y(), 0.02, 1e-12);
  EXPECT_GT(top->z(), 0.9);  // the polyhedron lies inside the sphere, near it
  EXPECT_LE(top->z(), 1.0);
  const auto bottom = lines.crossing_near(origin, direction, Eigen::Vector3d(0, 0, -0.9), 0.3);
  ASSERT_TRUE(bottom.has_value());
  EXPECT_NEAR(bottom->z(), -top->z(), 0.05);
  EXPECT_FALSE(lines.crossing_near(origin, direction, Eigen::Vector3d(0, 0, 0.5), 0.3).has_value());
  EXPECT_FALSE(lines.crossing_near(origin, direction, Eigen::Vector3d(0.5, 0, 0.95), 0.3).has_value())
      << "the hint is farther than the reach from the line";
  EXPECT_FALSE(lines.crossing_near(origin, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.9), 0.3));
  EXPECT_FALSE(lines.crossing_near(origin, direction, Eigen::Vector3d(0, 0, NAN), 0.3));
}

TEST(SurfaceQuery, NormalNearIsTheInterpolatedVertexNormal) {
  const SurfaceQuery on_sphere(test::sphere(3));  // vertex normals ≈ radial
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 2), Eigen::Vector3d(0.3, -0.5, 0.1), Eigen::Vector3d(-1, -1, -1)})
    EXPECT_GT(on_sphere.normal_near(p).dot(p.normalized()), 0.99) << p.transpose();
  const SurfaceQuery on_square(square(4, some_rotation()));  // flat: every normal is the plane's
  const Eigen::Vector3d plane_normal = some_rotation() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d n = on_square.normal_near(some_rotation() * Eigen::Vector3d(0.3, 0.6, 0.5));
  EXPECT_NEAR(std::abs(n.dot(plane_normal)), 1.0, 1e-12);
  EXPECT_NEAR(n.norm(), 1.0, 1e-12);
}

// A hint never changes the distance: from any triangle, far or near, zero-area or out of range, the hinted
// query finds a point as close as the unhinted one, on the surface (its triangle holds it).
TEST(SurfaceQuery, HintedClosestIsAsCloseAsUnhinted) {
  TriMesh mesh = test::sphere(3);
  mesh.triangles.push_back({0, 0, 1});  // a zero-area triangle to hint at (not in the tree)
  const SurfaceQuery query(mesh);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5);
  const std::size_t zero_area = mesh.triangles.size() - 1;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    const SurfaceQuery::Closest plain = query.closest(p);
    const double d = (plain.point - p).norm();
    for (std::size_t hint :
         {plain.triangle, static_cast<std::size_t>(i) % zero_area, zero_area, mesh.triangles.size() + 5}) {
      const SurfaceQuery::Closest hinted = query.closest(p, hint);
      EXPECT_NEAR((hinted.point - p).norm(), d, 1e-12 * (1 + d)) << "point " << i << ", hint " << hint;
      ASSERT_LT(hinted.triangle, zero_area);
      const auto& t = mesh.triangles[hinted.triangle];
      const Eigen::Vector3d a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
      EXPECT_NEAR((b - a).cross(c - a).normalized().dot(hinted.point - a), 0.0, 1e-12)
          << "the point lies in its triangle's plane";
    }
  }
}

TEST(SurfaceQuery, LineInATrianglesPlaneTakesTheOverlapsEnds) {
  const SurfaceQuery lines(square(4));
  const auto hit = lines.crossing_near(Eigen::Vector3d(-1, 0.5, 0), Eigen::Vector3d(1, 0, 0),
                                       Eigen::Vector3d(-0.1, 0.5, 0), 0.5);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->x(), 0.0, 1e-12);  // the square's edge x = 0 is the nearest point of the overlap
  EXPECT_THROW(SurfaceQuery(TriMesh{}), InvalidInput);
}

}  // namespace
}  // namespace geomip
