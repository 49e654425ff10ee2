// Benchmarks of geometry-image resampling and uniform remeshing on the repaired bunny (../shared/meshes), the
// parameterization excluded (computed once, outside the timed loops). Issue 4's goal: resampling + remeshing
// to M8 in ≤ 0.2 s (the paper: 2.15 s). Run: build/tests/bench/gimage_bench. Not part of ctest.
#include "gimage/exr_io.h"
#include "gimage/resample.h"
#include "gimage/uniform_remesh.h"
#include "param/consistent_parameterization.h"
#include "mesh/mesh_io.h"
#include "mesh/mesh_repair.h"
#include "mesh/mesh_topology.h"
#include "param/partition_points.h"

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

namespace geomip {
namespace {

std::string shared(const std::string& name) {
  return std::string(GEOMIP_SHARED_MESHES) + "/" + name;
}

// The repaired bunny's parameterization (automatic points, MVC baseline off), computed once.
const ModelParameterization* bunny() {
  static std::unique_ptr<ModelParameterization> model;
  if (model) return model.get();
  if (!std::filesystem::exists(shared("bunny.obj"))) return nullptr;
  ParameterizationInput in;
  in.name = "bunny";
  in.mesh = read_mesh(shared("bunny.obj"));
  const TopologyReport r = analyze_topology(in.mesh);
  if (r.boundary_loops > 0 || !r.manifold) in.mesh = repair_mesh(in.mesh).mesh;
  const PartitionPoints p = choose_partition_points(in.mesh);
  in.partition_points = p.partition_points;
  in.auxiliary_points = p.auxiliary_points;
  ParameterizationOptions options;
  options.measure_mvc_baseline = false;
  model = std::make_unique<ModelParameterization>(parameterize_consistently({in}, options)[0]);
  return model.get();
}

// Geometry images at level K (no normals) and the uniform M_K remesh: the figure of issue 4.
void BM_ResampleAndRemesh(benchmark::State& state) {
  const ModelParameterization* model = bunny();
  if (!model) {
    state.SkipWithError("missing ../shared/meshes/bunny.obj");
    return;
  }
  const int level = static_cast<int>(state.range(0));
  ResampleOptions options;
  options.normals = false;
  std::size_t faces = 0;
  for (auto _ : state) {
    const GeometryImages images = resample_geometry(*model, level, options);
    const UniformRemeshResult remesh = uniform_remesh(images, level);
    faces = remesh.mesh.triangles.size();
    benchmark::DoNotOptimize(remesh.mesh.positions.data());
  }
  state.counters["faces"] = static_cast<double>(faces);
  state.counters["input_faces"] = static_cast<double>(model->mesh.triangles.size());
}

// Geometry images at level K plus normal maps at K+1 (what `geomip gimage` computes).
void BM_ResampleWithNormals(benchmark::State& state) {
  const ModelParameterization* model = bunny();
  if (!model) {
    state.SkipWithError("missing ../shared/meshes/bunny.obj");
    return;
  }
  const int level = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const GeometryImages images = resample_geometry(*model, level);
    benchmark::DoNotOptimize(images.normals.data());
  }
}

// Writing <stem>.geometry.exr (float) and <stem>.normals.exr (half) at level K; file sizes as counters.
void BM_WriteExr(benchmark::State& state) {
  const ModelParameterization* model = bunny();
  if (!model) {
    state.SkipWithError("missing ../shared/meshes/bunny.obj");
    return;
  }
  const int level = static_cast<int>(state.range(0));
  const GeometryImages images = resample_geometry(*model, level);
  const std::string stem =
      (std::filesystem::temp_directory_path() / ("gimage_bench_" + std::to_string(::getpid()))).string();
  GeometryImageFileInfo info;
  info.source_mesh = "bunny.obj";
  info.adjacency = images.adjacency;
  for (auto _ : state) {
    info.kind = "geometry";
    write_geometry_image_exr(stem + ".geometry.exr", images.geometry, info);
    info.kind = "normals";
    write_geometry_image_exr(stem + ".normals.exr", images.normals, info, {true, 64});
  }
  state.counters["geometry_KiB"] = std::filesystem::file_size(stem + ".geometry.exr") / 1024.0;
  state.counters["normals_KiB"] = std::filesystem::file_size(stem + ".normals.exr") / 1024.0;
  std::filesystem::remove(stem + ".geometry.exr");
  std::filesystem::remove(stem + ".normals.exr");
}

BENCHMARK(BM_ResampleAndRemesh)->Arg(6)->Arg(8)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ResampleWithNormals)->Arg(8)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteExr)->Arg(8)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace geomip

BENCHMARK_MAIN();
