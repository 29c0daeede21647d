// The reference pages of the docs site generated from the program, never copied by hand:
// docs/reference/cli.md (every subcommand's --help) and docs/reference/config.md (the config
// schema, cli/config_reference.hpp). Each test fails when the committed page differs from what
// the program produces; GVIO_UPDATE_DOCS=1 rewrites the pages instead.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli/app.hpp"
#include "cli/config_reference.hpp"
#include "cli/yaml_comments.hpp"
#include "support/fixtures.hpp"

namespace gvio {
namespace {
namespace fs = std::filesystem;

const fs::path kReferenceDir = fs::path(GVIO_SOURCE_DIR) / "docs" / "reference";
constexpr const char* kRegenerate =
    "GVIO_UPDATE_DOCS=1 build/tests/gvio_unit_tests --gtest_filter='DocsReference*'";

bool updating() {
  const char* update = std::getenv("GVIO_UPDATE_DOCS");
  return update != nullptr && std::string(update) == "1";
}

// Where two texts first differ, as "line N: committed '...', program '...'".
std::string firstDifference(const std::string& committed, const std::string& program) {
  std::istringstream a(committed), b(program);
  std::string line_a, line_b;
  for (int n = 1;; ++n) {
    const bool more_a = static_cast<bool>(std::getline(a, line_a));
    const bool more_b = static_cast<bool>(std::getline(b, line_b));
    if (!more_a && !more_b) return "line endings";
    if (!more_a || !more_b || line_a != line_b) {
      return "line " + std::to_string(n) + ": committed '" + (more_a ? line_a : "<end>") +
             "', program '" + (more_b ? line_b : "<end>") + "'";
    }
  }
}

// The committed page must be the program's; with GVIO_UPDATE_DOCS=1 it is made so.
void checkPage(const fs::path& page, const std::string& program) {
  if (updating()) {
    fs::create_directories(page.parent_path());
    std::ofstream(page, std::ios::binary) << program;
    ASSERT_EQ(test::readText(page), program) << "could not write " << page;
    return;
  }
  if (!fs::exists(page)) FAIL() << page << " is missing; generate it with " << kRegenerate;
  const std::string committed = test::readText(page);
  EXPECT_TRUE(committed == program)
      << page << " differs from what the program produces (" << firstDifference(committed, program)
      << "); regenerate it with " << kRegenerate;
}

// The subcommands `gvio --help` lists, in its order, taken from the program's command line itself
// so that a new one cannot be missed. Hidden ones (fleet-task: typed only by fleet job scripts)
// are left out, as the help leaves them out.
std::vector<std::string> listedSubcommands() {
  cli::CommonOptions common;
  const cli::Cli built = cli::buildCli(common);
  const CLI::App& app = *built.app;
  std::vector<std::string> names;
  for (const CLI::App* sub :
       app.get_subcommands([](const CLI::App* s) { return !s->get_group().empty(); })) {
    names.push_back(sub->get_name());
  }
  return names;
}

// One command's help as the executable prints it, in a section of the page. CLI11 lays the help
// out in fixed columns (no terminal-width detection), so the text is the same on every machine.
std::string helpSection(const std::string& subcommand) {
  const std::string command = subcommand.empty() ? "gvio" : "gvio " + subcommand;
  const test::CommandResult r = test::runGvio(subcommand + " --help");
  EXPECT_EQ(r.exit_code, 0) << command << " --help: " << r.err;
  EXPECT_EQ(r.err, "") << command << " --help";
  std::string text = r.out;
  if (!text.empty() && text.back() != '\n') text += '\n';
  return "\n## " + command + "\n\n```text\n" + text + "```\n";
}

std::string cliReferenceMarkdown() {
  std::string page =
      "# Command-line reference\n"
      "\n"
      "Generated from the program's own `--help` output by `tests/unit/docs_reference_test.cpp`, "
      "which fails when this page differs from it; regenerate it with\n"
      "`" +
      std::string(kRegenerate) + "`, do not edit it.\n";
  page += helpSection("");
  for (const std::string& sub : listedSubcommands()) page += helpSection(sub);
  return page;
}

TEST(DocsReference, CliPageIsTheProgramsHelp) {
  const std::vector<std::string> subcommands = listedSubcommands();
  ASSERT_FALSE(subcommands.empty());
  checkPage(kReferenceDir / "cli.md", cliReferenceMarkdown());
  std::cout << "cli.md: gvio and " << subcommands.size() << " subcommands\n";
}

TEST(DocsReference, ConfigPageIsTheConfigSchema) {
  const std::string yaml =
      test::readText(fs::path(GVIO_SOURCE_DIR) / "assets" / "config" / "default.yaml");
  ASSERT_FALSE(yaml.empty());
  checkPage(kReferenceDir / "config.md", cli::configReferenceMarkdown(yaml));

  // Not failures: how much of the page the program could fill in.
  std::size_t by_validation = 0, any = 0;
  std::string undocumented;
  const std::vector<cli::KeyReference> keys = cli::configReference(yaml);
  for (const cli::KeyReference& key : keys) {
    by_validation += key.allowed_by_validation ? 1 : 0;
    any += key.allowed == "any" ? 1 : 0;
    if (key.description.empty()) undocumented += " " + key.name;
  }
  std::cout << "config.md: " << keys.size() << " keys, allowed values from validation for "
            << by_validation << ", from the parser alone for " << keys.size() - by_validation - any
            << ", any for " << any << "; without a comment in default.yaml:"
            << (undocumented.empty() ? " none" : undocumented) << "\n";
}

// The scanner behind the descriptions, on the layouts default.yaml uses.
TEST(DocsReference, YamlCommentsFollowTheFileLayout) {
  const std::string yaml =
      "# file header, not a key's\n"
      "\n"
      "# the section\n"
      "vio:\n"
      "  # above the key,\n"
      "  #   on two lines\n"
      "  mode: auto\n"
      "  window: 10     # trailing,   wrapped\n"
      "                 #   onto the next line\n"
      "  # above a dotted key\n"
      "  tracker.grid: 8\n"
      "  bare: 1\n"
      "  # cut off by a blank line\n"
      "\n"
      "  topic: \"#not a comment\"  # the topic\n"
      "sim:\n"
      "  rate: 10\n";
  const std::map<std::string, std::string> expected = {
      {"vio", "the section"},
      {"vio.mode", "above the key, on two lines"},
      {"vio.window", "trailing, wrapped onto the next line"},
      {"vio.tracker.grid", "above a dotted key"},
      {"vio.bare", "above a dotted key"},  // the group the comment above begins
      {"vio.topic", "the topic"}};
  EXPECT_EQ(cli::yamlKeyComments(yaml), expected);
}

// The probes find a key's range, its parser's type, or nothing, and each key's own default.
TEST(DocsReference, ConfigProbesFindWhatIsRefused) {
  std::map<std::string, cli::KeyReference> keys;
  for (cli::KeyReference& key : cli::configReference("")) keys[key.name] = std::move(key);
  EXPECT_EQ(keys.at("sim.knot_spacing_s").allowed, "in [0.05, 5]");
  EXPECT_EQ(keys.at("sim.knot_spacing_s").default_value, "0.25");
  EXPECT_TRUE(keys.at("sim.knot_spacing_s").allowed_by_validation);
  EXPECT_EQ(keys.at("vio.tracker.klt_levels").allowed, "an integer; in [0, 8]");
  EXPECT_EQ(keys.at("imu.prefer_dataset_noise").allowed, "true or false");
  EXPECT_FALSE(keys.at("imu.prefer_dataset_noise").allowed_by_validation);
  EXPECT_EQ(keys.at("dataset.topics.cam0").allowed, "any");
  EXPECT_EQ(keys.at("dataset.topics.cam0").default_value, "");
  EXPECT_EQ(keys.at("fleet.retries").allowed, "an integer; 0..10");  // checked by gvio fleet
}

}  // namespace
}  // namespace gvio
