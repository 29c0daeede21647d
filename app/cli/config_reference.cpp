#include "cli/config_reference.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <map>
#include <string_view>

#include "cli/config.hpp"
#include "cli/yaml_comments.hpp"
#include "odometry/error.hpp"

namespace gvio::cli {
namespace {

// Every check the program applies to a configuration: AppConfig's whenever one is loaded, the
// fleet's and the merge's sections when gvio fleet and gvio merge start (AppConfig::validate
// leaves those to them).
void validateEverything(const AppConfig& config) {
  config.validate();
  config.fleet.validate();
  config.merge.validate();
}

// Values outside a typical rule of every kind of key: beyond any range (numbers, integers,
// vectors), negative, zero, empty, not a name any rule accepts (text, one-word Slurm names). A key
// whose parser refuses one (the wrong type) simply is not probed with it.
constexpr std::array<std::string_view, 11> kOutOfRange = {
    "1e300", "-1e300", "1000000000",        "-1000000000",          "0",
    "-1",    "0.5",    "1e300,1e300,1e300", "-1e300,-1e300,-1e300", "__invalid__",
    ""};

// Values of the wrong type for some parser, most telling first: "-1" is refused by the parsers
// that take "auto" or a name (their message lists what they take), "0.5" by the integer one,
// "__invalid__" by every numeric one.
constexpr std::array<std::string_view, 3> kWrongType = {"-1", "0.5", "__invalid__"};

std::string textAfter(const std::string& text, std::string_view marker) {
  const auto at = text.find(marker);
  return at == std::string::npos ? std::string() : text.substr(at + marker.size());
}

// The rule a validation message states about `key`, or "" when it is about another key (a rule
// over several keys that the other key's check reports). The libraries name their fields from
// their own section ("config: tracker.max_features must ..."), the tail of the dotted key.
// "config: sim.knot_spacing_s must be in [0.05, 5] (got 1e+300)" -> "in [0.05, 5]".
std::string ruleAbout(const std::string& key, const std::string& message) {
  const std::string subject_and_rule = textAfter(message, "config: ");
  const std::string subject = subject_and_rule.substr(0, subject_and_rule.find(' '));
  if (subject.empty() || (subject != key && !key.ends_with("." + subject))) return "";
  std::string rule = textAfter(subject_and_rule, " must be ");
  if (rule.empty()) rule = textAfter(subject_and_rule, " must ");
  for (const std::string_view tail : {" (got", ", got"}) rule = rule.substr(0, rule.find(tail));
  return rule;
}

// The key set to `value` on a fresh default configuration (no probe sees another's value): the
// validation message it leads to, "" when the value is accepted or refused by the key's parser.
std::string validationMessage(std::string_view name, std::string_view value) {
  AppConfig config;
  for (ConfigKey& key : configKeys(config)) {
    if (key.name != name) continue;
    try {
      key.set(value);
    } catch (const InvalidInput&) {
      return "";  // the wrong type for this key
    }
  }
  try {
    validateEverything(config);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

// What the key's parser takes, from its refusal of a value of the wrong type ("bad value '-1' for
// vio.max_iterations: expected auto or an integer >= 1"); "" for a parser that takes anything.
std::string parserExpectation(const std::string& name) {
  AppConfig config;
  for (ConfigKey& key : configKeys(config)) {
    if (key.name != name) continue;
    for (const std::string_view value : kWrongType) {
      try {
        key.set(value);
      } catch (const InvalidInput& e) {
        return textAfter(e.what(), ": expected ");
      }
    }
  }
  return "";
}

// The key's rules, each once, in the order the probes found them.
std::vector<std::string> validationRules(const std::string& name) {
  std::vector<std::string> rules;
  for (const std::string_view value : kOutOfRange) {
    const std::string rule = ruleAbout(name, validationMessage(name, value));
    if (!rule.empty() && std::find(rules.begin(), rules.end(), rule) == rules.end()) {
      rules.push_back(rule);
    }
  }
  return rules;
}

// The key's rules after its type; a plain number's type goes without saying next to a range.
void describeAllowed(KeyReference& key) {
  const std::vector<std::string> rules = validationRules(key.name);
  std::string type = parserExpectation(key.name);
  key.allowed_by_validation = !rules.empty();
  if (!rules.empty() && type == "a finite number") type.clear();
  key.allowed.clear();
  for (const std::string& rule : rules) key.allowed += (key.allowed.empty() ? "" : "; ") + rule;
  if (!type.empty()) key.allowed = key.allowed.empty() ? type : type + "; " + key.allowed;
  if (key.allowed.empty()) key.allowed = "any";
}

// Inside a code span only "|" needs an escape, so that it does not end the table cell.
std::string escapePipes(std::string_view code) {
  std::string out;
  for (const char c : code) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

// Text outside code spans: Markdown's inline markup characters taken literally, "|" escaped so
// that it does not end the cell. "<" as an entity: Python-Markdown (MkDocs) has no "\<" escape.
std::string escapeText(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '<') {
      out += "&lt;";
      continue;
    }
    if (c == '\\' || c == '`' || c == '*' || c == '_' || c == '|') out += '\\';
    out += c;
  }
  return out;
}

// A table cell's text. default.yaml's comments quote commands in backticks (`gvio run`): those
// stay code spans; an unpaired backtick is literal.
std::string escapeCell(std::string_view text) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const auto open = text.find('`', at);
    const auto close = open == std::string_view::npos ? open : text.find('`', open + 1);
    if (close == std::string_view::npos) {
      out += escapeText(text.substr(at));
      break;
    }
    out += escapeText(text.substr(at, open - at));
    out += escapePipes(text.substr(open, close + 1 - open));
    at = close + 1;
  }
  return out;
}

// A value as code; the empty text as "" (an empty code span would not show).
std::string codeCell(const std::string& value) {
  return value.empty() ? "`\"\"`" : "`" + escapePipes(value) + "`";
}

std::string sectionOf(const std::string& key) {
  return key.substr(0, key.find('.'));
}

constexpr std::string_view kIntro =
    "# Configuration reference\n"
    "\n"
    "Generated from the program by `tests/unit/docs_reference_test.cpp`, which fails when this "
    "page differs from what the program produces; regenerate it with\n"
    "`GVIO_UPDATE_DOCS=1 build/tests/gvio_unit_tests --gtest_filter='DocsReference*'`, do not "
    "edit it.\n"
    "\n"
    "Every key can be set in a YAML file given with `--config FILE` (nested sections or dotted "
    "keys, as in `assets/config/default.yaml`) or on the command line with `--set key=value`. "
    "**default**: the value without either. **allowed values**: what the key's parser takes and "
    "what validation asks of it (a value outside is refused, exit 2; `fleet.*` and `merge.*` are "
    "checked when `gvio fleet` and `gvio merge` start); \"any\": nothing is refused. "
    "**description**: the key's comment in `assets/config/default.yaml`.\n";

}  // namespace

