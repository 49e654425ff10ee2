// Properties of the geometric stretch metric (Sander et al. 2001): isometry, scaling, flips, an analytic
// anisotropic map, normalization invariances and the lower bound 1.
#include "param/stretch.h"
#include "mesh/errors.h"
#include "tests/param/test_meshes.h"

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace geomip {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A generic 3D triangle and its isometric image in uv (rotated and translated in the plane).
struct IsometricTriangle {
  Eigen::Vector3d q[3];
  Eigen::Vector2d p[3];
};

IsometricTriangle isometric_triangle() {
  IsometricTriangle t;
  // 3D triangle in a tilted plane spanned by orthonormal e1, e2.
  const Eigen::Vector3d e1 = Eigen::Vector3d(1, 2, 2).normalized();
  const Eigen::Vector3d e2 = e1.cross(Eigen::Vector3d(0, 0, 1)).normalized();
  const Eigen::Vector3d origin(0.3, -1.2, 4.0);
  const Eigen::Vector2d local[3] = {{0, 0}, {1.7, 0.2}, {0.4, 1.1}};
  const Eigen::Rotation2Dd rotation(0.7);
  for (int i = 0; i < 3; ++i) {
    t.q[i] = origin + local[i].x() * e1 + local[i].y() * e2;
    t.p[i] = rotation * local[i] + Eigen::Vector2d(5, -3);
  }
  return t;
}

TEST(TriangleStretch, IsometryIsOne) {
  const IsometricTriangle t = isometric_triangle();
  const StretchValues s = triangle_stretch(t.q, t.p);
  EXPECT_NEAR(s.l2, 1.0, 1e-12);
  EXPECT_NEAR(s.linf, 1.0, 1e-12);
}

TEST(TriangleStretch, UniformScaleOfUvGivesInverse) {
  IsometricTriangle t = isometric_triangle();
  for (double scale : {0.01, 0.5, 3.0, 250.0}) {
    Eigen::Vector2d p[3];
    for (int i = 0; i < 3; ++i) p[i] = scale * t.p[i];
    const StretchValues s = triangle_stretch(t.q, p);
    EXPECT_NEAR(s.l2, 1.0 / scale, 1e-12 / scale) << scale;
    EXPECT_NEAR(s.linf, 1.0 / scale, 1e-12 / scale) << scale;
  }
}

TEST(TriangleStretch, FlippedOrDegenerateIsInfinite) {
  IsometricTriangle t = isometric_triangle();
  const Eigen::Vector2d flipped[3] = {t.p[0], t.p[2], t.p[1]};
  EXPECT_TRUE(std::isinf(triangle_stretch(t.q, flipped).l2));
  EXPECT_TRUE(std::isinf(triangle_stretch(t.q, flipped).linf));
  const Eigen::Vector2d collinear[3] = {{0, 0}, {1, 1}, {2, 2}};
  EXPECT_TRUE(std::isinf(triangle_stretch(t.q, collinear).l2));
  const Eigen::Vector2d point[3] = {{1, 1}, {1, 1}, {1, 1}};
  EXPECT_TRUE(std::isinf(triangle_stretch(t.q, point).linf));
}

// uv = (x / 2, 3 y): the map uv → 3D is (s, t) ↦ (2s, t / 3), singular values 2 and 1/3 for any triangle.
TEST(TriangleStretch, AnisotropicScaleHasExactSingularValues) {
  const Eigen::Vector3d q[3] = {{0.1, 0.2, 0}, {1.3, 0.5, 0}, {0.4, 1.6, 0}};
  Eigen::Vector2d p[3];
  for (int i = 0; i < 3; ++i) p[i] = Eigen::Vector2d(q[i].x() / 2, 3 * q[i].y());
  const StretchValues s = triangle_stretch(q, p);
  EXPECT_NEAR(s.linf, 2.0, 1e-12);
  EXPECT_NEAR(s.l2, std::sqrt((4.0 + 1.0 / 9.0) / 2), 1e-12);
}

// A shear u = x + k y, v = y: the uv → 3D map is [[1, −k], [0, 1]] with Γ,γ = (sqrt(k²+4) ± k) / 2.
TEST(TriangleStretch, ShearMatchesClosedForm) {
  const double k = 1.5;
  const Eigen::Vector3d q[3] = {{0, 0, 0}, {1, 0, 0}, {0.2, 1, 0}};
  Eigen::Vector2d p[3];
  for (int i = 0; i < 3; ++i) p[i] = Eigen::Vector2d(q[i].x() + k * q[i].y(), q[i].y());
  const double big = (std::sqrt(k * k + 4) + k) / 2, small = (std::sqrt(k * k + 4) - k) / 2;
  const StretchValues s = triangle_stretch(q, p);
  EXPECT_NEAR(s.linf, big, 1e-12);
  EXPECT_NEAR(s.l2, std::sqrt((big * big + small * small) / 2), 1e-12);
  EXPECT_NEAR(big * small, 1.0, 1e-12);  // area preserved
}

std::vector<Eigen::Vector2d> xy(const TriMesh& m) {
  std::vector<Eigen::Vector2d> uv;
  for (const auto& p : m.positions) uv.emplace_back(p.x(), p.y());
  return uv;
}

/// The grid lifted onto a paraboloid z = a (x² + y²) (a curved surface whose xy projection is the unit
/// square).
TriMesh paraboloid(int n, double a) {
  TriMesh m = test::grid(n);
  for (auto& p : m.positions) p.z() = a * ((p.x() - 0.5) * (p.x() - 0.5) + (p.y() - 0.5) * (p.y() - 0.5));
  return m;
}

TEST(MeshStretch, FlatGridParameterizedByXyIsOne) {
  const TriMesh g = test::grid(7);
  const StretchValues s = mesh_stretch(g.positions, g.triangles, xy(g));
  EXPECT_NEAR(s.l2, 1.0, 1e-12);
  EXPECT_NEAR(s.linf, 1.0, 1e-12);
}

TEST(MeshStretch, InvariantToScalingUvAnd3d) {
  const TriMesh m = paraboloid(6, 1.3);
  const std::vector<Eigen::Vector2d> uv = xy(m);
  const StretchValues reference = mesh_stretch(m.positions, m.triangles, uv);
  EXPECT_GT(reference.l2, 1.01);  // a curved surface cannot be isometric to the plane
  EXPECT_GT(reference.linf, reference.l2);

  std::vector<Eigen::Vector2d> scaled_uv = uv;
  for (auto& p : scaled_uv) p = 4.5 * p + Eigen::Vector2d(-2, 7);
  const StretchValues su = mesh_stretch(m.positions, m.triangles, scaled_uv);
  EXPECT_NEAR(su.l2, reference.l2, 1e-12);
  EXPECT_NEAR(su.linf, reference.linf, 1e-12);

  std::vector<Eigen::Vector3d> scaled_positions = m.positions;
  for (auto& q : scaled_positions) q = 0.02 * q + Eigen::Vector3d(1, 2, 3);
  const StretchValues sq = mesh_stretch(scaled_positions, m.triangles, uv);
  EXPECT_NEAR(sq.l2, reference.l2, 1e-12);
  EXPECT_NEAR(sq.linf, reference.linf, 1e-12);
}

// The normalized L2 stretch is >= 1 for every embedding (Cauchy–Schwarz over Γγ = A3/A2), with equality for
// an isometry; L∞ >= L2.
TEST(MeshStretch, AtLeastOneForRandomEmbeddings) {
  const TriMesh g = test::grid(6);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.03, 0.03);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector2d> uv = xy(g);
    for (auto& p : uv) {
      if (p.x() > 0 && p.x() < 1 && p.y() > 0 && p.y() < 1) p += Eigen::Vector2d(jitter(rng), jitter(rng));
    }
    ASSERT_EQ(count_flipped(g.triangles, uv), 0u);
    const StretchValues s = mesh_stretch(g.positions, g.triangles, uv);
    EXPECT_GT(s.l2, 1.0);
    EXPECT_GE(s.linf, s.l2);
  }
}

