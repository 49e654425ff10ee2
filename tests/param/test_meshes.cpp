#include "tests/param/test_meshes.h"

#include <cmath>
#include <filesystem>
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

}  // namespace geomip::test
