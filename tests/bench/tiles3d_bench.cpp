// The level-of-detail octree and 3D Tiles (issue 62 target: writing the viewer's octree costs at
// most 0.2 s per million points). A 2 km street of 2 M points (uniform along the road, 30 m
// across, 12 m up), default PointLodConfig: buildPointLod alone, and writeTiles3d whole (the tree,
// ECEF conversion, every .pnts and tileset.json written atomically to a temporary folder).
// items_per_second is points per second.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "export/tiles3d_writer.hpp"
#include "mapping/point_lod.hpp"

namespace gvio {
namespace {

const std::vector<exporter::TilesPoint>& street() {
  static const std::vector<exporter::TilesPoint> points = [] {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> along(0.0, 2000.0), across(-15, 15), up(-1, 11);
    std::vector<exporter::TilesPoint> p(2'000'000);
    for (auto& x : p) {
      x.p_enu = {along(rng), across(rng), up(rng)};
      x.intensity = static_cast<std::uint16_t>(rng());
    }
    return p;
  }();
  return points;
}

void BM_PointLodBuild(benchmark::State& state) {
  std::vector<Eigen::Vector3d> p;
  for (const auto& x : street()) p.push_back(x.p_enu);
  for (auto _ : state) {
    benchmark::DoNotOptimize(mapping::buildPointLod(p, {}));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(p.size()));
}
BENCHMARK(BM_PointLodBuild)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Tiles3dWrite(benchmark::State& state) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("gvio_tiles3d_bench_" + std::to_string(::getpid()));
  for (auto _ : state) {
    exporter::writeTiles3d(dir, {35.15, 136.97, 48.0}, street());
  }
  std::filesystem::remove_all(dir);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(street().size()));
}
BENCHMARK(BM_Tiles3dWrite)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace gvio
