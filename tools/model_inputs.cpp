#include "tools/model_inputs.h"

#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "param/partition_points.h"
#include "param/quad_layout.h"
#include "tools/atomic_file.h"
#include "tools/correspondence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <sstream>

namespace geomip::tools {

// repair_mesh() with its refusals said of `path` ("repair_mesh: every face is degenerate" named no file).
RepairResult repair_named(const std::string& path, const TriMesh& input, const RepairOptions& options) {
  try {
    return repair_mesh(input, options);
  } catch (const InvalidInput& e) {
    std::string what = e.what();
    if (what.rfind("repair_mesh: ", 0) == 0) what.erase(0, 13);
    throw InvalidInput(path + ": " + what);
  }
}

namespace {

// The partition needs 4 partition points and 4 auxiliary points, distinct vertices (genus 0).
constexpr std::size_t kMinParameterizableVertices = 8;

// Signed volume enclosed by a closed, consistently oriented mesh (divergence theorem), about its centroid.
double enclosed_volume(const TriMesh& mesh) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : mesh.positions) c += p;
  c /= static_cast<double>(std::max<std::size_t>(mesh.positions.size(), 1));
  double six_v = 0;
  for (const auto& t : mesh.triangles) {
    six_v += (mesh.positions[t[0]] - c).dot((mesh.positions[t[1]] - c).cross(mesh.positions[t[2]] - c));
  }
  return six_v / 6.0;
}

// What the parameterization needs of a prepared (closed, manifold) mesh and cannot say itself in words a user
// can act on: one connected surface, enough vertices for the partition points, and a volume (a flat disk,
// once its hole is filled, is two coincident sheets that no partition can cut into patches).
void check_parameterizable(const std::string& path, const TriMesh& mesh, const TopologyReport& input_report) {
  const TopologyReport r = analyze_topology(mesh);
  if (r.components > 1) {
    throw InvalidInput(path + ": the mesh has " + std::to_string(r.components) +
                       " connected components; geomip parameterizes one connected surface: keep the largest "
                       "with `geomip repair --largest-component IN -o OUT` and use OUT");
  }
  if (r.vertices < kMinParameterizableVertices) {
    throw InvalidInput(path + ": too few vertices to parameterize (" + std::to_string(input_report.vertices) +
                       " in the file, " + std::to_string(r.vertices) + " after repair; at least " +
                       std::to_string(kMinParameterizableVertices) + " are needed)");
  }
  const double diagonal = r.bbox_diagonal;
  if (!(diagonal > 0) || std::abs(enclosed_volume(mesh)) < 1e-6 * diagonal * diagonal * diagonal) {
    throw InvalidInput(path + ": the mesh is flat (" +
                       std::string(input_report.boundary_loops
                                       ? "a surface with a boundary whose filled holes "
                                         "enclose no volume"
                                       : "it encloses no volume") +
                       "); geomip parameterizes closed surfaces around a volume");
  }
}

// True when no directed edge appears twice: neighbouring faces run through their shared edge in opposite
// directions (a closed manifold mesh with one face flipped is still "manifold" to analyze_topology, but its
// signed volume cancels and its partition fails).
bool consistently_oriented(const TriMesh& mesh) {
  std::vector<std::pair<int, int>> directed;
  directed.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) directed.emplace_back(t[k], t[(k + 1) % 3]);
  std::sort(directed.begin(), directed.end());
  return std::adjacent_find(directed.begin(), directed.end()) == directed.end();
}

// The mesh ready for partitioning: repaired when open, non-manifold, degenerate or inconsistently oriented
// (with a note on stderr).
TriMesh prepare_mesh(const std::string& path, const TriMesh& input, const std::string& command, bool quiet) {
  const TopologyReport r = analyze_topology(input);
  const bool oriented = consistently_oriented(input);
  if (r.boundary_loops == 0 && r.manifold && r.degenerate_faces == 0 && oriented) {
    check_parameterizable(path, input, r);
    return input;
  }
  const RepairResult repaired = repair_named(path, input);
  check_parameterizable(path, repaired.mesh, r);
  if (!quiet) {
    std::cerr << command << ": " << path << ": "
              << (r.boundary_loops                                    ? "open"
                  : !r.manifold || r.degenerate_faces > 0 || oriented ? "non-manifold or degenerate"
                                                                      : "inconsistently oriented")
              << " mesh repaired first (as `geomip repair`): " << repaired.filled_holes << " holes filled, "
              << repaired.split_non_manifold_vertices << " vertices split, "
              << repaired.removed_degenerate_faces << " degenerate faces removed\n";
  }
  return repaired.mesh;
}

