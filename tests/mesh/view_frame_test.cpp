// The viewer's frame of a mesh (mesh/view_frame.h): a four-legged "table" in any of the 24 axis-aligned
// orientations rests on its legs and is turned upright with its higher end in front; the rotation is proper
// (a signed permutation, det +1); the normalization maps the rotated box onto the centred unit box. On the
// animals of ../shared/meshes the guessed up axis is the one their data has (seen in the meshes: the horse
// stands on −z, the pig lies on its back with its legs towards +y, cow and bunny stand on −y) and the front
// is the head's end (the pig's head rests lower than its rump: a lying animal with ears covers that case).
// Upright shapes (a bust with a nose, a biped whose arm span is its longest extent; the shared heads, busts
// and the armadillo) turn their face to +z, the default camera's side.
#include "mesh/view_frame.h"
#include "mesh/mesh_io.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <utility>

namespace geomip {
namespace {

/// Adds an axis-aligned box [lo, hi] as 12 triangles.
void add_box(TriMesh& m, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const int base = static_cast<int>(m.positions.size());
  for (int i = 0; i < 8; ++i)
    m.positions.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({base + q[0], base + q[1], base + q[2]});
    m.triangles.push_back({base + q[0], base + q[2], base + q[3]});
  }
}

/// A quadruped in its own frame: y up, standing on four legs, 2 long along x, a "head" block at +x that
/// reaches higher than the body's back.
TriMesh animal() {
  TriMesh m;
  add_box(m, {-1, 0.5, -0.3}, {0.8, 1.0, 0.3});     // body
  add_box(m, {0.8, 0.6, -0.15}, {1.0, 1.4, 0.15});  // head, above the back
  for (double x : {-0.8, 0.5})
    for (double z : {-0.25, 0.2}) add_box(m, {x, 0, z}, {x + 0.1, 0.5, z + 0.05});  // legs
  return m;
}

/// The 24 proper axis-aligned rotations.
std::vector<Eigen::Matrix3d> axis_rotations() {
  std::vector<Eigen::Matrix3d> out;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d r = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) r(i, p[i]) = signs & (1 << i) ? -1 : 1;
      if (r.determinant() > 0) out.push_back(r);
    }
  return out;
}

TEST(ViewFrame, AnAnimalInAnyAxisOrientationIsTurnedUprightHeadInFront) {
  const TriMesh base = animal();
  const auto rotations = axis_rotations();
  ASSERT_EQ(rotations.size(), 24u);
  for (const Eigen::Matrix3d& q : rotations) {
    TriMesh m = base;
    for (auto& p : m.positions) p = q * p;  // the data's frame: up = q·y, head = q·x
    EXPECT_TRUE(ground_direction(m).isApprox(-(q * Eigen::Vector3d::UnitY()))) << q;
    const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
    EXPECT_TRUE((r * r.transpose()).isApprox(Eigen::Matrix3d::Identity()));
    EXPECT_TRUE((r * q).isApprox(Eigen::Matrix3d::Identity())) << "turned back into its own frame:\n"
                                                               << r * q;
  }
}

/// A quadruped lying down, y up, 2 long along x: its head (at +x) rests on the ground, lower than its rump,
/// with ears out to the sides; the body's bulk is behind the middle of its length.
TEST(ViewFrame, ALyingAnimalWhoseHeadIsLowerThanItsRumpFacesWithItsHead) {
  TriMesh m;
  add_box(m, {-0.8, 0, -0.3}, {0.4, 0.8, 0.3});       // body, its back the highest point
  add_box(m, {-1, 0.2, -0.2}, {-0.8, 0.6, 0.2});      // rump
  add_box(m, {0.4, 0, -0.15}, {1.0, 0.5, 0.15});      // head and neck, on the ground
  add_box(m, {0.85, 0.3, -0.45}, {0.95, 0.4, 0.45});  // ears, wider than the body
  for (const Eigen::Matrix3d& q : axis_rotations()) {
    TriMesh t = m;
    for (auto& p : t.positions) p = q * p;
    const Eigen::Matrix3d r = upright_rotation(t, UpAxis::kAuto);
    EXPECT_TRUE((r * q).isApprox(Eigen::Matrix3d::Identity())) << "turned back into its own frame:\n"
                                                               << r * q;
  }
}

