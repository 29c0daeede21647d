// gvio eval on a 100k-pose pair: association by time, SE(3) Umeyama alignment, APE and RPE.
// Target (issue: gvio eval): < 1 s for APE se3 + RPE. And the revisit consistency of an hour at
// 100 Hz (360k poses), which must not be quadratic.
#include <benchmark/benchmark.h>

#include <random>

#include "eval/evaluate.hpp"
#include "eval/revisits.hpp"

namespace gvio::eval {
namespace {

std::pair<Trajectory, Trajectory> makePair(std::size_t n) {
  Trajectory ref, est;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.05);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < n; ++i) {
    const double s = 0.01 * static_cast<double>(i);
    T.linear() = Eigen::AngleAxisd(0.05 * s, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() =
        Eigen::Vector3d(200 * std::cos(0.01 * s), 150 * std::sin(0.013 * s), std::sin(s));
    ref.poses.push_back(T);
    ref.t_ns.push_back(static_cast<std::int64_t>(i) * 10'000'000);
    Eigen::Isometry3d P = T;
    P.translation() += Eigen::Vector3d{noise(rng), noise(rng), noise(rng)};
    est.poses.push_back(P);
    est.t_ns.push_back(static_cast<std::int64_t>(i) * 10'000'000 + 1'000'000);  // 1 ms offset
  }
  return {ref, est};
}

void BM_EvalApeSe3AndRpe(benchmark::State& state) {
  const auto [ref, est] = makePair(static_cast<std::size_t>(state.range(0)));
  EvalOptions opt;
  opt.align = Alignment::kSe3;
  opt.rpe_delta = 10;
  for (auto _ : state) {
    const EvalResult r = evaluate(ref, est, opt);
    benchmark::DoNotOptimize(r.ape_stats.rmse);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_EvalApeSe3AndRpe)->Arg(100'000)->Unit(benchmark::kMillisecond);

// makePair's reference is a Lissajous curve at about 2 m/s crossing itself many times; within
// 0.5 m of a crossing two passes make up to 50 x 50 pose pairs, so the pairs (and the cost, which
// grows with them) come to millions: the cost of a place seen many times, not of the search.
void BM_EvalRevisits(benchmark::State& state) {
  const auto [ref, est] = makePair(static_cast<std::size_t>(state.range(0)));
  std::vector<Eigen::Matrix4d> ref_poses, est_poses;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    ref_poses.push_back(ref.poses[i].matrix());
    est_poses.push_back(est.poses[i].matrix());
  }
  std::size_t pairs = 0;
  for (auto _ : state) {
    const RevisitResult r = computeRevisits(ref_poses, est_poses, ref.t_ns, {0.5, 30'000'000'000});
    pairs = r.pairs.size();
    benchmark::DoNotOptimize(r.stats);
  }
  state.counters["pairs"] = static_cast<double>(pairs);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_EvalRevisits)->Arg(360'000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gvio::eval
