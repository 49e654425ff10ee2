// Properties of partition_mesh() and choose_partition_points() on the shared meshes (label real).
// Prints the balance of the automatic choice against naive ones, and timings, for the record.
#include "param/mesh_partition.h"

#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "param/partition_points.h"
#include "tests/param/partition_checks.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

namespace geomip {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The shared mesh, repaired when it is not a closed manifold (bunny: holes; cow: a pinch vertex).
TriMesh closed_mesh(const std::string& path) {
  TriMesh m = read_mesh(path);
  const TopologyReport t = analyze_topology(m);
  if (!t.manifold || t.boundary_edges > 0 || t.unreferenced_vertices > 0) m = repair_mesh(m).mesh;
  return m;
}

struct Figures {
  double balance = 0.0, cut = 0.0, flat_min = 0.0;
};

Figures figures(const TriMesh& m, const PartitionResult& r) {
  const PartitionStats s = partition_stats(r);
  Figures f;
  f.balance = s.area_balance;
  f.cut = s.cut_length / std::sqrt(test::surface_area(m));  // scale-free: cut length / √area
  f.flat_min = std::min(s.patches[0].flatness, s.patches[1].flatness);
  return f;
}

// Genus 0: the automatic points partition validly, fast, and beat naive choices on balance.
void check_genus0(const std::string& name) {
  GEOMIP_REQUIRE_SHARED_MESH(path, name);
  const TriMesh m = closed_mesh(path);
  auto t0 = std::chrono::steady_clock::now();
  const PartitionPoints pts = choose_partition_points(m);
  const double t_choose = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  const PartitionResult r = partition_mesh(m, pts.partition_points, pts.auxiliary_points);
  const double t_partition = seconds_since(t0);
  EXPECT_EQ(test::check_partition(m, pts.partition_points, r), "");
  const Figures autof = figures(m, r);

  // The alternative considered: the loop around the "equator", across the longest axis; and the chosen
  // corners without their guiding points.
  PartitionPointsOptions equator_options;
  equator_options.cut_axis = 1;
  const PartitionPoints eq = choose_partition_points(m, equator_options);
  const Figures equator = figures(m, partition_mesh(m, eq.partition_points, eq.auxiliary_points));
  const Figures unguided = figures(m, partition_mesh(m, pts.partition_points, {}));

  // Naive 1: the first four vertex ids. Naive 2: four random vertices (mean of 10 seeded draws).
  Figures first;
  try {
    first = figures(m, partition_mesh(m, {0, 1, 2, 3}, {}));
  } catch (const InvalidInput&) {
    // balance 0: no partition at all
  }
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(m.num_vertices()) - 1);
  Figures random;
  int draws = 0, random_failures = 0;
  double worst_random = 1.0;
  while (draws < 10) {
    std::vector<int> p;
    while (p.size() < 4) {
      const int v = pick(rng);
      if (std::find(p.begin(), p.end(), v) == p.end()) p.push_back(v);
    }
    ++draws;
    try {
      const PartitionResult rr = partition_mesh(m, p, {});
      EXPECT_EQ(test::check_partition(m, p, rr), "");
      const Figures f = figures(m, rr);
      random.balance += f.balance / 10;
      random.cut += f.cut / 10;
      random.flat_min += f.flat_min / 10;
      worst_random = std::min(worst_random, f.balance);
    } catch (const InvalidInput&) {
      ++random_failures;
      worst_random = 0.0;
    }
  }
  std::printf("[figures] %-10s F=%zu splits=%zu time: choose %.3f s, partition %.3f s\n", name.c_str(),
              m.num_triangles(), r.split_vertices, t_choose, t_partition);
  auto row = [&](const char* what, const Figures& f) {
    std::printf("[figures] %-10s %-26s balance %.3f  cut/sqrt(area) %.2f  min flatness %.2f\n", name.c_str(),
                what, f.balance, f.cut, f.flat_min);
  };
  row("auto (thin-axis outline)", autof);
  row("auto corners, no guides", unguided);
  row("equator (cut_axis 1)", equator);
  row("first 4 vertex ids", first);
  row("random (mean of 10)", random);
  std::printf("[figures] %-10s random: worst balance %.3f, %d of 10 failed\n", name.c_str(), worst_random,
              random_failures);
  EXPECT_GT(autof.balance, 0.7) << name;
  EXPECT_GT(autof.flat_min, equator.flat_min) << name << ": the thin-axis cut should give flatter halves";
  EXPECT_GE(autof.balance, unguided.balance) << name << ": guiding points should not hurt the balance";
  EXPECT_GT(autof.balance, first.balance) << name;
  EXPECT_GT(autof.balance, random.balance) << name;
}