// How far an [x,y,z] point of CORR.json may lie from the mesh's nearest vertex, as a fraction of the mesh's
// bounding-box diagonal.
constexpr double kMaxSnapDistance = 0.05;

// A point of CORR.json as a position of the input file, then the nearest vertex of the prepared mesh (the
// same vertex when the mesh was not repaired, its surviving copy when it was). An [x,y,z] point farther than
// kMaxSnapDistance from every vertex is refused.
int resolve_point(const PointSpec& p, const TriMesh& input, const TriMesh& mesh, const std::string& what,
                  const std::string& file) {
  Eigen::Vector3d target = p.position;
  if (p.index >= 0) {
    if (p.index >= static_cast<long long>(input.positions.size())) {
      throw InvalidInput(file + ": " + what + " is vertex " + std::to_string(p.index) +
                         ", but the mesh has " + std::to_string(input.positions.size()) + " vertices");
    }
    if (&input == &mesh) return static_cast<int>(p.index);
    target = input.positions[p.index];
  }
  std::vector<char> referenced(mesh.positions.size(), 0);
  for (const auto& t : mesh.triangles) referenced[t[0]] = referenced[t[1]] = referenced[t[2]] = 1;
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    if (!referenced[v]) continue;
    const double d = (mesh.positions[v] - target).squaredNorm();
    if (d < best_d) {
      best_d = d;
      best = static_cast<int>(v);
    }
  }
  // An [x,y,z] point snaps to the nearest vertex, but one far from the surface is a mistake (another unit,
  // another mesh, a typo), not a choice: refuse it rather than pick a vertex the user did not mean.
  const double diagonal = referenced_bounding_box(mesh).diagonal();
  if (p.index < 0 && std::sqrt(best_d) > kMaxSnapDistance * diagonal) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "%s [%g, %g, %g] is %.3g from the nearest vertex of the mesh, %.1f %% of its bounding-box "
                  "diagonal (at most %.0f %%: points snap to the nearest vertex; wrong units or mesh?)",
                  what.c_str(), target.x(), target.y(), target.z(), std::sqrt(best_d),
                  100 * std::sqrt(best_d) / diagonal, 100 * kMaxSnapDistance);
    throw InvalidInput(file + ": " + text);
  }
  return best;
}

std::vector<int> resolve_points(const std::vector<PointSpec>& specs, const TriMesh& input,
                                const TriMesh& mesh, const std::string& what, const std::string& file) {
  std::vector<int> ids;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    ids.push_back(resolve_point(specs[i], input, mesh, what + "[" + std::to_string(i) + "]", file));
  }
  return ids;
}

// Options of an automatic K-quad layout: the defaults, by equal area when `equal_area_layout`.
QuadLayoutOptions automatic_layout_options(int patches, bool equal_area_layout,
                                           const std::vector<double>& error_weights) {
  QuadLayoutOptions options;
  options.patches = patches;
  if (equal_area_layout) options.error_weight = 0.0;
  options.error_weight_factors = error_weights;
  return options;
}

void check_layout_error_weights(const std::vector<double>& weights) {
  if (weights.empty() || weights.size() > kMaxLayoutErrorWeights)
    throw InvalidInput("--layout-error-weights: give 1 to " + std::to_string(kMaxLayoutErrorWeights) +
                       " weights (" + std::to_string(weights.size()) + " given)");
  for (double w : weights)
    if (!std::isfinite(w) || w <= 0.0)
      throw InvalidInput("--layout-error-weights: every weight must be a finite number > 0");
}

