#include "cli/yaml_comments.hpp"

#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

namespace gvio::cli {
namespace {

std::string_view trim(std::string_view s) {
  const auto begin = s.find_first_not_of(" \t\r");
  if (begin == std::string_view::npos) return {};
  return s.substr(begin, s.find_last_not_of(" \t\r") - begin + 1);
}

// A comment's text: "#" and the blanks around it stripped ("#   auto = ..." -> "auto = ..."),
// runs of blanks (columns lined up in the file) made one.
std::string commentText(std::string_view comment) {
  std::string out;
  for (const char c : trim(comment.substr(1))) {
    const bool blank = c == ' ' || c == '\t';
    if (!blank || out.empty() || out.back() != ' ') out += blank ? ' ' : c;
  }
  return out;
}

// Where a key line's trailing comment starts: a "#" after a blank, outside quotes (a "#" inside a
// quoted value, or glued to a word, is part of the value).
std::string_view::size_type trailingCommentAt(std::string_view line) {
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && i > 0 && (line[i - 1] == ' ' || line[i - 1] == '\t')) {
      return i;
    }
  }
  return std::string_view::npos;
}

void append(std::string& text, const std::string& more) {
  if (more.empty()) return;
  text += (text.empty() ? "" : " ") + more;
}

// The scanner's state between lines.
struct Scan {
  std::vector<std::pair<std::size_t, std::string>> sections;  // enclosing keys, by indentation
  std::vector<std::string> block;  // comment lines since the last key or blank line
  std::string last_key;            // dotted
  std::size_t last_indent = 0;
  bool continuing = false;  // the last key had a trailing comment that may go on below it
  // A comment block above a run of keys (no blank line between them) is about all of them:
  // "Geodetic origin ..." above origin_lat_deg, origin_lon_deg and origin_h_m.
  std::string group;
  std::map<std::string, std::string> comments;
};

void scanComment(Scan& scan, std::size_t indent, std::string_view content) {
  // Indented past the key it follows: the key's trailing comment wrapped onto the next line. At
  // the key's indentation (or less) it is about what comes next.
  if (scan.continuing && indent > scan.last_indent) {
    append(scan.comments[scan.last_key], commentText(content));
    return;
  }
  scan.continuing = false;
  scan.block.push_back(commentText(content));
}

void scanKey(Scan& scan, std::size_t indent, std::string_view content) {
  const auto hash = trailingCommentAt(content);
  const std::string_view body = content.substr(0, hash);
  const auto colon = body.find(':');
  if (colon == std::string_view::npos) return;  // a sequence item or a wrapped value
  while (!scan.sections.empty() && scan.sections.back().first >= indent) scan.sections.pop_back();
  std::string name;
  for (const auto& section : scan.sections) name += section.second + ".";
  name += std::string(trim(body.substr(0, colon)));
  if (trim(body.substr(colon + 1)).empty()) {
    scan.sections.emplace_back(indent, std::string(trim(body.substr(0, colon))));
  }
  std::string comment;
  if (hash != std::string_view::npos) {
    comment = commentText(content.substr(hash));
    scan.group.clear();
  } else if (!scan.block.empty()) {
    for (const auto& line : scan.block) append(comment, line);
    scan.group = comment;
  } else {
    comment = scan.group;
  }
  if (!comment.empty()) scan.comments[name] = comment;
  if (trim(body.substr(colon + 1)).empty()) scan.group.clear();  // a section's comment is its own
  scan.block.clear();
  scan.last_key = name;
  scan.last_indent = indent;
  scan.continuing = hash != std::string_view::npos;
}

}  // namespace

std::map<std::string, std::string> yamlKeyComments(const std::string& yaml_text) {
  Scan scan;
  std::istringstream lines(yaml_text);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t indent = line.find_first_not_of(' ');
    const std::string_view content = indent == std::string::npos
                                         ? std::string_view()
                                         : trim(std::string_view(line).substr(indent));
    if (content.empty()) {  // a blank line ends a comment block, a group and a trailing comment
      scan.block.clear();
      scan.group.clear();
      scan.continuing = false;
    } else if (content.front() == '#') {
      scanComment(scan, indent, content);
    } else {
      scanKey(scan, indent, content);
    }
  }
  return std::move(scan.comments);
}

}  // namespace gvio::cli
