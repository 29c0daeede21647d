// gvio simulate --world-seed (issue 18's fleets): drives of one route with one world seed and
// different --seed see the same streets with their own noise; without it the world follows --seed.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

TEST(CliSimulateWorldSeed, OneWorldSeedGivesOneWorldWhateverTheNoiseSeed) {
  const TempDir dir("cli_simulate_world_seed");
  const auto simulate = [&](const std::string& name, const std::string& seeds) {
    const CommandResult r = runGvio(
        fmt::format("-q simulate --trajectory {}/assets/demo/drive.tum --seconds 1 {} --out {}",
                    GVIO_SOURCE_DIR, seeds, quoted(dir.path() / name)));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return dir.path() / name;
  };
  const fs::path a = simulate("a", "--seed 1 --world-seed 7");
  const fs::path b = simulate("b", "--seed 2 --world-seed 7");
  const fs::path c = simulate("c", "--seed 2");
  EXPECT_EQ(readText(a / "world/world.ply"), readText(b / "world/world.ply"));
  EXPECT_NE(readText(b / "world/world.ply"), readText(c / "world/world.ply"));
  EXPECT_NE(readText(a / "gnss/fixes.nmea"), readText(b / "gnss/fixes.nmea"));  // own noise
  EXPECT_NE(readText(a / "sim.yaml").find("world_seed: 7"), std::string::npos);
  EXPECT_NE(readText(c / "sim.yaml").find("world_seed: 2"), std::string::npos);
}

// Seeds are unsigned: "-1" is refused in one line, not wrapped into 2^64 - 1 and run.
TEST(CliSimulateWorldSeed, NegativeSeedsAreRefused) {
  const TempDir dir("cli_simulate_negative_seed");
  for (const char* seed : {"--seed", "--world-seed"}) {
    const CommandResult r = runGvio(
        fmt::format("-q simulate --trajectory {}/assets/demo/drive.tum --seconds 1 {} -1 --out {}",
                    GVIO_SOURCE_DIR, seed, quoted(dir.path() / "s")));
    EXPECT_EQ(r.exit_code, 2) << seed;
    EXPECT_NE(r.err.find(seed), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("not a whole number"), std::string::npos) << r.err;
  }
  const CommandResult r =
      runGvio(fmt::format("-q run --dataset {} --gnss-noise spp --seed -1", quoted(dir.path())));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--seed"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gvio::test
