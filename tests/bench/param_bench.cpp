// Benchmarks of the parameterization on real meshes (../shared/meshes): wall time per stage and peak memory.
// Run: build/tests/bench/param_bench  (or scripts/bench). Not part of ctest: timings are not tests.
#include "param/consistent_parameterization.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "param/partition_points.h"

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <filesystem>
#include <string>

namespace geomip {
namespace {

std::string shared(const std::string& name) { return std::string(GEOMIP_SHARED_MESHES) + "/" + name; }

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux: kilobytes
}

ParameterizationInput prepare(const std::string& name) {
  ParameterizationInput in;
  in.name = name;
  in.mesh = read_mesh(shared(name));
  const TopologyReport r = analyze_topology(in.mesh);
  if (r.boundary_loops > 0 || !r.manifold) in.mesh = repair_mesh(in.mesh).mesh;
  const PartitionPoints p = choose_partition_points(in.mesh);
  in.partition_points = p.partition_points;
  in.auxiliary_points = p.auxiliary_points;
  return in;
}

// One model, automatic partition points (chosen outside the timed region), MVC baseline off (it is a
// measurement aid, not part of the pipeline).
void BM_Parameterize(benchmark::State& state, const std::string& name) {
  if (!std::filesystem::exists(shared(name))) {
    state.SkipWithError(("missing " + shared(name)).c_str());
    return;
  }
  const ParameterizationInput in = prepare(name);
  ParameterizationOptions options;
  options.measure_mvc_baseline = false;
  StageSeconds stages;
  for (auto _ : state) {
    const auto result = parameterize_consistently({in}, options);
    stages = result[0].seconds;
    benchmark::DoNotOptimize(result);
  }
  state.counters["faces"] = static_cast<double>(in.mesh.triangles.size());
  state.counters["partition_s"] = stages.partition;
  state.counters["pm_s"] = stages.progressive_mesh;
  state.counters["base_s"] = stages.base_embedding;
  state.counters["c2f_s"] = stages.coarse_to_fine;
  state.counters["final_s"] = stages.final_optimization;
  state.counters["peak_rss_MB"] = peak_rss_mb();
}

BENCHMARK_CAPTURE(BM_Parameterize, bunny_repaired, std::string("bunny.obj"))->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Parameterize, horse, std::string("horse.obj"))->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_Parameterize, pig, std::string("pig.obj"))->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_Parameterize, venus, std::string("venus.obj"))->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace geomip

BENCHMARK_MAIN();
