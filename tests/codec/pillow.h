// A closed two-patch test surface for codec tests: a "pillow" over [−1,1]², the top patch z = h(x, y), the
// bottom patch z = −h with its (i, j) transposed so both are oriented outward; h = 0 on the square's border,
// so the four sides are glued (reversed), and seam samples are bit-identical in both patches.
#pragma once

#include "codec/geometry_codec.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <random>
#include <vector>

namespace geomip::test {

/// Height of the pillow at (x, y) ∈ [−1, 1]²: a smooth bump plus a little ripple (so every band has detail).
inline double pillow_height(double x, double y) {
  return 0.6 * (1 - x * x) * (1 - y * y) * (1 + 0.15 * std::sin(5 * x) * std::cos(4 * y));
}

struct Pillow {
  std::vector<codec::Grid3> patches;
  std::vector<codec::PatchSeam> seams;
};

/// A mirrored seam table (one seam per side, (patch, side) in order, each its partner's mirror) that glues
/// the sides of `patches` patches in random pairs with random orientations: the form of a quad layout's
/// table, for seam-table tests and fuzz seeds (the grids need not agree on the seams: the decoder copies
/// each seam sample from its owner).
inline std::vector<codec::PatchSeam> random_layout_seams(int patches, std::mt19937& rng) {
  std::vector<int> sides(4 * static_cast<std::size_t>(patches));
  std::iota(sides.begin(), sides.end(), 0);
  std::shuffle(sides.begin(), sides.end(), rng);
  std::vector<codec::PatchSeam> seams(sides.size());
  for (std::size_t k = 0; k < sides.size(); k += 2) {
    const int a = sides[k], b = sides[k + 1];
    const bool reversed = rng() % 2 == 0;
    seams[static_cast<std::size_t>(a)] = {a / 4, a % 4, b / 4, b % 4, reversed};
    seams[static_cast<std::size_t>(b)] = {b / 4, b % 4, a / 4, a % 4, reversed};
  }
  return seams;
}

using Quad = std::array<int, 4>;  // corner ids, counter-clockwise seen from outside

/// The seam table of a closed quad mesh: side s of quad q runs from corner s to corner s + 1 (the grid's
/// sides), glued reversed to the quad that has the same edge the other way. Empty if an edge has no partner.
inline std::vector<codec::PatchSeam> seams_of(const std::vector<Quad>& quads) {
  std::map<std::pair<int, int>, std::pair<int, int>> edge;  // (from, to) → (quad, side)
  for (int q = 0; q < static_cast<int>(quads.size()); ++q)
    for (int s = 0; s < 4; ++s) edge[{quads[q][s], quads[q][(s + 1) % 4]}] = {q, s};
  std::vector<codec::PatchSeam> seams;
  for (int q = 0; q < static_cast<int>(quads.size()); ++q) {
    for (int s = 0; s < 4; ++s) {
      const auto it = edge.find({quads[q][(s + 1) % 4], quads[q][s]});
      if (it == edge.end()) return {};
      seams.push_back({q, s, it->second.first, it->second.second, true});
    }
  }
  return seams;
}

/// The surface of the cube [0, n]³ cut into 6·n² unit quads, oriented outwards.
inline std::vector<Quad> cube_quads(int n) {
  std::map<std::array<int, 3>, int> ids;
  const auto id = [&](std::array<int, 3> p) {
    return ids.emplace(p, static_cast<int>(ids.size())).first->second;
  };
  std::vector<Quad> quads;
  for (int a = 0; a < 3; ++a) {
    for (int sign = 0; sign < 2; ++sign) {
      // u × v = the outward normal: (a+1, a+2) for +a, swapped for −a.
      const int u = sign == 1 ? (a + 1) % 3 : (a + 2) % 3, v = sign == 1 ? (a + 2) % 3 : (a + 1) % 3;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          Quad q;
          const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            std::array<int, 3> p{};
            p[a] = sign == 1 ? n : 0;
            p[u] = i + du[c], p[v] = j + dv[c];
            q[c] = id(p);
          }
          quads.push_back(q);
        }
      }
    }
  }
  return quads;
}

