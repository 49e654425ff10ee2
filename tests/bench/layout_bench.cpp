// Automatic quad layouts on real meshes: area balance (smallest / largest patch), area spread and the corner
// moves of the balancing for each K, without the parameterization. Not part of ctest (figures, not tests).
// Run: build/tests/bench/layout_bench MESH K [K...]   (env GEOMIP_BALANCE_STEPS: balancing steps, default
// QuadLayoutOptions' own)
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "param/quad_layout.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  using namespace geomip;
  if (argc < 3) {
    std::fprintf(stderr, "usage: layout_bench MESH K [K...]\n");
    return 2;
  }
  try {
    TriMesh mesh = read_mesh(argv[1]);
    const TopologyReport r = analyze_topology(mesh);
    if (r.boundary_loops > 0 || !r.manifold) mesh = repair_mesh(mesh).mesh;
    for (int i = 2; i < argc; ++i) {
      QuadLayoutOptions options;
      options.patches = std::atoi(argv[i]);
      if (const char* steps = std::getenv("GEOMIP_BALANCE_STEPS")) options.balance_steps = std::atoi(steps);
      if (const char* t = std::getenv("GEOMIP_TIP_PERSISTENCE")) options.tip_persistence = std::atof(t);
      options.only_pinned_tips = std::getenv("GEOMIP_ONLY_PINNED_TIPS") != nullptr;
      if (const char* w = std::getenv("GEOMIP_SHAPE_WEIGHT")) options.shape_weight = std::atof(w);
      if (const char* a = std::getenv("GEOMIP_MAX_CORNER_ANGLE")) options.max_corner_angle_deg = std::atof(a);
      if (const char* ratio = std::getenv("GEOMIP_MAX_SIDE_RATIO")) options.max_side_ratio = std::atof(ratio);
      if (const char* f = std::getenv("GEOMIP_MIN_FLATNESS")) options.min_flatness = std::atof(f);
      if (const char* n = std::getenv("GEOMIP_SHAPE_STEPS")) options.shape_steps = std::atoi(n);
      if (const char* w = std::getenv("GEOMIP_ERROR_WEIGHT")) options.error_weight = std::atof(w);
      if (const char* o = std::getenv("GEOMIP_LAYOUT_OBJECTIVE"); o && std::string(o) == "area")
        options.objective = LayoutObjective::kAreaSpread;
      const auto start = std::chrono::steady_clock::now();
      const QuadLayoutChoice c = choose_quad_layout(mesh, options);
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("%s K=%d balance %.3f spread %.3f cost %.3f max angle %.0f max side %.2f penalty %.2f moves %d + %d candidates %zu tips %zu%s (%.1f s)\n", argv[1],
                  options.patches, c.area_balance, c.area_spread, c.sampling_cost, c.max_corner_angle_deg,
                  c.max_side_ratio, c.shape_penalty, c.balance_steps, c.shape_steps,
                  c.candidates, c.tips.size(), c.tips_pinned ? " pinned" : "", seconds);
      if (const char* json = std::getenv("GEOMIP_LAYOUT_JSON")) {  // a CORR.json of this layout, corners as xyz
        std::FILE* f = std::fopen(json, "w");
        if (!f) throw std::runtime_error(std::string("cannot write ") + json);
        std::fprintf(f, "{\"layout\": {\"quads\": [");
        for (std::size_t q = 0; q < c.layout.quads.size(); ++q) {
          const auto& quad = c.layout.quads[q];
          std::fprintf(f, "%s[%d, %d, %d, %d]", q ? ", " : "", quad[0], quad[1], quad[2], quad[3]);
        }
        std::fprintf(f, "]}, \"models\": [{\"mesh\": \"%s\", \"partition_points\": [", argv[1]);
        for (std::size_t j = 0; j < c.layout.corners.size(); ++j) {
          const auto& p = mesh.positions[c.layout.corners[j]];
          std::fprintf(f, "%s[%.17g, %.17g, %.17g]", j ? ", " : "", p.x(), p.y(), p.z());
        }
        std::fprintf(f, "]}]}\n");
        std::fclose(f);
      }
      const PartitionResult partition = partition_mesh_layout(mesh, c.layout);
      {  // corner angles: the 3D angle sum of each patch's triangles at each of its corners (90° on a square)
        std::vector<double> angles;
        const auto& m = partition.mesh;
        for (const Patch& patch : partition.patches) {
          for (int corner : patch.corners) {
            double sum = 0.0;
            for (int f : patch.faces) {
              const auto& t = m.triangles[f];
              for (int k = 0; k < 3; ++k) {
                if (t[k] != corner) continue;
                const Eigen::Vector3d u = m.positions[t[(k + 1) % 3]] - m.positions[corner];
                const Eigen::Vector3d w = m.positions[t[(k + 2) % 3]] - m.positions[corner];
                sum += std::atan2(u.cross(w).norm(), u.dot(w));
              }
            }
            angles.push_back(sum * 180.0 / M_PI);
          }
        }
        std::sort(angles.begin(), angles.end());
        auto at = [&](double q) { return angles[static_cast<std::size_t>(q * (angles.size() - 1))]; };
        int over = 0;
        for (double a : angles) over += a > 180.0;
        std::printf("  corner angles: min %.0f, median %.0f, 90th %.0f, max %.0f, %d of %zu above 180\n",
                    at(0), at(0.5), at(0.9), at(1.0), over, angles.size());
      }
      const PartitionStats stats = partition_stats(partition);
      for (std::size_t q = 0; q < stats.patches.size(); ++q) {
        std::printf("  patch %zu: area %.6g, boundary %.4g, flatness %.3f\n", q, stats.patches[q].area,
                    stats.patches[q].boundary_length, stats.patches[q].flatness);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "layout_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
