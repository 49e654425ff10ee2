// geomip's topology counts must equal the table in ../shared/meshes/README.md for every mesh there.
#include "mesh/mesh_io.h"
#include "mesh/mesh_topology.h"
#include "tests/param/test_meshes.h"

#include <gtest/gtest.h>

namespace geomip {
namespace {

struct Expected {
  const char* file;
  std::size_t vertices, faces;  // referenced vertices
  int genus;
  std::size_t components, boundary_loops, non_manifold_vertices, unreferenced;
};

// From ../shared/meshes/README.md (V_ref for the bunny: 35947 − 1113; the cow's genus is that of the split
// surface, 0).
const Expected kTable[] = {
    {"bunny.obj", 34834, 69451, 0, 1, 5, 0, 1113},   {"bunny-small.obj", 3485, 6966, 0, 1, 0, 0, 0},
    {"horse.obj", 48485, 96966, 0, 1, 0, 0, 0},      {"cow.obj", 2903, 5804, 0, 1, 0, 1, 0},
    {"spot.obj", 2930, 5856, 0, 1, 0, 0, 0},         {"pig.obj", 1843, 3682, 0, 1, 0, 0, 0},
    {"armadillo.obj", 43243, 86482, 0, 1, 0, 0, 0},  {"max-planck.obj", 5272, 10540, 0, 1, 0, 0, 0},
    {"igea.ply", 134345, 268686, 0, 1, 0, 0, 0},     {"venus.obj", 50002, 100000, 0, 1, 0, 0, 0},
    {"fandisk.obj", 6475, 12946, 0, 1, 0, 0, 0},     {"rocker-arm.obj", 10044, 20088, 1, 1, 0, 0, 0},
    {"bob.obj", 5344, 10688, 1, 1, 0, 0, 0},         {"camelhead.obj", 11381, 22704, 0, 1, 1, 0, 0},
};

class SharedMesh : public ::testing::TestWithParam<Expected> {};

TEST_P(SharedMesh, TopologyMatchesTheReadme) {
  const Expected& e = GetParam();
  GEOMIP_REQUIRE_SHARED_MESH(path, e.file);
  const TopologyReport r = analyze_topology(read_mesh(path));
  EXPECT_EQ(r.vertices, e.vertices);
  EXPECT_EQ(r.faces, e.faces);
  EXPECT_EQ(r.genus, e.genus);
  EXPECT_EQ(r.components, e.components);
  EXPECT_EQ(r.boundary_loops, e.boundary_loops);
  EXPECT_EQ(r.non_manifold_vertices, e.non_manifold_vertices);
  EXPECT_EQ(r.manifold, e.non_manifold_vertices == 0);
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.degenerate_faces, 0u);
  EXPECT_EQ(r.unreferenced_vertices, e.unreferenced);
  EXPECT_GT(r.bbox_diagonal, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Readme, SharedMesh, ::testing::ValuesIn(kTable),
                         [](const ::testing::TestParamInfo<Expected>& param_info) {
                           std::string name = param_info.param.file;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace geomip
