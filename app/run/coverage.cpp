#include "run/coverage.hpp"

#include <fmt/format.h>

namespace gvio::run {
namespace {

double spanS(const std::vector<std::int64_t>& t_ns) {
  return t_ns.size() < 2 ? 0.0 : static_cast<double>(t_ns.back() - t_ns.front()) * 1e-9;
}

}  // namespace

Coverage coverageOf(const std::vector<std::int64_t>& input_t_ns,
                    const std::vector<std::int64_t>& output_t_ns) {
  return {spanS(input_t_ns), spanS(output_t_ns)};
}

std::string runStatus(const Coverage& c) {
  return c.partial() ? "partial" : "complete";
}

nlohmann::json coverageJson(const Coverage& c) {
  return {{"input_s", c.input_s},
          {"output_s", c.output_s},
          {"fraction", c.fraction()},
          {"partial_below", kCompleteCoverage},
          {"allowed_missing_s", kAllowedMissingS}};
}

std::string partialNote(const Coverage& c) {
  if (!c.partial()) return "";
  return fmt::format(", partial: the trajectory covers {:.1f} s of the input's {:.1f} s ({:.1f} %)",
                     c.output_s, c.input_s, 100.0 * c.fraction());
}

}  // namespace gvio::run