// Genus ≥ 2 has no two-square (or 2×2 periodic) layout: quad layouts of increasing K, from the smallest the
// genus allows (K + 2 − 2g = 4 coarse vertices), until one partitions the mesh.
QuadLayoutChoice layout_for_high_genus(const TriMesh& mesh, int genus, const std::string& name,
                                       const std::string& command, bool quiet, bool equal_area_layout,
                                       const std::vector<double>& error_weights) {
  std::vector<int> ks;
  for (int k : {2 * genus + 2, 4 * genus, 6 * genus, 8 * genus, 12 * genus, 16 * genus, 24 * genus, 32 * genus})
    if (k + 2 - 2 * genus <= static_cast<int>(mesh.positions.size()) && (ks.empty() || k > ks.back())) ks.push_back(k);
  std::string tried;
  for (int k : ks) {
    try {
      QuadLayoutChoice chosen =
          choose_quad_layout(mesh, automatic_layout_options(k, equal_area_layout, error_weights));
      if (!quiet)
        std::cerr << command << ": " << name << " has genus " << genus << ": automatic layout of " << k
                  << " patches (--patches K chooses another)\n";
      return chosen;
    } catch (const InvalidInput&) {
      tried += (tried.empty() ? "" : ", ") + std::to_string(k);
    }
  }
  throw InvalidInput(name + ": genus " + std::to_string(genus) + ", and no automatic quad layout of " + tried +
                     " patches partitions it; give its layout in a --points CORR.json");
}

const char* loop_flag(LoopKind loop) { return loop == LoopKind::kEnds ? "--end-loop" : "--tip-loop"; }

}  // namespace

PartitionPointsOptions loop_options(LoopKind kind) {
  PartitionPointsOptions o;
  o.tip_loop = kind != LoopKind::kPlain;
  if (kind == LoopKind::kEnds) {
    o.outline_guides = 4;
    o.tube_ratio = 2.5;
  }
  return o;
}

int default_seam_slide_rounds(LoopKind kind) { return kind == LoopKind::kEnds ? 10 : 0; }

LoopKind loop_kind(bool tip_loop, bool end_loop) {
  if (tip_loop && end_loop) throw InvalidInput("--tip-loop and --end-loop are two different loops: give one");
  return end_loop ? LoopKind::kEnds : tip_loop ? LoopKind::kTips : LoopKind::kPlain;
}

void check_loop_patches(LoopKind loop, int patches) {
  if (loop != LoopKind::kPlain && patches != 2)
    throw InvalidInput(std::string(loop_flag(loop)) + " routes the two-square loop; it does not go with --patches " +
                       std::to_string(patches));
}