std::vector<KeyReference> configReference(const std::string& default_yaml) {
  const std::map<std::string, std::string> comments = yamlKeyComments(default_yaml);
  AppConfig defaults;
  std::vector<KeyReference> out;
  for (const ConfigKey& key : configKeys(defaults)) {
    KeyReference ref;
    ref.name = key.name;
    ref.default_value = key.get();
    describeAllowed(ref);
    if (const auto it = comments.find(key.name); it != comments.end()) ref.description = it->second;
    out.push_back(std::move(ref));
  }
  return out;
}

std::string configReferenceMarkdown(const std::string& default_yaml) {
  const std::map<std::string, std::string> comments = yamlKeyComments(default_yaml);
  std::string page(kIntro);
  std::string section;
  for (const KeyReference& key : configReference(default_yaml)) {
    if (sectionOf(key.name) != section) {
      section = sectionOf(key.name);
      page += "\n## " + section + "\n\n";
      if (const auto it = comments.find(section); it != comments.end()) {
        page += escapeCell(it->second) + "\n\n";
      }
      page += "| key | default | allowed values | description |\n| --- | --- | --- | --- |\n";
    }
    page += fmt::format("| {} | {} | {} | {} |\n", codeCell(key.name), codeCell(key.default_value),
                        escapeCell(key.allowed), escapeCell(key.description));
  }
  return page;
}

}  // namespace gvio::cli
