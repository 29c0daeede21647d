// The fuzz targets (tests/fuzz) in the normal suite: each target's prepared input is accepted,
// and every committed corpus input and every input a fuzzer once broke the readers with is now
// either read or refused with one line naming the file, never a bug (harness.hpp Verdict).
#include <gtest/gtest.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>

#include "fuzz/harness.hpp"
#include "support/fixtures.hpp"

namespace gvio::fuzz {

// Verdicts print by name in failures.
void PrintTo(Verdict verdict, std::ostream* os) {
  *os << toString(verdict);
}

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputsIn(const fs::path& dir) {
  std::vector<fs::path> files;
  if (!fs::is_directory(dir)) return files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

class FuzzTarget : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override { spdlog::set_level(spdlog::level::err); }
  void TearDown() override { spdlog::set_level(spdlog::level::info); }
  [[nodiscard]] const Target& target() const { return *findTarget(GetParam()); }
};

TEST_P(FuzzTarget, PreparedInputIsAccepted) {
  const Outcome o = runInput(target(), seedOf(target()));
  EXPECT_EQ(o.verdict, Verdict::kAccepted) << o.message;
}

TEST_P(FuzzTarget, CommittedInputsAreReadOrRefusedWithTheFileNamed) {
  const auto corpus = inputsIn(fs::path(GVIO_FUZZ_CORPUS_DIR) / GetParam());
  EXPECT_FALSE(corpus.empty()) << "no seed in tests/fuzz/corpus/" << GetParam()
                               << " (build/tests/fuzz/gvio_fuzz_seeds tests/fuzz/corpus)";
  auto inputs = inputsIn(fs::path(GVIO_FUZZ_REGRESSIONS_DIR) / GetParam());
  inputs.insert(inputs.end(), corpus.begin(), corpus.end());
  for (const fs::path& file : inputs) {
    const Outcome o = runInput(target(), test::readText(file));
    EXPECT_NE(o.verdict, Verdict::kBug) << file << ": " << o.message;
  }
}

std::vector<std::string> targetNames() {
  std::vector<std::string> names;
  for (const Target& t : targets()) names.push_back(t.name);
  return names;
}

INSTANTIATE_TEST_SUITE_P(Readers, FuzzTarget, ::testing::ValuesIn(targetNames()),
                         [](const auto& test_info) { return test_info.param; });

// The refusal of an empty file is the same one line naming it for every reader.
TEST(FuzzHarness, EmptyInputIsRefusedOrReadNeverABug) {
  spdlog::set_level(spdlog::level::err);
  for (const Target& t : targets()) {
    const Outcome o = runInput(t, "");
    EXPECT_NE(o.verdict, Verdict::kBug) << t.name << ": " << o.message;
  }
  spdlog::set_level(spdlog::level::info);
}

}  // namespace
}  // namespace gvio::fuzz
