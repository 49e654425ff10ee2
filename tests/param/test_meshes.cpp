#include "tests/param/test_meshes.h"

#include "mesh/mesh_topology.h"
#include "param/partition_points.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <filesystem>
#include <map>
#include <random>

namespace geomip::test {

TriMesh tetrahedron() {
  TriMesh m;
  m.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  m.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  return m;
}

TriMesh cube() {
  TriMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return m;
}

TriMesh torus(int n, int m) {
  TriMesh t;
  const double kPi = 3.14159265358979323846;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      const double u = 2 * kPi * i / n, v = 2 * kPi * j / m;
      t.positions.emplace_back((1 + 0.3 * std::cos(v)) * std::cos(u), (1 + 0.3 * std::cos(v)) * std::sin(u),
                               0.3 * std::sin(v));
    }
  }
  auto id = [&](int i, int j) { return ((i + n) % n) * m + (j + m) % m; };
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      t.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return t;
}

TriMesh open_cylinder(int n, int m) {
  TriMesh c;
  const double kPi = 3.14159265358979323846;
  for (int j = 0; j <= m; ++j) {
    for (int i = 0; i < n; ++i) {
      const double a = 2 * kPi * i / n;
      c.positions.emplace_back(std::cos(a), std::sin(a), 2.0 * j / m);
    }
  }
  auto id = [&](int i, int j) { return j * n + (i % n); };
  for (int j = 0; j < m; ++j) {
    for (int i = 0; i < n; ++i) {
      c.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      c.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return c;
}

TriMesh grid(int n) {
  TriMesh g;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) g.positions.emplace_back(double(i) / n, double(j) / n, 0.0);
  }
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      g.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      g.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  }
  return g;
}

TriMesh subdivide(const TriMesh& mesh, int levels) {
  TriMesh m = mesh;
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.positions.push_back(0.5 * (m.positions[a] + m.positions[b]));
      return mid[key] = static_cast<int>(m.positions.size()) - 1;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& t : m.triangles) {
      const int a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
      finer.push_back({t[0], a, c});
      finer.push_back({a, t[1], b});
      finer.push_back({c, b, t[2]});
      finer.push_back({a, b, c});
    }
    m.triangles = std::move(finer);
  }
  return m;
}

TriMesh sphere(int levels) {
  TriMesh c = cube();
  for (auto& p : c.positions) p -= Eigen::Vector3d::Constant(0.5);
  TriMesh m = subdivide(c, levels);
  for (auto& p : m.positions) p.normalize();
  return m;
}

TriMesh pinched_tetrahedra() {
  TriMesh b = tetrahedron();
  for (auto& p : b.positions) p += Eigen::Vector3d(2, 2, 2);
  TriMesh m = join(tetrahedron(), b);
  for (auto& t : m.triangles) {
    for (int& v : t) {
      if (v == 4) v = 0;  // glue the second tetrahedron's vertex 0 onto the first one's
    }
  }
  return m;
}

int nearest_vertex(const TriMesh& mesh, const Eigen::Vector3d& p) {
  int best = 0;
  for (int v = 1; v < static_cast<int>(mesh.positions.size()); ++v) {
    if ((mesh.positions[v] - p).squaredNorm() < (mesh.positions[best] - p).squaredNorm()) best = v;
  }
  return best;
}

TriMesh float32(TriMesh mesh) {
  for (auto& p : mesh.positions) {
    for (int c = 0; c < 3; ++c) {
      const volatile float f = static_cast<float>(p[c]);
      p[c] = f;
    }
  }
  return mesh;
}

TriMesh join(const TriMesh& a, const TriMesh& b) {
  TriMesh m = a;
  const int offset = static_cast<int>(a.positions.size());
  m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
  for (const auto& t : b.triangles) m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return m;
}

std::string shared_mesh(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(GEOMIP_SHARED_MESHES) / name;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

std::string temp_dir(const std::string& tag) {
  std::random_device rd;
  const auto dir = std::filesystem::temp_directory_path() /
                   ("geomip-" + tag + "-" + std::to_string(rd()) + std::to_string(rd()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

// Two tori joined by a tube: genus 2. The tube's winding and matching are searched so that the result is a
// consistently oriented closed manifold.
TriMesh spiked_ellipsoid(int levels, double width) {
  TriMesh m = sphere(levels);
  for (auto& q : m.positions) {
    const double theta = std::acos(std::clamp(q.z(), -1.0, 1.0));
    q = Eigen::Vector3d(3 * q.x(), 2 * q.y(), q.z() + 2.5 * std::exp(-theta * theta / (width * width)));
  }
  return m;
}

TriMesh double_torus() {
  const int n = 16, mm = 8;
  const TriMesh a = test::torus(n, mm);
  TriMesh b = test::torus(n, mm);
  for (auto& p : b.positions) p.x() += 3.0;
  auto id = [&](int i, int j) { return ((i + n) % n) * mm + (j + mm) % mm; };
  // Remove the quad (i=0, j=0) of A (facing +x) and (i=n/2, j=0) of B (facing -x).
  const std::array<int, 4> ha = {id(0, 0), id(1, 0), id(1, 1), id(0, 1)};
  const std::array<int, 4> hb = {id(n / 2, 0), id(n / 2 + 1, 0), id(n / 2 + 1, 1), id(n / 2, 1)};
  auto without = [&](const TriMesh& t, int i) {
    TriMesh r = t;
    r.triangles.erase(r.triangles.begin() + 2 * (i * mm));  // the two triangles of quad (i, 0)
    r.triangles.erase(r.triangles.begin() + 2 * (i * mm));
    return r;
  };
  const TriMesh base = test::join(without(a, 0), without(b, n / 2));
  const int off = static_cast<int>(a.positions.size());
  for (int shift = 0; shift < 4; ++shift) {
    for (int dir = -1; dir <= 1; dir += 2) {
      for (int flip = 0; flip < 2; ++flip) {
        TriMesh m = base;
        for (int k = 0; k < 4; ++k) {
          const int a0 = ha[k], a1 = ha[(k + 1) % 4];
          const int b0 = hb[(shift + dir * k + 8) % 4] + off, b1 = hb[(shift + dir * (k + 1) + 8) % 4] + off;
          std::array<int, 3> t1 = {a1, a0, b0}, t2 = {a1, b0, b1};
          if (flip) {
            std::swap(t1[1], t1[2]);
            std::swap(t2[1], t2[2]);
          }
          m.triangles.push_back(t1);
          m.triangles.push_back(t2);
        }
        const TopologyReport r = analyze_topology(m);
        std::set<std::pair<int, int>> directed;
        bool consistent = true;
        for (const auto& t : m.triangles) {
          for (int k = 0; k < 3; ++k) consistent &= directed.insert({t[k], t[(k + 1) % 3]}).second;
        }
        if (consistent && r.manifold && r.boundary_edges == 0 && r.genus == 2) return m;
      }
    }
  }
  ADD_FAILURE() << "could not build a double torus";
  return base;
}

ParameterizationInput automatic_input(const TriMesh& mesh, const std::string& name) {
  ParameterizationInput in;
  in.mesh = mesh;
  in.name = name;
  const PartitionPoints points = choose_partition_points(mesh);
  in.partition_points = points.partition_points;
  in.auxiliary_points = points.auxiliary_points;
  return in;
}

}  // namespace geomip::test