PreparedModels prepare_models(const std::vector<std::string>& meshes, const std::string& points_file_arg,
                              const std::string& command, bool quiet, int patches, LoopKind loop,
                              bool equal_area_layout, const std::vector<double>& error_weights) {
  const bool tip_loop = loop != LoopKind::kPlain;
  PreparedModels models;
  std::vector<ParameterizationInput>& inputs = models.inputs;
  std::vector<std::string>& paths = models.paths;
  std::vector<ModelSpec> specs;
  const std::string& points_file = points_file_arg;
  if (patches < 2) throw InvalidInput("--patches " + std::to_string(patches) + ": a layout needs at least 2");
  check_loop_patches(loop, patches);
  check_layout_error_weights(error_weights);
  if (!points_file_arg.empty()) {
    if (!meshes.empty()) {
      throw InvalidInput("give either meshes or --points CORR.json (which names the meshes), not both");
    }
    if (patches != 2) {
      throw InvalidInput("--patches chooses an automatic layout; with --points CORR.json the file gives the points");
    }
    if (tip_loop) {
      throw InvalidInput(std::string(loop_flag(loop)) + " chooses automatic partition points; with --points CORR.json the file gives them");
    }
    specs = read_correspondence(points_file_arg);
  } else {
    if (meshes.size() > 1) {
      throw InvalidInput("several meshes need --points CORR.json: their partition points must correspond");
    }
    if (meshes.empty()) throw InvalidInput("no mesh given (a MESH or --points CORR.json)");
    specs.push_back(ModelSpec{meshes[0], {}, {}, {}, {}, {}});
  }

  for (std::size_t m = 0; m < specs.size(); ++m) {
    const ModelSpec& spec = specs[m];
    note_input_file(spec.mesh);
    const TriMesh input = read_mesh(spec.mesh);
    ParameterizationInput in;
    in.mesh = prepare_mesh(spec.mesh, input, command, quiet);
    in.name = std::filesystem::path(spec.mesh).stem().string();
    // Point indices refer to the file as written; after a repair they are matched by position.
    const bool repaired =
        in.mesh.positions.size() != input.positions.size() || in.mesh.triangles != input.triangles;
    const TriMesh& source = repaired ? input : in.mesh;
    const std::string where = points_file.empty()
                                  ? spec.mesh
                                  : points_file + ": models[" + std::to_string(m) + "] (" +
                                        std::filesystem::path(spec.mesh).filename().string() + ")";
    const int genus = spec.partition_points.empty() && patches == 2 ? analyze_topology(in.mesh).genus.value_or(0) : 0;
    if (genus >= 2) {
      const QuadLayoutChoice chosen =
          layout_for_high_genus(in.mesh, genus, spec.mesh, command, quiet, equal_area_layout, error_weights);
      in.partition_points = chosen.layout.corners;
      in.layout_quads = chosen.layout.quads;
    } else if (spec.partition_points.empty() && patches != 2) {
      QuadLayoutChoice chosen;
      try {
        chosen =
            choose_quad_layout(in.mesh, automatic_layout_options(patches, equal_area_layout, error_weights));
      } catch (const InvalidInput& e) {  // name the mesh: the message is the layout's
        throw InvalidInput(spec.mesh + ": " + e.what());
      }
      in.partition_points = chosen.layout.corners;
      in.layout_quads = chosen.layout.quads;
    } else if (spec.partition_points.empty()) {
      const PartitionPointsOptions point_options = loop_options(loop);
      const PartitionPoints chosen = choose_partition_points(in.mesh, point_options);
      in.partition_points = chosen.partition_points;
      in.auxiliary_points = chosen.auxiliary_points;
      in.side_guides = chosen.side_guides;
      if (tip_loop && in.side_guides.empty() && !quiet)  // say so, rather than quietly give the plain loop
        std::fprintf(
            stderr, "%s: %s: %s found no protrusion tips to route the loop through; the plain loop is used\n",
            command.c_str(), spec.mesh.c_str(), loop_flag(loop));
    } else {
      in.partition_points = resolve_points(spec.partition_points, source, in.mesh, "partition_points", where);
      in.auxiliary_points = resolve_points(spec.auxiliary_points, source, in.mesh, "auxiliary_points", where);
      for (std::size_t k = 0; k < spec.side_guides.size(); ++k) {
        in.side_guides.push_back(resolve_points(spec.side_guides[k], source, in.mesh,
                                                "side_guides[" + std::to_string(k) + "]", where));
      }
      in.features = resolve_points(spec.features, source, in.mesh, "features", where);
      in.layout_quads = spec.layout_quads;
    }
    inputs.push_back(std::move(in));
    paths.push_back(spec.mesh);
    models.originals.push_back(repaired ? input : TriMesh{});
  }
  // Two meshes of the same stem (a/spot.obj, b/spot.obj) get distinct names: outputs are named after them.
  std::vector<std::string> names;
  for (const auto& in : inputs) names.push_back(in.name);
  const std::vector<std::string> unique = model_file_names(names);
  for (std::size_t i = 0; i < inputs.size(); ++i) inputs[i].name = unique[i];
  return models;
}

CLI::Validator finite_range(double lo, double hi) {
  const auto number = [](double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  };
  const std::string range = "[" + number(lo) + " - " + number(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double v = 0;
        std::size_t used = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != text.size()) return "Value " + text + " is not a number";
        if (!std::isfinite(v) || v < lo || v > hi) return "Value " + text + " not in range " + range;
        return {};
      },
      "FLOAT in " + range);
}

