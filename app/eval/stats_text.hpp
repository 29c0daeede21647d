#pragma once
// evo's statistics as `gvio eval` prints and writes them: the table rows in evo's order and the
// JSON object of the same keys.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "eval/metrics.hpp"

namespace gvio::eval {

[[nodiscard]] nlohmann::json statsJson(const Stats& s);

// evo's rows in evo's (alphabetical) order; p95 where given; the count as `count_label`.
[[nodiscard]] std::string statsTable(const std::string& title, const Stats& s,
                                     std::optional<double> p95 = std::nullopt,
                                     const char* count_label = "n");

}  // namespace gvio::eval
