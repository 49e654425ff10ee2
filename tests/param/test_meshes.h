// Small synthetic meshes for property tests, and access to ../shared/meshes.
#pragma once

#include "mesh/mesh.h"
#include "param/consistent_parameterization.h"

#include <string>

namespace geomip::test {

/// Regular tetrahedron, outward oriented: closed, genus 0.
TriMesh tetrahedron();
/// Axis-aligned cube of 12 triangles, outward oriented.
TriMesh cube();
/// Torus sampled on an n×m grid (radii R=1, r=0.3): closed, genus 1, 2·n·m triangles.
TriMesh torus(int n, int m);
/// Open cylinder (two boundary loops), n around × m along, radius 1, height 2.
TriMesh open_cylinder(int n, int m);
/// Flat (n+1)×(n+1) grid on the unit square in z = 0: a disk with one boundary loop.
TriMesh grid(int n);
/// 1-to-4 midpoint subdivision, `levels` times (positions not moved).
TriMesh subdivide(const TriMesh& mesh, int levels);
/// Two tetrahedra sharing one vertex (a "pinch"): 7 referenced vertices, 8 faces, vertex 4 unreferenced.
TriMesh pinched_tetrahedra();
/// Unit sphere around the origin: a cube subdivided `levels` times (1-to-4) and projected, 12·4^levels
/// triangles.
TriMesh sphere(int levels);
/// A flat ellipsoid (semi-axes 3, 2, 1) with a spike of height 2.5 on its top (+z, Gaussian profile of width
/// `width` radians), sampled by sphere(levels): a protrusion inside the +z half, away from the z = median
/// outline that choose_partition_points() cuts along.
TriMesh spiked_ellipsoid(int levels, double width);
/// Two tori (test::torus(16, 8)) joined by a tube: a closed, consistently oriented genus-2 mesh.
TriMesh double_torus();
/// Index of the vertex nearest to `p` (brute force).
int nearest_vertex(const TriMesh& mesh, const Eigen::Vector3d& p);
/// Concatenation of two meshes (indices of `b` shifted).
TriMesh join(const TriMesh& a, const TriMesh& b);

/// `mesh` with every coordinate rounded to float32 (what OBJ/PLY/glTF files of float data hold). Rounds
/// through a volatile float: Debian's GCC 12.2 at -O2/-O3 miscompiles the plain in-place loop
/// `p[c] = double(float(p[c]))` over xyz (its SLP vectorizer drops the rounding of two of the three
/// components; seen 2026-12-02 with g++ 12.2.0-14).
TriMesh float32(TriMesh mesh);

/// Absolute path of a mesh in ../shared/meshes (empty when that folder is absent).
std::string shared_mesh(const std::string& name);
/// A fresh empty directory under the system temp dir, for test outputs.
std::string temp_dir(const std::string& tag);

/// A parameterization input with automatically chosen partition (and auxiliary) points.
ParameterizationInput automatic_input(const TriMesh& mesh, const std::string& name);

}  // namespace geomip::test

/// Skips the current test when ../shared/meshes is not beside the checkout.
#define GEOMIP_REQUIRE_SHARED_MESH(var, name)                \
  const std::string var = ::geomip::test::shared_mesh(name); \
  if (var.empty()) GTEST_SKIP() << "../shared/meshes/" << name << " not found"
