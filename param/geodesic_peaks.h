// Geodesic distance on a mesh's edge graph and the persistent peaks of a vertex function: what the automatic
// layouts use to find the tips of protrusions (partition_points.cpp: distance from the outline;
// quad_layout.cpp: distance from the middle of the surface).
#pragma once

#include "mesh/mesh.h"

#include <utility>
#include <vector>

namespace geomip {

/// The neighbours of each vertex: for every triangle corner, the next corner (on a closed, consistently
/// oriented mesh each edge is listed once from each end). Unreferenced vertices get none.
std::vector<std::vector<int>> vertex_neighbours(const TriMesh& mesh);

/// Shortest-path distance over the edges (Euclidean lengths) from the nearest of `sources`.
struct GeodesicDistance {
  std::vector<double> dist;  ///< per vertex; +infinity where no source is reachable
  std::vector<int> nearest;  ///< per vertex: index into `sources` of the one reached from (the first listed
                             ///< of a repeated vertex); -1 where unreachable
};

/// Multi-source Dijkstra over `neighbours` (vertex_neighbours()).
GeodesicDistance geodesic_distance(const TriMesh& mesh, const std::vector<std::vector<int>>& neighbours,
                                   const std::vector<int>& sources);

/// The peaks of `f` (per vertex, >= 0, finite on the vertices considered) over the vertices with neighbours
/// and finite f, with their persistence (0-dimensional, superlevel sets): vertices are added in decreasing f
/// (ties by index); where the regions of two peaks meet at vertex v, the lower peak (ties: the smaller vertex
/// id survives) ends with persistence f(peak) − f(v). The highest peak never ends: its persistence is its
/// f. Peaks of persistence 0 are left out. Unsorted: (persistence, vertex) pairs.
std::vector<std::pair<double, int>> persistent_peaks(const std::vector<std::vector<int>>& neighbours,
                                                     const std::vector<double>& f);

}  // namespace geomip
