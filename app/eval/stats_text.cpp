#include "eval/stats_text.hpp"

#include <fmt/format.h>

#include <utility>
#include <vector>

namespace gvio::eval {

nlohmann::json statsJson(const Stats& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"sse", s.sse},       {"n", s.n}};
}

std::string statsTable(const std::string& title, const Stats& s, std::optional<double> p95,
                       const char* count_label) {
  std::string out = title + "\n";
  std::vector<std::pair<const char*, double>> rows = {
      {"max", s.max},   {"mean", s.mean}, {"median", s.median}, {"min", s.min},
      {"rmse", s.rmse}, {"sse", s.sse},   {"std", s.std}};
  if (p95) rows.insert(rows.begin() + 4, {"p95", *p95});
  for (const auto& [name, value] : rows) out += fmt::format("{:>10}  {:.6f}\n", name, value);
  return out + fmt::format("{:>10}  {}\n", count_label, s.n);
}

}  // namespace gvio::eval
