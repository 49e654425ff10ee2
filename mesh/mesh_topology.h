// Topology report of an indexed triangle mesh, counted on the triangles as read (no half-edge structure).
#pragma once

#include "mesh/mesh.h"

#include <optional>

namespace geomip {

/// What `geomip info` reports. Definitions follow ../shared/meshes/README.md:
/// - an edge is an unordered vertex pair; a boundary edge has 1 face, a non-manifold edge more than 2;
/// - a non-manifold ("pinch") vertex is one whose faces form more than one edge-connected fan;
/// - components, boundary loops and genus are those of the surface with pinch vertices split into one vertex
///   per fan (so a pinched sphere still has genus 0), and genus is that of the surface with its holes capped:
///   g = (2C − χ − B)/2 with χ = V − E + F of the split surface.
struct TopologyReport {
  std::size_t vertices = 0;               ///< vertices referenced by at least one face
  std::size_t faces = 0;                  ///< all faces, degenerate ones included
  std::size_t edges = 0;                  ///< unique undirected edges of non-degenerate faces
  std::size_t components = 0;             ///< edge-connected components of faces
  std::size_t boundary_loops = 0;
  std::size_t boundary_edges = 0;
  std::optional<int> genus;               ///< empty when undefined (non-manifold edges, non-orientable)
  bool manifold = false;                  ///< no non-manifold edge and no non-manifold vertex
  std::size_t non_manifold_edges = 0;
  std::size_t non_manifold_vertices = 0;
  std::size_t degenerate_faces = 0;       ///< a repeated vertex index, or exactly zero area
  std::size_t unreferenced_vertices = 0;
  double bbox_diagonal = 0.0;             ///< of the referenced vertices, in the mesh's units
};

/// Counts the topology of `mesh`. Linear-logarithmic in the number of faces; never throws on any input whose
/// indices are in range.
/// \throw InvalidInput if a triangle index is out of range.
TopologyReport analyze_topology(const TriMesh& mesh);

}  // namespace geomip
