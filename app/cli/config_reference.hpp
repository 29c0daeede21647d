#pragma once
// The configuration reference (docs/reference/config.md), generated from the program so that it
// cannot drift from it: the keys are configKeys', the defaults AppConfig's, the allowed values
// what validation refuses, the descriptions default.yaml's comments. tests/unit/
// docs_reference_test.cpp compares the committed page with it (and rewrites it on request).
#include <string>
#include <vector>

namespace gvio::cli {

struct KeyReference {
  std::string name;           // dotted, e.g. "sim.knot_spacing_s"
  std::string default_value;  // the key's value in a default AppConfig, as YAML text
  // What validation asks of the key, from the message refusing a value probed out of range
  // ("in [0.05, 5]"); else what the key's parser accepts ("true or false"); else "any".
  std::string allowed;
  bool allowed_by_validation = false;  // `allowed` came from a refused value
  std::string description;             // default.yaml's comment on the key; empty without one
};

// Every key of configKeys, in its order. default_yaml: the text of assets/config/default.yaml.
std::vector<KeyReference> configReference(const std::string& default_yaml);

// The page: a title and one table per top-level section (key | default | allowed values |
// description), each section introduced by default.yaml's comment on it when there is one.
std::string configReferenceMarkdown(const std::string& default_yaml);

}  // namespace gvio::cli