/// A smooth unit vector field for normal-map tests: each sample's normalized position ((0, 0, 1) at the
/// origin). The normal maps of the golden packs are made this way.
inline std::vector<codec::Grid3> position_normals(const std::vector<codec::Grid3>& patches) {
  std::vector<codec::Grid3> normals = patches;
  for (codec::Grid3& g : normals) {
    for (std::size_t k = 0; k < g.values.size(); k += 3) {
      float* v = g.values.data() + k;
      const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int c = 0; c < 3; ++c) v[c] = len > 0 ? v[c] / len : (c == 2 ? 1.f : 0.f);
    }
  }
  return normals;
}

/// The pillow sampled on (2^level+1)² grids, with `scale` applied to every coordinate.
inline Pillow make_pillow(int level, double scale = 1.0) {
  Pillow p;
  const int n = (1 << level) + 1;
  for (int patch = 0; patch < 2; ++patch) {
    codec::Grid3 g;
    g.level = level;
    g.values.resize(3 * static_cast<std::size_t>(n) * n);
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        const int a = patch == 0 ? i : j, b = patch == 0 ? j : i;
        const double x = 2.0 * a / (n - 1) - 1, y = 2.0 * b / (n - 1) - 1;
        const double h = (a == 0 || a == n - 1 || b == 0 || b == n - 1) ? 0.0 : pillow_height(x, y);
        float* v = g.values.data() + 3 * (static_cast<std::size_t>(j) * n + i);
        v[0] = static_cast<float>(scale * x);
        v[1] = static_cast<float>(scale * y);
        v[2] = static_cast<float>(patch == 0 ? scale * h : 0.0 - scale * h);
      }
    }
    p.patches.push_back(std::move(g));
  }
  // Side s of patch 0 ↔ side of patch 1 (see the derivation in the header comment of each pair):
  // (0,s0)↔(1,s3), (0,s1)↔(1,s2), (0,s2)↔(1,s1), (0,s3)↔(1,s0), all reversed.
  const int partner[4] = {3, 2, 1, 0};
  for (int s = 0; s < 4; ++s) p.seams.push_back({0, s, 1, partner[s], true});
  for (int s = 0; s < 4; ++s) p.seams.push_back({1, s, 0, partner[s], true});
  return p;
}

/// The (i, j) sample of side s of a (2^level+1)² grid at parameter k (geometry_codec.h convention).
inline void side_sample(int level, int side, int k, int& i, int& j) {
  const int last = 1 << level;
  switch (side) {
    case 0:
      i = k, j = 0;
      break;
    case 1:
      i = last, j = k;
      break;
    case 2:
      i = last - k, j = last;
      break;
    default:
      i = 0, j = last - k;
      break;
  }
}

/// Number of seam samples whose glued copies differ bitwise (0 for a watertight decode).
inline std::size_t seam_mismatches(const std::vector<codec::Grid3>& patches,
                                   const std::vector<codec::PatchSeam>& seams) {
  std::size_t bad = 0;
  for (const codec::PatchSeam& s : seams) {
    const codec::Grid3& a = patches[static_cast<std::size_t>(s.patch)];
    const codec::Grid3& b = patches[static_cast<std::size_t>(s.other_patch)];
    const int n = a.size(), last = n - 1;
    for (int k = 0; k <= last; ++k) {
      int ia, ja, ib, jb;
      side_sample(a.level, s.side, k, ia, ja);
      side_sample(b.level, s.other_side, s.reversed ? last - k : k, ib, jb);
      for (int c = 0; c < 3; ++c) {
        const float va = a.values[3 * (static_cast<std::size_t>(ja) * n + ia) + c];
        const float vb = b.values[3 * (static_cast<std::size_t>(jb) * n + ib) + c];
        if (std::memcmp(&va, &vb, sizeof va) != 0) ++bad;
      }
    }
  }
  return bad;
}

}  // namespace geomip::test
