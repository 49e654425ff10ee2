// geomip rd MESH -o DIR [--json] [--quick] [--no-lindstrom-turk]: rate–distortion baselines of MESH — Draco
// on the full mesh over quantization bits, Draco on QEM-decimated copies (faces × bits; meshoptimizer's
// simplifier, and CGAL's Lindstrom–Turk where the mesh is an oriented 2-manifold) and their upper envelopes,
// meshoptimizer's codec — each
// decoded mesh measured against MESH with the Metro-style surface distance — and geomip: MESH converted to a
// geometry-only pack (DIR/<stem>.gip), measured at many byte prefixes. Writes DIR/rd.csv (every point) and
// DIR/rd.svg (the plot).
//
// The command is a list of series: each series is a method name and a list of jobs, a job codes one mesh and
// returns its bytes, decoded mesh and decode time; evaluation, the envelope, the files and the table are the
// same for every series. A further codec adds one `Series` to `plan_series()`.
#include "baselines/draco_baseline.h"
#include "baselines/mesh_decimation.h"
#include "baselines/meshopt_baseline.h"
#include "baselines/rd_curve.h"
#include "codec/parallel.h"
#include "gimage/surface_distance.h"
#include "mesh/errors.h"
#include "mesh/gltf_io.h"
#include "mesh/mesh_io.h"
#include "tools/atomic_file.h"
#include "tools/commands.h"
#include "tools/convert_pipeline.h"
#include "tools/convert_search.h"
#include "tools/model_inputs.h"
#include "tools/pack_models.h"
#include "tools/progress.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace geomip::tools {
namespace {

struct RdArgs {
  std::string mesh;
  std::string output;
  bool json = false;
  bool quiet = false;  // -q: no progress bar, no table
  bool quick = false;
  // The draco_lt series (CGAL Lindstrom–Turk decimation) and its envelope, the strongest baseline: by default
  // whenever the mesh is an oriented 2-manifold (else a note, and none); --lindstrom-turk: required (a mesh
  // it cannot take is an error); --no-lindstrom-turk: never.
  bool lindstrom_turk = false;
  bool no_lindstrom_turk = false;
  std::size_t samples = 0;  // face samples per surface for the evaluation; 0 = surface_distance's default
  unsigned threads = 0;     // 0 = hardware_concurrency
  int level = 8;  // geomip: the pack's geometry image level (without --level: default_grid_level(patches))
  bool no_geomip = false;   // only the baselines
  int normal_mesh_steps = -1;  // geomip: normal-mesh resampling steps (-1 = the convert default, 0 = off)
  int patches = 2;          // geomip: patches of the automatic layout (--patches)
  bool patches_given = false;      // --patches given (else a stretched shape moves to 16 or 64 patches)
  bool equal_area_layout = false;  // geomip: --equal-area-layout
  std::vector<double> layout_error_weights = {1.0};  // geomip: --layout-error-weights
  bool layout_error_weights_given = false;  // (else a stretched shape tries kStretchedLayoutErrorWeights)
  bool fit = false;         // geomip: least-squares fitted samples (--fit, as `geomip convert`)
  bool fit_given = false;   // --fit or --no-fit given (else fit_by_default(), as `geomip convert`)
  bool tip_loop = false;    // geomip: the two-square loop through the tips (--tip-loop, as `geomip convert`)
  bool end_loop = false;    // geomip: the loop through the ends (--end-loop, as `geomip convert`)
  bool search = false;  // geomip: the best of the loops, the 8- to 64-patch layouts, the fit, ... (--search)
};

/// One coded mesh: its R-D point (bytes, decode time and parameters filled; distortion not yet) and the
/// decoded mesh to measure.
struct Coded {
  RdPoint point;
  TriMesh decoded;
};
using Job = std::function<Coded()>;

struct Series {
  std::string method;
  std::vector<Job> jobs;
};

/// The sweep parameters (the full sweep, or the --quick one for tests).
struct Sweep {
  std::vector<int> draco_bits;      // Draco on the full mesh
  std::vector<std::size_t> faces;   // decimation targets (those below the mesh's face count are used)
  std::vector<int> draco_qem_bits;  // Draco on each decimated mesh
  std::vector<int> meshopt_bits;    // meshoptimizer's codec on the full mesh
};

Sweep make_sweep(bool quick) {
  if (quick) return {{8, 11, 14}, {500, 2000}, {8, 11}, {16}};
  return {{6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16},
          {500, 750, 1000, 1500, 2000, 3000, 4000, 6000, 8000, 12000, 16000, 24000, 32000, 40000},
          {7, 8, 9, 10, 11, 12, 13},
          {12, 14, 16}};
}

constexpr int kDracoLevel = 10;  // draco_encoder -cl 10: speed 0, the smallest streams

Job draco_job(std::string method, std::shared_ptr<const TriMesh> mesh, int bits) {
  return [method = std::move(method), mesh = std::move(mesh), bits] {
    DracoOptions options;
    options.quantization_bits = bits;
    options.compression_level = kDracoLevel;
    DracoResult r = draco_encode(*mesh, options);
    Coded c;
    c.point.method = method;
    c.point.bytes = r.bytes.size();
    c.point.decode_ms = r.decode_ms;
    c.point.faces = mesh->num_triangles();
    c.point.vertices = r.decoded.num_vertices();
    c.point.quantization_bits = bits;
    c.decoded = std::move(r.decoded);
    return c;
  };
}

Job meshopt_job(std::shared_ptr<const TriMesh> mesh, int bits) {
  return [mesh = std::move(mesh), bits] {
    MeshoptCodecOptions options;
    options.quantization_bits = bits;
    MeshoptCodecResult r = meshopt_encode(*mesh, options);
    Coded c;
    c.point.method = "meshopt";
    c.point.bytes = r.bytes;
    c.point.decode_ms = r.decode_ms;
    c.point.faces = mesh->num_triangles();
    c.point.vertices = r.decoded.num_vertices();
    c.point.quantization_bits = bits;
    c.decoded = std::move(r.decoded);
    return c;
  };
}

/// Every series of the report. Decimation happens here (in parallel), coding later, in the jobs.
/// The decimated copies of `original` at `sweep.faces` (those below its face count), in parallel.
std::vector<std::shared_ptr<const TriMesh>> decimate_all(const std::shared_ptr<const TriMesh>& original,
                                                         const Sweep& sweep, DecimationMethod method,
                                                         unsigned threads, ProgressBar& progress) {
  std::vector<std::size_t> faces;
  for (std::size_t f : sweep.faces)
    if (f < original->num_triangles()) faces.push_back(f);
  std::vector<std::shared_ptr<const TriMesh>> decimated(faces.size());
  std::atomic<std::size_t> done{0};
  std::mutex progress_mutex;
  DecimationOptions options;
  options.method = method;
  codec::parallel_for(static_cast<int>(faces.size()), static_cast<int>(threads), [&](int i) {
    decimated[i] = std::make_shared<const TriMesh>(decimate_mesh(*original, faces[i], options).mesh);
    std::lock_guard<std::mutex> lock(progress_mutex);
    progress.update("decimating", static_cast<double>(++done) / static_cast<double>(faces.size()));
  });
  return decimated;
}

std::vector<Series> plan_series(const std::shared_ptr<const TriMesh>& original, const Sweep& sweep,
                                bool lindstrom_turk, unsigned threads, ProgressBar& progress) {
  std::vector<Series> plan;

  Series draco{"draco", {}};
  for (int q : sweep.draco_bits) draco.jobs.push_back(draco_job("draco", original, q));
  plan.push_back(std::move(draco));

  Series qem{"draco_qem", {}};
  for (const auto& mesh : decimate_all(original, sweep, DecimationMethod::kMeshopt, threads, progress))
    for (int q : sweep.draco_qem_bits) qem.jobs.push_back(draco_job("draco_qem", mesh, q));
  plan.push_back(std::move(qem));

  if (lindstrom_turk) {
    Series lt{"draco_lt", {}};
    for (const auto& mesh :
         decimate_all(original, sweep, DecimationMethod::kLindstromTurk, threads, progress))
      for (int q : sweep.draco_qem_bits) lt.jobs.push_back(draco_job("draco_lt", mesh, q));
    plan.push_back(std::move(lt));
  }

  Series meshopt{"meshopt", {}};
  for (int q : sweep.meshopt_bits) meshopt.jobs.push_back(meshopt_job(original, q));
  plan.push_back(std::move(meshopt));

  // A further codec appends its Series here; an envelope over it is one more entry of kEnvelopes.
  return plan;
}

/// The sizes at which rd's table compares geomip with the Draco envelopes: those issues 5 and 14 name.
constexpr std::size_t kComparisonSizes[] = {1500, 2000, 4700, 8800, 12000, 16000, 21100, 32000, 32800, 42800};

/// The byte sizes at which geomip prefixes are measured: the comparison sizes, plus a geometric sweep from
/// just after the manifest to the whole pack.
std::vector<std::size_t> prefix_sizes(std::size_t manifest_end, std::size_t pack_size, bool quick) {
  std::set<std::size_t> sizes;
  if (!quick)
    for (std::size_t s : kComparisonSizes) sizes.insert(s);
  else  // three rows of the table (the others are left out of it)
    sizes.insert({2000, 8800, 32000});
  const double lo = static_cast<double>(manifest_end + 100), hi = static_cast<double>(pack_size);
  const int count = quick ? 4 : 20;
  for (int k = 0; k < count && lo < hi; ++k)
    sizes.insert(static_cast<std::size_t>(std::llround(lo * std::pow(hi / lo, k / double(count - 1)))));
  std::vector<std::size_t> out;
  for (std::size_t s : sizes)
    if (s > manifest_end && s <= pack_size) out.push_back(s);
  return out;
}

/// geomip: the mesh converted once (repair → parameterization → level-N geometry images → geometry-only
/// pack), then one job per prefix size: decode the first N bytes and build the level-N mesh. `search`: the
/// pack of search_conversion() (the loops, the K-patch layouts, the fit, ...), its choice in `chosen`.
/// `relayout`: the layout was left to us (no --patches, the plain loop), so a shape that two squares stretch
/// moves to 16 or 64 patches, whichever codes it better, as `geomip convert` does
/// (convert_relayout_when_stretched()); `moved` then reports the choice (chosen_patches 0: not moved).
Series geomip_series(const RdArgs& args, LoopKind loop, bool relayout, std::vector<std::uint8_t>& pack_out,
                     std::optional<SearchResult>& chosen, RelayoutChoice& moved, ProgressBar& progress) {
  const std::string& mesh_path = args.mesh;
  const int level = args.level, normal_mesh_steps = args.normal_mesh_steps;
  ConvertOptions options;
  options.seam_slide_rounds = default_seam_slide_rounds(loop);
  options.level = level;
  options.normals = false;
  options.normal_mesh_steps = normal_mesh_steps;
  options.fit = args.fit;  // --search: the search tries the fit itself
  options.threads = static_cast<int>(args.threads);
  options.progress = [&](const char* stage, double f) { progress.update(stage, f); };
  std::shared_ptr<const std::vector<std::uint8_t>> pack;
  if (args.search) {
    chosen = search_conversion(mesh_path, options, full_search_options(), true);
    pack = std::make_shared<const std::vector<std::uint8_t>>(chosen->converted.pack);
  } else {
    PreparedModels models = prepare_models({mesh_path}, "", "geomip rd", true, args.patches, loop,
                                           args.equal_area_layout, args.layout_error_weights);
    if (!args.fit_given) options.fit = fit_by_default(models.inputs.size());  // as `geomip convert`
    ConvertResult converted = convert_relayout_when_stretched(
        models, options,
        [&](int k, std::string& why_not) {
          if (!relayout) return -1;
          const int coarser = relayout_level(level, k);
          // The default framed steps are capped at the level; asked-for normal-mesh steps must fit.
          if (coarser < 1 || normal_mesh_steps > coarser) {
            why_not = coarser < 1 ? "its level would be below 1" : "--normal-mesh is above its level";
            return 0;
          }
          return coarser;
        },
        args.layout_error_weights_given ? std::vector<std::vector<double>>{args.layout_error_weights}
                                        : kStretchedLayoutErrorWeights,
        [&](int k, const std::vector<double>& weights) {
          return prepare_models({mesh_path}, "", "geomip rd", true, k, LoopKind::kPlain,
                                args.equal_area_layout, weights);
        },
        {}, moved);
    pack = std::make_shared<const std::vector<std::uint8_t>>(std::move(converted.pack));
  }
  pack_out = *pack;
  codec::PackInfo info;
  codec::read_pack_info(*pack, info);
  Series series{"geomip", {}};
  for (std::size_t size : prefix_sizes(info.manifest_end, pack->size(), args.quick)) {
    series.jobs.push_back([pack, size] {
      codec::PackDecodeOptions decode;
      decode.max_bytes = size;
      decode.normals = false;
      codec::PackDecodeResult result;
      double best_ms = INFINITY;
      for (int r = 0; r < 3; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        result = codec::decode_pack(*pack, decode);
        best_ms = std::min(best_ms,
                           std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      }
      if (result.models.empty())
        throw SolverFailure("geomip rd: a " + std::to_string(size) + "-byte prefix of the pack does not decode");
      Coded c;
      c.decoded = decoded_mesh(result.models.front());
      c.point.method = "geomip";
      c.point.bytes = size;
      c.point.decode_ms = best_ms;
      c.point.faces = c.decoded.num_triangles();
      c.point.vertices = c.decoded.num_vertices();
      c.point.quantization_bits = ConvertOptions{}.quantization_bits;
      return c;
    });
  }
  return series;
}

/// Envelopes written as series of their own: name and the methods whose points they are taken over. An
/// envelope is written when one of its methods has points that no earlier envelope covers.
struct Envelope {
  std::string name;
  std::set<std::string> methods;
};
const std::vector<Envelope> kEnvelopes = {
    {"draco_envelope", {"draco", "draco_qem"}},  // issue 5's Draco baseline
    {"draco_lt_envelope",
     {"draco", "draco_qem", "draco_lt"}},  // with the stronger decimation (--lindstrom-turk)
};

template <typename... T>
std::string format(const char* fmt, T... values) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, fmt, values...);
  return buffer;
}