TEST(MeshStretch, MatchesAreaWeightedTriangleStretch) {
  const TriMesh m = paraboloid(3, 0.8);
  std::vector<Eigen::Vector2d> uv = xy(m);
  double sum_a3 = 0, sum_a2 = 0, sum = 0, max_linf = 0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d q[3] = {m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]};
    const Eigen::Vector2d p[3] = {uv[t[0]], uv[t[1]], uv[t[2]]};
    const double a3 = 0.5 * (q[1] - q[0]).cross(q[2] - q[0]).norm();
    const StretchValues s = triangle_stretch(q, p);
    sum_a3 += a3;
    sum_a2 += 0.5 * signed_double_area(p[0], p[1], p[2]);
    sum += a3 * s.l2 * s.l2;
    max_linf = std::max(max_linf, s.linf);
  }
  const StretchValues s = mesh_stretch(m.positions, m.triangles, uv);
  EXPECT_NEAR(s.l2, std::sqrt(sum / sum_a3) * std::sqrt(sum_a2 / sum_a3), 1e-12);
  EXPECT_NEAR(s.linf, max_linf * std::sqrt(sum_a2 / sum_a3), 1e-12);
}

TEST(MeshStretch, AnyFlipGivesInfinity) {
  const TriMesh g = test::grid(4);
  std::vector<Eigen::Vector2d> uv = xy(g);
  uv[6] = Eigen::Vector2d(0.9, 0.9);  // interior vertex (1,1)/4 pushed across its ring
  EXPECT_GT(count_flipped(g.triangles, uv), 0u);
  const StretchValues s = mesh_stretch(g.positions, g.triangles, uv);
  EXPECT_TRUE(std::isinf(s.l2));
  EXPECT_TRUE(std::isinf(s.linf));
}

