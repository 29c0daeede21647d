#pragma once
// The comments of a commented YAML configuration (assets/config/default.yaml), by key: they are
// the keys' documentation, which the configuration reference (cli/config_reference.hpp) shows.
// A line scanner, not a YAML parser: yaml-cpp drops comments.
#include <map>
#include <string>

namespace gvio::cli {

// Each key's comment by its dotted name, as loadConfig flattens the file ("vio.tracker.klt_levels"
// from "tracker.klt_levels:" under "vio:"); section keys ("fleet") included. A key's comment is
// the one trailing its line, with the comment lines below it indented past the key (its
// continuation); else the comment lines right above it (no blank line between), which also
// describe the keys that follow it with no comment of their own and no blank line (a group). "#"
// and surrounding blanks are stripped and the lines joined with one space. Keys without a comment
// are absent.
std::map<std::string, std::string> yamlKeyComments(const std::string& yaml_text);

}  // namespace gvio::cli