/// A bust in its own frame, y up: a neck (a cylinder of radius 0.3, y in [0, 1], cut flat at y = 0 and closed
/// by a disc there) under a head (a sphere of radius 1 around (0, 1.8, 0), 24 latitude bands). The crown's
/// cap within 5 % of the height spans a wider hull (its ring of radius 0.5) than the neck's cut (0.3), so the
/// support polygon alone rests it on its crown; but the crown widens further in (a dome, radius 0.87 within
/// 20 %) while the neck keeps its width.
TriMesh bust() {
  TriMesh m;
  constexpr int kAround = 32, kRings = 24;
  constexpr double kPi = 3.14159265358979323846;
  const auto ring = [&](double y, double radius) {
    const int base = static_cast<int>(m.positions.size());
    for (int k = 0; k < kAround; ++k)
      m.positions.emplace_back(radius * std::cos(2 * kPi * k / kAround), y,
                               radius * std::sin(2 * kPi * k / kAround));
    return base;
  };
  const auto band = [&](int a, int b) {  // quads between two rings
    for (int k = 0; k < kAround; ++k) {
      const int k1 = (k + 1) % kAround;
      m.triangles.push_back({a + k, b + k, b + k1});
      m.triangles.push_back({a + k, b + k1, a + k1});
    }
  };
  const auto fan = [&](int centre, int r, bool flip) {
    for (int k = 0; k < kAround; ++k) {
      const int k1 = (k + 1) % kAround;
      m.triangles.push_back(flip ? std::array<int, 3>{centre, r + k1, r + k}
                                 : std::array<int, 3>{centre, r + k, r + k1});
    }
  };
  // The neck: rings every 0.25, the cut's disc at y = 0.
  m.positions.emplace_back(0, 0, 0);
  int previous = ring(0, 0.3);
  fan(0, previous, false);
  for (int i = 1; i <= 4; ++i) {
    const int next = ring(0.25 * i, 0.3);
    band(previous, next);
    previous = next;
  }
  // The head: latitude rings between the poles.
  const int south = static_cast<int>(m.positions.size());
  m.positions.emplace_back(0, 0.8, 0);
  previous = -1;
  for (int i = 1; i < kRings; ++i) {
    const double polar = kPi * i / kRings;
    const int next = ring(1.8 - std::cos(polar), std::sin(polar));
    if (previous < 0)
      fan(south, next, false);
    else
      band(previous, next);
    previous = next;
  }
  const int north = static_cast<int>(m.positions.size());
  m.positions.emplace_back(0, 2.8, 0);
  fan(north, previous, true);
  return m;
}

TEST(ViewFrame, ABustInAnyAxisOrientationRestsOnItsNeckNotOnItsCrown) {
  const TriMesh base = bust();
  for (const Eigen::Matrix3d& q : axis_rotations()) {
    TriMesh m = base;
    for (auto& p : m.positions) p = q * p;
    EXPECT_TRUE(ground_direction(m).isApprox(-(q * Eigen::Vector3d::UnitY())))
        << q << "\nground " << ground_direction(m).transpose();
    const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto);
    EXPECT_TRUE((r * q * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitY())) << r * q;
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
}

/// The bust above with a nose: a block on the face's side (+z) at the height of the head's equator.
TEST(ViewFrame, ABustWithANoseInAnyAxisOrientationTurnsItsFaceToTheCamera) {
  TriMesh base = bust();
  add_box(base, {-0.1, 1.7, 0.95}, {0.1, 1.9, 1.25});
  for (const Eigen::Matrix3d& q : axis_rotations()) {
    TriMesh m = base;
    for (auto& p : m.positions) p = q * p;  // up = q·y, face = q·z
    const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto);
    EXPECT_TRUE((r * q).isApprox(Eigen::Matrix3d::Identity())) << "turned back into its own frame:\n"
                                                               << r * q;
  }
}

