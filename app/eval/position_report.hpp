#pragma once
// `gvio eval` against or of a GNSS track: the horizontal / vertical report (table and JSON) and
// the per-pose errors file.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/eval_inputs.hpp"
#include "eval/evaluate.hpp"

namespace gvio::eval {

// Horizontal and vertical errors in the ENU frame, overall and per quality flag of the estimate's
// epochs: the table, and the same into `json` ("enu_origin", "horizontal", "vertical",
// "by_quality"). `in.enu_origin` must be set.
std::string positionReport(const EvalResult& r, const EvalInputs& in, nlohmann::json& json);

// One line per associated pose: its time, APE and the position error est - ref per axis (in the
// reference's frame: east, north, up where a side is a GNSS track), and the estimate epoch's
// quality flag where it states one (NMEA GGA convention). Written atomically.
void writeErrorsCsv(const std::string& file, const EvalResult& r,
                    const std::vector<int>& est_quality);

}  // namespace gvio::eval
