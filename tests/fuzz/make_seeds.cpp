// Writes each fuzz target's seed (its prepared, valid file) as CORPUS/<target>/seed: how the
// committed corpus in tests/fuzz/corpus was made. Inputs the fuzzers found are added beside it.
//   build/tests/gvio_fuzz_seeds tests/fuzz/corpus
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>

#include "fuzz/harness.hpp"
#include "support/fixtures.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: gvio_fuzz_seeds CORPUS_DIR\n");
    return 2;
  }
  spdlog::set_level(spdlog::level::off);
  const std::filesystem::path corpus(argv[1]);
  for (const auto& target : gvio::fuzz::targets()) {
    const std::filesystem::path dir = corpus / target.name;
    const std::string seed = gvio::fuzz::seedOf(target);
    gvio::test::writeText(dir / "seed", seed);
    std::printf("%-24s %6zu bytes\n", target.name.c_str(), seed.size());
  }
  return 0;
}