/// A biped in its own frame, y up, facing +z: two legs under a torso, arms held out sideways (its longest
/// extent, 2.4 across x against a height of 2 and a depth of 0.55), a head with a snout at +z and a bump on
/// its back (the deepest point at −z; a flat back would rest it on its back). Mirror-symmetric across x only.
TEST(ViewFrame, ABipedInAnyAxisOrientationTurnsItsFaceNotItsArmSpanToTheCamera) {
  TriMesh base;
  add_box(base, {-0.35, 0, -0.1}, {-0.15, 0.8, 0.1});  // legs
  add_box(base, {0.15, 0, -0.1}, {0.35, 0.8, 0.1});
  add_box(base, {-0.4, 0.8, -0.15}, {0.4, 1.6, 0.15});    // torso
  add_box(base, {-0.2, 1.1, -0.2}, {0.2, 1.3, -0.15});    // back
  add_box(base, {-1.2, 1.35, -0.08}, {-0.4, 1.5, 0.08});  // arms
  add_box(base, {0.4, 1.35, -0.08}, {1.2, 1.5, 0.08});
  add_box(base, {-0.2, 1.6, -0.15}, {0.2, 2.0, 0.15});   // head
  add_box(base, {-0.06, 1.7, 0.15}, {0.06, 1.8, 0.35});  // snout
  for (const Eigen::Matrix3d& q : axis_rotations()) {
    TriMesh m = base;
    for (auto& p : m.positions) p = q * p;
    EXPECT_TRUE(ground_direction(m).isApprox(-(q * Eigen::Vector3d::UnitY()))) << q;
    const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto);
    EXPECT_TRUE((r * q).isApprox(Eigen::Matrix3d::Identity())) << "turned back into its own frame:\n"
                                                               << r * q;
  }
}

TEST(ViewFrame, AGivenFrontAcrossUpIsTakenAsItIs) {
  const TriMesh m = animal();  // y up, head at +x
  for (const Eigen::Vector3d& front :
       {Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1)}) {
    const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto, front);
    EXPECT_TRUE(r.row(0).transpose().isApprox(front)) << front.transpose();
    EXPECT_TRUE(r.row(1).transpose().isApprox(Eigen::Vector3d::UnitY()));
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
  // Along up, or not a unit axis: the shape's rule.
  for (const Eigen::Vector3d& front :
       {Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0.6, 0, 0.8)})
    EXPECT_TRUE(upright_rotation(m, UpAxis::kAuto, front).isApprox(upright_rotation(m, UpAxis::kAuto)))
        << front.transpose();
}

TEST(ViewFrame, ANamedUpAxisIsTakenAsItIs) {
  TriMesh m = animal();  // y up; say z is up instead
  const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kZ);
  EXPECT_TRUE((r * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  // Of x and y, x is the longer axis: it becomes the front, its higher (in z: equal) end first.
  EXPECT_NEAR(std::abs((r * Eigen::Vector3d::UnitX()).x()), 1.0, 1e-12);
}

TEST(ViewFrame, NormalizationMapsTheRotatedBoxToTheCentredUnitBox) {
  TriMesh m = animal();
  for (auto& p : m.positions) p = 3.0 * Eigen::Vector3d(p.z(), p.x(), p.y()) + Eigen::Vector3d(5, -2, 7);
  m.positions.emplace_back(1e6, 1e6, 1e6);  // unreferenced: ignored
  const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto);
  const auto n = view_normalization(m, r);
  EXPECT_EQ(n[12], 0);
  EXPECT_EQ(n[13], 0);
  EXPECT_EQ(n[14], 0);
  EXPECT_EQ(n[15], 1);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(HUGE_VAL), hi = -lo;
  for (std::size_t v = 0; v + 1 < m.positions.size(); ++v) {
    const Eigen::Vector3d& p = m.positions[v];
    Eigen::Vector3d q;
    for (int i = 0; i < 3; ++i)
      q[i] = n[static_cast<std::size_t>(4 * i)] * p.x() + n[static_cast<std::size_t>(4 * i + 1)] * p.y() +
             n[static_cast<std::size_t>(4 * i + 2)] * p.z() + n[static_cast<std::size_t>(4 * i + 3)];
    lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  }
  EXPECT_NEAR((hi - lo).maxCoeff(), 1.0, 1e-12);
  EXPECT_TRUE((lo + hi).isZero(1e-12)) << (lo + hi).transpose();
  EXPECT_NEAR(hi.y() - lo.y(), 1.4 / 2.0, 1e-12) << "y is the animal's height (1.4 of its length 2)";
}