nlohmann::json point_to_json(const RdPoint& p) {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json j{{"method", p.method},
                   {"bytes", p.bytes},
                   {"psnr_db", num(p.psnr_db)},
                   {"hausdorff_pct", num(p.hausdorff_pct)},
                   {"rms_pct", num(p.rms_pct)},
                   {"decode_ms", num(p.decode_ms)},
                   {"faces", p.faces},
                   {"vertices", p.vertices},
                   {"quantization_bits", p.quantization_bits}};
  if (!p.source.empty()) j["source"] = p.source;
  return j;
}

std::string point_row(const RdPoint& p) {
  return format("%-15s %7zu %3d %9zu %9.2f %8.2f %9.4f %9.3f\n", p.method.c_str(), p.faces,
                p.quantization_bits, p.bytes, static_cast<double>(p.bytes) / 1000.0, p.psnr_db,
                p.hausdorff_pct, p.decode_ms);
}

int run_rd(const RdArgs& args) {
  // Before the baselines' work: bad loop options fail at once.
  const LoopKind loop = loop_kind(args.tip_loop, args.end_loop);
  check_loop_patches(loop, args.patches);
  check_output_directory(args.output);
  if (args.search &&
      (args.patches != 2 || args.layout_error_weights_given || loop != LoopKind::kPlain || args.fit_given))
    throw InvalidInput(
        "--search chooses the layout and the fit itself: not with --patches, "
        "--layout-error-weights, --tip-loop, --end-loop, --fit or --no-fit");
  const auto start = std::chrono::steady_clock::now();
  note_input_file(args.mesh);
  const auto original = std::make_shared<const TriMesh>(read_mesh(args.mesh));
  check_draco_positions(original->positions, args.mesh);  // every series codes with Draco: refused now
  const unsigned threads =
      args.threads > 0 ? args.threads : std::max(1u, std::thread::hardware_concurrency());
  const Sweep sweep = make_sweep(args.quick);

  bool lindstrom_turk = !args.no_lindstrom_turk;
  if (lindstrom_turk) {
    if (const std::optional<std::string> why = lindstrom_turk_refusal(*original)) {
      if (args.lindstrom_turk)
        throw InvalidInput("--lindstrom-turk needs an oriented 2-manifold, and " + args.mesh + " is " + *why +
                           " (`geomip repair` makes one)");
      lindstrom_turk = false;
      std::fprintf(stderr,
                   "note: no Lindstrom-Turk baseline (draco_lt, draco_lt_envelope), the strongest one: %s is "
                   "%s (`geomip repair` makes an oriented 2-manifold; --no-lindstrom-turk drops this note)\n",
                   args.mesh.c_str(), why->c_str());
    }
  }
  ProgressBar progress("rd", !args.json && !args.quiet);
  std::vector<Series> plan = plan_series(original, sweep, lindstrom_turk, threads, progress);
  std::vector<std::uint8_t> pack;
  std::optional<SearchResult> searched;
  RelayoutChoice moved;  // the layout chosen for a shape two squares stretch
  if (!args.no_geomip)
    plan.push_back(geomip_series(args, loop, !args.patches_given && loop == LoopKind::kPlain, pack, searched,
                                 moved, progress));

  // Code and measure every job: one job per worker, each distance query single-threaded.
  struct Slot {
    std::size_t series;
    std::size_t job;
  };
  std::vector<Slot> slots;
  for (std::size_t s = 0; s < plan.size(); ++s)
    for (std::size_t j = 0; j < plan[s].jobs.size(); ++j) slots.push_back({s, j});
  std::vector<RdPoint> measured(slots.size());
  SurfaceDistanceOptions distance_options;
  distance_options.threads = 1;
  distance_options.face_samples = args.samples > 0 ? args.samples : (args.quick ? 20000 : 0);
  std::atomic<std::size_t> done{0};
  std::mutex progress_mutex;
  codec::parallel_for(static_cast<int>(slots.size()), static_cast<int>(threads), [&](int i) {
    Coded c = plan[slots[i].series].jobs[slots[i].job]();
    SurfaceDistance d;
    try {
      d = measure_surface_distance(*original, c.decoded, distance_options);
    } catch (const InvalidInput& e) {  // the decoded mesh is ours, not the user's
      throw SolverFailure(c.point.method + " Q" + std::to_string(c.point.quantization_bits) + " " +
                          std::to_string(c.point.faces) +
                          " faces: cannot measure the decoded mesh: " + e.what());
    }
    c.point.psnr_db = d.psnr_db;
    c.point.hausdorff_pct = d.hausdorff_pct;
    c.point.rms_pct = d.rms_pct;
    measured[i] = std::move(c.point);
    std::lock_guard<std::mutex> lock(progress_mutex);
    progress.update("coding and measuring", static_cast<double>(++done) / static_cast<double>(slots.size()));
  });
  progress.finish();

  std::vector<RdPoint> all = measured;
  std::set<std::string> covered;
  for (const Envelope& e : kEnvelopes) {
    std::vector<RdPoint> input;
    bool adds = false;
    for (const RdPoint& p : measured)
      if (e.methods.count(p.method) != 0) {
        input.push_back(p);
        adds = adds || covered.count(p.method) == 0;
      }
    if (!adds) continue;
    covered.insert(e.methods.begin(), e.methods.end());
    for (RdPoint p : upper_envelope(input)) {
      p.source = p.method;
      p.method = e.name;
      all.push_back(std::move(p));
    }
  }

  // Render both files first, then write them as one set: a failure leaves none of them written.
  std::ostringstream csv, svg;
  write_rd_csv(csv, all);
  RdPlotOptions plot;
  plot.scatter_methods = {"draco_qem", "draco_lt"};
  plot.title = "Rate-distortion: " + std::filesystem::path(args.mesh).filename().string() + " (" +
               std::to_string(original->num_triangles()) + " faces)";
  write_rd_svg(svg, all, plot);
  const CreatedDirectories created = make_output_directory(args.output);
  const std::filesystem::path dir(args.output);
  AtomicFileSet files;  // the table, the plot and the pack, or none of them
  files.add((dir / "rd.csv").string(), [&](std::ostream& out) { out << csv.str(); });
  files.add((dir / "rd.svg").string(), [&](std::ostream& out) { out << svg.str(); });
  const std::string pack_path = (dir / (std::filesystem::path(args.mesh).stem().string() + ".gip")).string();
  if (!pack.empty()) {
    files.add(pack_path, [&](std::ostream& out) {
      out.write(reinterpret_cast<const char*>(pack.data()), static_cast<std::streamsize>(pack.size()));
    });
  }
  files.commit();

  // geomip against the Draco envelopes at the sizes issues 5 and 14 name: draco_envelope (meshoptimizer's
  // decimation) always, draco_lt_envelope (Lindstrom–Turk, the stronger baseline) when it was built.
  // geomip is measured at exactly these sizes (prefix_sizes; --quick: only the rows it measured), so its
  // staircase is its prefix there (the whole pack above the pack's size); the envelopes are interpolated in
  // log(bytes) between their points, as scripts/prefix-vs-envelope and the README read them (a staircase
  // reading put Draco up to a few KB short of the size and overstated geomip's margin by up to 1.7 dB).
  std::vector<RdPoint> geomip_points, envelope_points, lt_points;
  for (const RdPoint& p : all) {
    if (p.method == "geomip") geomip_points.push_back(p);
    if (p.method == "draco_envelope") envelope_points.push_back(p);
    if (p.method == "draco_lt_envelope") lt_points.push_back(p);
  }
  const std::vector<RdPoint> geomip_front = upper_envelope(geomip_points);
  nlohmann::json comparison = nlohmann::json::array(), lt_comparison = nlohmann::json::array();
  std::string comparison_text;
  if (!geomip_front.empty() && !envelope_points.empty()) {
    comparison_text = format("%-9s %12s %16s %8s", "bytes", "geomip dB", "draco_envelope dB", "margin");
    if (!lt_points.empty()) comparison_text += format(" %19s %8s", "draco_lt_envelope dB", "margin");
    comparison_text += "\n";
    const std::vector<RdPoint> envelope_front = upper_envelope(envelope_points),
                               lt_front = upper_envelope(lt_points);
    std::set<std::size_t> geomip_sizes;  // --quick measures only a few prefixes
    for (const RdPoint& p : geomip_points) geomip_sizes.insert(p.bytes);
    for (std::size_t size : kComparisonSizes) {
      // A size geomip was not measured at (a --quick run) has no row: the staircase would show a smaller
      // prefix's PSNR there against the envelope at the size. From the pack's size on, the pack is the
      // prefix.
      if (!geomip_sizes.count(size) && size < pack.size()) continue;
      const double g = envelope_at(geomip_front, size), d = envelope_interpolated(envelope_front, size);
      comparison.push_back({{"bytes", size}, {"geomip_db", g}, {"draco_envelope_db", d}, {"margin_db", g - d}});
      comparison_text += format("%-9zu %12.2f %16.2f %+8.2f", size, g, d, g - d);
      if (!lt_points.empty()) {
        const double l = envelope_interpolated(lt_front, size);
        lt_comparison.push_back(
            {{"bytes", size}, {"geomip_db", g}, {"draco_lt_envelope_db", l}, {"margin_db", g - l}});
        comparison_text += format(" %19.2f %+8.2f", l, g - l);
      }
      comparison_text += "\n";
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (args.json) {
    nlohmann::json j;
    j["mesh"] = args.mesh;
    j["faces"] = original->num_triangles();
    j["vertices"] = original->num_vertices();
    j["csv"] = (dir / "rd.csv").string();
    j["svg"] = (dir / "rd.svg").string();
    j["seconds"] = seconds;
    if (!pack.empty()) j["pack"] = pack_path;
    j["geomip_vs_draco_envelope"] = comparison;
    if (!lt_points.empty()) j["geomip_vs_draco_lt_envelope"] = lt_comparison;
    if (searched) j["search"] = search_json(*searched, args.level);
    if (moved.chosen_patches > 0)
      j["geomip_moved_to_patches"] = {{"patches", moved.chosen_patches},
                                      {"error_weights", moved.chosen_error_weights},
                                      {"level", moved.chosen_level},
                                      {"two_squares_l2_stretch", moved.two_squares_l2_stretch}};
    if (!moved.candidates.empty()) j["geomip_layout_choice"] = relayout_json(moved);
    j["points"] = nlohmann::json::array();
    for (const RdPoint& p : all) j["points"].push_back(point_to_json(p));
    std::cout << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
    return kExitOk;
  }
  if (args.quiet) return kExitOk;
  std::cout << args.mesh << ": " << original->num_triangles() << " faces, " << original->num_vertices()
            << " vertices\n"
            << format("%-15s %7s %3s %9s %9s %8s %9s %9s\n", "method", "faces", "Q", "bytes", "KB", "PSNR dB",
                      "Haus. %", "decode ms");
  std::size_t candidates = 0;
  for (const RdPoint& p : all) {
    if (p.method == "draco_qem" || p.method == "draco_lt") {
      ++candidates;
      continue;
    }
    std::cout << point_row(p);
  }
  if (searched) {
    std::string scores;
    for (const CandidateScore& c : searched->scores)
      scores += (scores.empty() ? "" : ", ") + c.candidate.name(args.level) + format(" %.2f dB", c.mean_psnr_db);
    std::cout << "geomip pack: " << searched->chosen.name(args.level) << " (--search; mean PSNR of its "
              << searched->sizes.size() << " scored prefixes: " << scores << ")\n";
  }
  if (!moved.candidates.empty()) {
    std::string scores, not_built;
    for (const RelayoutChoice::Candidate& c : moved.candidates) {
      if (!c.not_built.empty())
        not_built += (not_built.empty() ? "" : "; ") + moved.name(c) + " not built: " + c.not_built;
      else if (std::isfinite(c.mean_psnr_db))
        scores += (scores.empty() ? "" : ", ") + moved.name(c) + format(" %.2f dB", c.mean_psnr_db);
    }
    const std::string why = scores.empty() ? not_built : "mean PSNR of the prefixes: " + scores;
    if (moved.chosen_patches > 0)
      std::cout << format(
          "geomip pack: %d patches, error weights %s, at level %d (the two squares stretch this shape: L2 "
          "stretch %.2f; %s; --patches 2 keeps the two squares)\n",
          moved.chosen_patches, error_weights_text(moved.chosen_error_weights).c_str(), moved.chosen_level,
          moved.two_squares_l2_stretch, why.c_str());
    else
      std::cout << format("geomip pack: two squares (they stretch this shape, L2 stretch %.2f, but %s)\n",
                          moved.two_squares_l2_stretch, not_built.c_str());
  }
  std::cout << "(" << candidates << " decimate-then-Draco points, the envelopes' candidates, are in rd.csv)\n"
            << comparison_text
            << "wrote " << (dir / "rd.csv").string() << " and " << (dir / "rd.svg").string()
            << format(" in %.1f s\n", seconds);
  return kExitOk;
}

}  // namespace

CommandRunner add_rd_command(CLI::App& app) {
  auto args = std::make_shared<RdArgs>();
  CLI::App* cmd = app.add_subcommand(
      "rd",
      "Rate-distortion baselines of MESH: Draco (cl 10) at Q = 6..16 on the full mesh, Draco Q = 7..13 on "
      "copies decimated to 500..40k faces by meshoptimizer (draco_qem) and, when MESH is an oriented "
      "2-manifold, by CGAL's Lindstrom-Turk edge collapse (draco_lt), their upper envelopes, meshoptimizer's "
      "codec; PSNR and "
      "Hausdorff of each decoded mesh vs MESH (as `geomip eval`), and geomip's own geometry-only pack at "
      "many prefixes. Writes DIR/rd.csv, DIR/rd.svg and the pack DIR/<stem>.gip");
  cmd->add_option("mesh", args->mesh, "Original mesh (.obj .ply .off .stl), used as it is (not repaired)")
      ->required();
  cmd->add_option("-o,--output", args->output, "Output directory (created if missing)")->required();
  cmd->add_flag("--json", args->json, "Print every point as JSON instead of the table");
  cmd->add_flag("-q,--quiet", args->quiet,
                "No progress bar and no table (rd.csv and rd.svg are still written)");
  cmd->add_flag("--quick", args->quick, "A few points only, coarser evaluation (for tests)");
  CLI::Option* lt = cmd->add_flag(
      "--lindstrom-turk", args->lindstrom_turk,
      "Require the Lindstrom-Turk baseline: an error when MESH is not an oriented 2-manifold (by default it "
      "is built whenever MESH is one: CGAL's edge collapse, series draco_lt, same faces x Q, and "
      "draco_lt_envelope over draco, draco_qem and draco_lt, the strongest baseline; otherwise a note)");
  cmd->add_flag("--no-lindstrom-turk", args->no_lindstrom_turk,
                "No Lindstrom-Turk baseline (draco_envelope is then the strongest one in the table)")
      ->excludes(lt);
  // Bounded as `geomip eval --samples`: each sample is a closest-point query and 56 bytes.
  cmd->add_option("--samples", args->samples,
                  "Face samples per surface for the evaluation, in [1, 10^8] (default: as `geomip eval`; "
                  "--quick: 20000)")
      ->check(CLI::Range(std::size_t{1}, std::size_t{100000000}));
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)");
  CLI::Option* level =
      cmd->add_option(
             "--level", args->level,
             "geomip: geometry image level of the measured pack (default as `geomip convert`: 8 for two "
             "squares, fewer for a K-patch layout)")
          ->check(CLI::Range(1, 10));
  cmd->add_flag("--no-geomip", args->no_geomip, "Only the baselines (no geomip pack)");
  cmd->add_option("--normal-mesh", args->normal_mesh_steps,
                  "geomip: normal-mesh resampling of the finest STEPS wavelet steps (as `geomip convert`; 0 = off)")
      ->check(CLI::Range(0, 10));
  CLI::Option* fit = cmd->add_flag(
      "--fit,!--no-fit", args->fit,
      "geomip: fit the pack's samples to the surface by least squares before coding (as `geomip convert "
      "--fit`; up to about twice the conversion time); --no-fit: samples on the surface. Default as `geomip "
      "convert`: fitted");
  add_patches_option(cmd, args->patches, args->patches_given, args->equal_area_layout,
                     args->layout_error_weights, args->layout_error_weights_given);
  cmd->add_flag("--tip-loop", args->tip_loop, "geomip: the two-square loop through the tips (as `geomip convert --tip-loop`)");
  cmd->add_flag("--end-loop", args->end_loop, "geomip: the two-square loop through the ends (as `geomip convert --end-loop`)");
  cmd->add_flag("--search", args->search,
                "geomip: the pack `geomip convert --search` keeps (the loops, the 8- to 64-patch layouts at "
                "about the same samples, then the best with --fit, the L-infinity pass and more framed "
                "steps; scored on 1.5-32 KB prefixes)");
  return [args, level, fit] {
    if (level->count() == 0) args->level = default_grid_level(static_cast<std::size_t>(args->patches));
    args->fit_given = fit->count() > 0;
    return run_rd(*args);
  };
}

}  // namespace geomip::tools