TEST(MeshStretch, RejectsBadInput) {
  const TriMesh g = test::grid(2);
  std::vector<Eigen::Vector2d> uv = xy(g);
  std::vector<Eigen::Vector2d> short_uv(uv.begin(), uv.end() - 1);
  EXPECT_THROW(mesh_stretch(g.positions, g.triangles, short_uv), InvalidInput);
  auto bad = g.triangles;
  bad[0][1] = 99;
  EXPECT_THROW(mesh_stretch(g.positions, bad, uv), InvalidInput);
  EXPECT_THROW(count_flipped(bad, uv), InvalidInput);
  EXPECT_THROW(mesh_stretch(g.positions, {}, uv), InvalidInput);
  std::vector<Eigen::Vector3d> flat(g.positions.size(), Eigen::Vector3d(1, 1, 1));
  EXPECT_THROW(mesh_stretch(flat, g.triangles, uv), InvalidInput);
}

TEST(CountFlipped, CountsFlippedAndDegenerate) {
  const TriMesh g = test::grid(3);
  std::vector<Eigen::Vector2d> uv = xy(g);
  EXPECT_EQ(count_flipped(g.triangles, uv), 0u);
  auto triangles = g.triangles;
  std::swap(triangles[0][1], triangles[0][2]);  // one clockwise triangle
  triangles.push_back({0, 0, 1});               // one degenerate triangle
  EXPECT_EQ(count_flipped(triangles, uv), 2u);
  for (auto& p : uv) p = Eigen::Vector2d(p.x(), -p.y());  // mirror: everything clockwise
  EXPECT_EQ(count_flipped(g.triangles, uv), g.triangles.size());
}

TEST(TriangleStretch, RotationOfUvDoesNotMatter) {
  IsometricTriangle t = isometric_triangle();
  const StretchValues base = triangle_stretch(t.q, t.p);
  for (double angle = 0; angle < 2 * kPi; angle += 0.9) {
    Eigen::Vector2d p[3];
    for (int i = 0; i < 3; ++i)
      p[i] = Eigen::Rotation2Dd(angle) * Eigen::Vector2d(t.p[i].x() * 2, t.p[i].y());
    const Eigen::Vector2d p0[3] = {Eigen::Vector2d(t.p[0].x() * 2, t.p[0].y()),
                                   Eigen::Vector2d(t.p[1].x() * 2, t.p[1].y()),
                                   Eigen::Vector2d(t.p[2].x() * 2, t.p[2].y())};
    const StretchValues a = triangle_stretch(t.q, p), b = triangle_stretch(t.q, p0);
    EXPECT_NEAR(a.l2, b.l2, 1e-12);
    EXPECT_NEAR(a.linf, b.linf, 1e-12);
    EXPECT_LT(a.l2, base.l2);  // stretching uv lowers stretch
  }
}

}  // namespace
}  // namespace geomip