TEST(PartitionReal, BunnyRepaired) {
  check_genus0("bunny.obj");
}
TEST(PartitionReal, Spot) {
  check_genus0("spot.obj");
}
TEST(PartitionReal, Horse) {
  check_genus0("horse.obj");
}
TEST(PartitionReal, CowRepaired) {
  check_genus0("cow.obj");
}

// Genus 1: the committed point files partition validly; the automatic method does too.
void check_genus1(const std::string& name, const std::string& points_file) {
  GEOMIP_REQUIRE_SHARED_MESH(path, name);
  const TriMesh m = read_mesh(path);  // the point files hold this file's vertex ids: no repair
  const TopologyReport topo = analyze_topology(m);
  ASSERT_TRUE(topo.manifold && topo.boundary_edges == 0 && topo.genus == 1) << name;
  std::ifstream in(std::string(GEOMIP_SOURCE_DIR) + "/tests/data/" + points_file);
  ASSERT_TRUE(in) << points_file;
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto p = j.at("partition_points").get<std::vector<int>>();
  const auto aux = j.at("auxiliary_points").get<std::vector<int>>();
  ASSERT_EQ(p.size(), 4u);
  ASSERT_EQ(aux.size(), 8u);
  auto t0 = std::chrono::steady_clock::now();
  const PartitionResult r = partition_mesh(m, p, aux);
  const double t_partition = seconds_since(t0);
  EXPECT_EQ(test::check_partition(m, p, r), "");
  const PartitionStats s = partition_stats(r);
  for (int k = 0; k < 8; ++k) {  // every auxiliary point lies on the two sides it guides
    int on_sides = 0;
    for (const Patch& patch : r.patches) {
      for (const PatchSide& side : patch.sides) {
        on_sides += std::count(side.vertices.begin(), side.vertices.end(), aux[k]);
      }
    }
    EXPECT_EQ(on_sides, 2) << "auxiliary point " << k;
  }
  t0 = std::chrono::steady_clock::now();
  const PartitionPoints chosen = choose_partition_points(m);
  const double t_choose = seconds_since(t0);
  const PartitionResult rc = partition_mesh(m, chosen.partition_points, chosen.auxiliary_points);
  EXPECT_EQ(test::check_partition(m, chosen.partition_points, rc), "");
  std::printf(
      "[figures] %-10s F=%zu file points: balance %.3f cut/sqrtA %.2f splits %zu, partition %.3f s | "
      "choose_partition_points: balance %.3f, %.3f s\n",
      name.c_str(), m.num_triangles(), s.area_balance, s.cut_length / std::sqrt(test::surface_area(m)),
      r.split_vertices, t_partition, partition_stats(rc).area_balance, t_choose);
  EXPECT_GT(s.area_balance, 0.2) << name;
}

TEST(PartitionReal, BobGenus1) {
  check_genus1("bob.obj", "bob.points.json");
}
TEST(PartitionReal, RockerArmGenus1) {
  check_genus1("rocker-arm.obj", "rocker-arm.points.json");
}

}  // namespace
}  // namespace geomip
