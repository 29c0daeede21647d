#include "run/evaluation.hpp"

#include "eval/evaluate.hpp"
#include "odometry/error.hpp"

namespace gvio::run {

EvaluationOutcome evaluateAgainstTruth(const Trajectory& truth, const Trajectory& estimate) {
  EvaluationOutcome out;
  if (estimate.empty()) {  // evaluate() would pair by index and complain about timestamps
    out.error = "the estimate has no poses (the estimator never initialised)";
    return out;
  }
  eval::EvalOptions options;
  options.align = eval::Alignment::kSe3;
  options.relation = eval::Relation::kTranslation;
  eval::EvalResult ape;
  try {
    ape = eval::evaluate(truth, estimate, options);
  } catch (const InvalidInput& e) {
    // A run that cannot be evaluated (a straight drive aligns degenerately) is still a good run.
    out.error = e.what();
    return out;
  }
  RunEvaluation r;
  r.ape_se3 = ape.ape_stats;
  Trajectory associated;
  for (const auto& T : ape.ref) associated.poses.emplace_back(T);
  r.path_length_m = pathLengthM(associated);
  options.rpe_delta = kRpeSegmentM;
  options.rpe_unit = eval::DeltaUnit::kMeters;
  try {
    const eval::EvalResult rpe = eval::evaluate(truth, estimate, options);
    if (rpe.rpe) r.rpe_100m_percent = rpe.rpe->stats.mean / kRpeSegmentM * 100.0;
  } catch (const InvalidInput&) {
    // Shorter than two 100 m segments: no RPE figure.
  }
  out.result = r;
  return out;
}

UnalignedOutcome evaluateUnaligned(const Trajectory& truth, const Trajectory& estimate) {
  UnalignedOutcome out;
  eval::EvalOptions options;
  options.align = eval::Alignment::kNone;
  try {
    out.ape = eval::evaluate(truth, estimate, options).ape_stats;
  } catch (const InvalidInput& e) {
    out.error = e.what();
  }
  return out;
}

}  // namespace gvio::run