// frame_rotation() takes the rotation back out of a normalization (what decode's glTF node carries).
TEST(ViewFrame, FrameRotationUndoesTheNormalizationsScale) {
  TriMesh m = animal();
  const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kZ);
  const std::array<double, 9> back = frame_rotation(view_normalization(m, r));
  EXPECT_TRUE(is_rotation(back));
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) EXPECT_NEAR(back[3 * row + col], r(row, col), 1e-12);
  const std::array<double, 9> identity{1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::array<double, 16> sheared{1, 0.5, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_EQ(frame_rotation(sheared), identity) << "not a scaled rotation";
  std::array<double, 16> mirrored{-2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1};
  EXPECT_EQ(frame_rotation(mirrored), identity) << "determinant −1";
  EXPECT_EQ(frame_rotation(std::array<double, 16>{}), identity) << "zero scale";
}

TEST(ViewFrame, DegenerateMeshesGiveAFrameWithoutNaN) {
  TriMesh empty;
  EXPECT_TRUE(ground_direction(empty).isApprox(-Eigen::Vector3d::UnitY()));
  const auto n = view_normalization(empty, upright_rotation(empty, UpAxis::kAuto));
  for (double v : n) EXPECT_TRUE(std::isfinite(v));
  TriMesh flat;  // one triangle in the plane z = 0
  flat.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  flat.triangles = {{0, 1, 2}};
  const Eigen::Matrix3d r = upright_rotation(flat, UpAxis::kAuto);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  for (double v : view_normalization(flat, r)) EXPECT_TRUE(std::isfinite(v));
}

struct Animal {
  const char* file;
  Eigen::Vector3d up;    // in the data's units, seen in the meshes
  Eigen::Vector3d head;  // where the head points (data units; tests/data/make_animals_corr.py)
};

TEST(ViewFrame, TheAnimalsOfTheSharedMeshesGetTheirDataUpAxisAndFaceWithTheirHeads) {
  const Animal animals[] = {{"horse.obj", Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY()},
                            {"pig.obj", -Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitZ()},
                            {"cow.obj", Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX()},
                            {"spot.obj", Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitZ()},
                            {"bunny.obj", Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitX()}};
  for (const Animal& a : animals) {
    GEOMIP_REQUIRE_SHARED_MESH(path, a.file);
    const TriMesh m = read_mesh(path);
    EXPECT_TRUE((-ground_direction(m)).isApprox(a.up)) << a.file << ": " << -ground_direction(m).transpose();
    const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto);
    EXPECT_TRUE((r * a.up).isApprox(Eigen::Vector3d::UnitY())) << a.file;
    EXPECT_TRUE((r * a.head).isApprox(Eigen::Vector3d::UnitX())) << a.file << ": front " << r.row(0);
  }
}

/// The heads, busts and the standing biped of ../shared/meshes, up = the top of the head and the face's
/// direction read off the data (side views of the vertices, docs/streaming.md "Upright and front"): each has
/// its neck (the armadillo its feet) at the −up face of its box (the camel head's neck cut is at −y, its
/// muzzle towards +z; Max Planck faces −z; the armadillo's arm span along x is its longest extent). The face
/// becomes +z, the default camera's side.
TEST(ViewFrame, TheHeadsBustsAndTheBipedOfTheSharedMeshesStandOnTheirNecksAndFeetFacingTheCamera) {
  struct Upright {
    const char* file;
    Eigen::Vector3d up, face;
  };
  const Upright shapes[] = {{"camelhead.obj", Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()},
                            {"max-planck.obj", Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitZ()},
                            {"venus.obj", Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()},
                            {"igea.ply", Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()},
                            {"armadillo.obj", Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()}};
  for (const Upright& u : shapes) {
    GEOMIP_REQUIRE_SHARED_MESH(path, u.file);
    const TriMesh m = read_mesh(path);
    EXPECT_TRUE((-ground_direction(m)).isApprox(u.up)) << u.file << ": " << -ground_direction(m).transpose();
    const Eigen::Matrix3d r = upright_rotation(m, UpAxis::kAuto);
    EXPECT_TRUE((r * u.up).isApprox(Eigen::Vector3d::UnitY())) << u.file;
    EXPECT_TRUE((r * u.face).isApprox(Eigen::Vector3d::UnitZ()))
        << u.file << ": towards the camera " << r.row(2);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12) << u.file;
  }
}

}  // namespace
}  // namespace geomip
