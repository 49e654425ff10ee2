#include "tools/report.h"

#include <cstdarg>
#include <cstdio>
#include <sstream>

namespace geomip::tools {

nlohmann::json topology_to_json(const TopologyReport& r) {
  nlohmann::json j;
  j["vertices"] = r.vertices;
  j["faces"] = r.faces;
  j["edges"] = r.edges;
  j["components"] = r.components;
  j["boundary_loops"] = r.boundary_loops;
  j["boundary_edges"] = r.boundary_edges;
  j["genus"] = r.genus ? nlohmann::json(*r.genus) : nlohmann::json(nullptr);
  j["manifold"] = r.manifold;
  j["non_manifold_edges"] = r.non_manifold_edges;
  j["non_manifold_vertices"] = r.non_manifold_vertices;
  j["degenerate_faces"] = r.degenerate_faces;
  j["unreferenced_vertices"] = r.unreferenced_vertices;
  j["bbox_diagonal"] = r.bbox_diagonal;
  return j;
}

std::string topology_to_text(const TopologyReport& r) {
  std::ostringstream s;
  s << "  vertices               " << r.vertices << " referenced";
  if (r.unreferenced_vertices) s << " (+" << r.unreferenced_vertices << " unreferenced)";
  s << "\n  faces                  " << r.faces;
  if (r.degenerate_faces) s << " (" << r.degenerate_faces << " degenerate)";
  s << "\n  edges                  " << r.edges;
  s << "\n  components             " << r.components;
  s << "\n  boundary loops         " << r.boundary_loops;
  if (r.boundary_loops) s << " (" << r.boundary_edges << " boundary edges)";
  s << "\n  genus                  ";
  if (r.genus) {
    s << *r.genus;
    if (r.boundary_loops) s << " (holes capped)";
  } else {
    s << "undefined (" << (r.non_manifold_edges ? "non-manifold edges" : "non-orientable") << ")";
  }
  s << "\n  manifold               " << (r.manifold ? "yes" : "no");
  if (!r.manifold) {
    s << " (" << r.non_manifold_edges << " non-manifold edges, " << r.non_manifold_vertices
      << " non-manifold vertices)";
  }
  s.precision(6);
  s << "\n  bounding-box diagonal  " << r.bbox_diagonal << "\n";
  return s.str();
}

std::string string_printf(const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  std::va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(size > 0 ? static_cast<std::size_t>(size) : 0, '\0');
  if (size > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  return text;
}

}  // namespace geomip::tools