void add_model_options(CLI::App* cmd, ModelArgs& args) {
  cmd->add_option("mesh", args.meshes, "One mesh (partition points chosen automatically)");
  cmd->add_option("--points", args.points,
                  "Correspondence file naming the meshes, their partition/auxiliary points and features");
  cmd->add_option("-o,--output", args.output, "Output directory (created if missing)")->required();
  cmd->add_flag("--json", args.json, "Machine-readable summary on stdout");
  cmd->add_flag("-q,--quiet", args.quiet, "No progress bar, no report");
  cmd->add_option(
         "--sampling-exponent", args.sampling_exponent,
         "Curvature sampling exponent g: stretch weights ((eps + |II|^2)/eps)^g give bent regions more "
         "samples; 0 = plain geometric stretch (default: 1/3 for param, gimage, remesh; 0 for convert)")
      ->check(finite_range(0.0, 2.0));
  cmd->add_option(
         "--curvature-metric", args.curvature_metric,
         "Anisotropic stretch: measure triangles in the metric I + L*D*|S| (S the shape operator, D the "
         "bounding-box diagonal), so directions in which the surface bends get more samples than "
         "straight ones (around a leg, not along it); 0 = Euclidean (default 0.03)")
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--linf-sweeps", args.linf_sweeps,
                  "Sweeps of the L-infinity pass after the stretch optimization: lowers each patch's worst "
                  "stretch (never raises it), raises the L2 stretch (default 0: off)")
      ->check(CLI::Range(0, 10000));
  add_patches_option(cmd, args.patches, args.patches_given, args.equal_area_layout, args.layout_error_weights,
                     args.layout_error_weights_given);
  cmd->add_flag("--tip-loop", args.tip_loop,
                "Two squares (genus 0): route the cut down each protrusion (legs, ears) to its tip and back, "
                "splitting it lengthwise between the squares (default off: helps some shapes, hurts others; "
                "docs/measurements.md)");
  cmd->add_flag("--end-loop", args.end_loop,
                "Two squares (genus 0): a loop through the shape's ends (hooves, nose, tail), joined by shortest "
                "paths through 4 outline guides, with sliding seams (default off; helps the horse at low rates, "
                "not the cow or the bunny: docs/measurements.md)");
  cmd->add_option("--slide-seams", args.slide_seams,
                  "Rounds of sliding seams: every seam vertex moves along its side to where its triangles in both "
                  "patches are least stretched, then stretch sweeps (default: 10 with --end-loop, else 0)")
      ->check(CLI::Range(0, 1000));
}

void add_patches_option(CLI::App* cmd, int& patches, bool& given, bool& equal_area_layout,
                        std::vector<double>& error_weights, bool& weights_given) {
  cmd->add_option(
         "--patches", patches,
         "Patches of the automatic layout: 2 (default) cuts the mesh into two squares along one loop "
         "(genus 1: a 2x2 periodic grid; genus >= 2: the first K = 2g+2, 4g, 6g, ... quad layout that fits); "
         "K >= 3 pairs the triangles of a coarse mesh into K quads (any genus: K + 2 - 2g >= 4). "
         "convert and rd without --patches move one mesh that two squares stretch (L2 stretch >= 1.5) "
         "to 16 patches one level coarser or 64 two levels coarser, whichever layout's prefixes measure "
         "closer to the mesh; --patches 2 keeps the two squares")
      ->each([&given](const std::string&) { given = true; });
  cmd->add_flag(
      "--equal-area-layout", equal_area_layout,
      "K-quad layouts: simplify to the coarse mesh by equal area (the layouts before 2026-12-04) instead "
      "of equal error (patches crowd where the surface bends)");
  cmd->add_option(
         "--layout-error-weights", error_weights,
         "K-quad layouts by equal error: simplify the mesh once with each of these multiples of the error "
         "weight (comma-separated, at most 8) and keep the pairing of least sampling cost among all (default "
         "1). convert and rd without --patches try both 1 and 1,0.5,2,0.25,4 on a stretched shape and keep "
         "the layout whose prefixes measure closer to the mesh")
      ->delimiter(',')
      ->type_name("W")
      ->check(finite_range(1e-6, 1e6).description(""))
      ->each([&weights_given](const std::string&) { weights_given = true; });
}

void apply_sampling(const ModelArgs& args, ParameterizationOptions& options) {
  options.curvature_sampling = args.sampling_exponent > 0;
  options.sampling_weights.exponent = args.sampling_exponent;
  options.curvature_metric = args.curvature_metric;
  options.linf_sweeps = static_cast<std::size_t>(args.linf_sweeps);
  options.seam_slide_rounds = args.slide_seams >= 0 ? args.slide_seams : default_seam_slide_rounds(loop_kind(args));
}

}  // namespace geomip::tools
