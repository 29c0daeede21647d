// The libFuzzer entry point: one executable for every target, picked by the environment variable
// GVIO_FUZZ_TARGET (one link instead of one per target). A refusal of bad input is the expected
// outcome; anything harness.hpp calls a bug aborts, so libFuzzer keeps the input as a crash.
//
//   GVIO_FUZZ_TARGET=nmea build-san/tests/fuzz/gvio_fuzz -max_total_time=60 CORPUS_DIR...
//   GVIO_FUZZ_TARGET=nmea build-san/tests/fuzz/gvio_fuzz crash-FILE   (replays one input)
#include <spdlog/spdlog.h>

#include <opencv2/core/utils/logger.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "fuzz/harness.hpp"

namespace {

const gvio::fuzz::Target* chosen = nullptr;  // set once by LLVMFuzzerInitialize

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  const char* name = std::getenv("GVIO_FUZZ_TARGET");
  chosen = name ? gvio::fuzz::findTarget(name) : nullptr;
  if (!chosen) {
    std::fprintf(stderr, "gvio_fuzz: set GVIO_FUZZ_TARGET to one of:");
    for (const auto& t : gvio::fuzz::targets()) std::fprintf(stderr, " %s", t.name.c_str());
    std::fprintf(stderr, "\n");
    std::exit(2);
  }
  spdlog::set_level(spdlog::level::off);  // readers warn about every oddity they skip
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);  // and so do decoders
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const gvio::fuzz::Outcome outcome =
      gvio::fuzz::runInput(*chosen, std::string_view(reinterpret_cast<const char*>(data), size));
  if (outcome.verdict == gvio::fuzz::Verdict::kBug) {
    std::fprintf(stderr, "gvio_fuzz %s: %s\n", chosen->name.c_str(), outcome.message.c_str());
    std::abort();
  }
  return 0;
}
