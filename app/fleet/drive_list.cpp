#include "fleet/drive_list.hpp"

#include <fstream>
#include <set>
#include <sstream>

#include "io/input_error.hpp"

namespace gvio::fleet {
namespace {

namespace fs = std::filesystem;

// Options of `gvio run` whose values are paths: resolved against the list's folder like the
// dataset. --calib takes one or two files.
bool takesPaths(const std::string& option) {
  return option == "--calib" || option == "--gnss-file" || option == "--config" ||
         option == "--gnss-noise";
}

fs::path resolve(const fs::path& base, const std::string& word) {
  const fs::path p(word);
  return (p.is_absolute() ? p : base / p).lexically_normal();
}

std::string defaultName(const fs::path& dataset) {
  fs::path p = dataset.lexically_normal();
  // "drive/" -> "drive"; the root ("/") has no name (the caller asks for --name), and its parent
  // is itself, so this is no loop (a fuzzer found that one).
  if (p.filename().empty() && p.has_relative_path()) p = p.parent_path();
  if (p.extension() == ".bag") return p.stem().string();
  return p.filename().string();
}

}  // namespace

std::vector<std::string> splitWords(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (const char c : line) {
    if (quote != 0) {
      if (c == quote) {
        quote = 0;
      } else {
        word += c;
      }
    } else if (c == '\'' || c == '"') {
      quote = c;
      in_word = true;
    } else if (c == ' ' || c == '\t' || c == '\r') {
      if (in_word) words.push_back(word);
      word.clear();
      in_word = false;
    } else if (c == '#' && !in_word) {
      break;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (quote != 0) throw InvalidInput("unterminated quote");
  if (in_word) words.push_back(word);
  return words;
}

std::vector<DriveSpec> parseDriveList(const std::string& text, const fs::path& file) {
  // Absolute: Slurm tasks run in another folder, maybe on another machine of the cluster.
  const fs::path base = fs::absolute(file).parent_path();
  std::vector<DriveSpec> drives;
  std::set<std::string> names;
  std::istringstream in(text);
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    std::vector<std::string> words;
    try {
      words = splitWords(line);
    } catch (const InvalidInput& e) {
      throw io::InputError(file, number, e.what());
    }
    if (words.empty()) continue;
    DriveSpec drive;
    drive.line = number;
    if (words[0].starts_with("-")) {
      throw io::InputError(file, number, "expected a dataset first, got option '" + words[0] + "'");
    }
    drive.dataset = resolve(base, words[0]);
    for (std::size_t k = 1; k < words.size(); ++k) {
      const std::string& w = words[k];
      if (w == "--dataset" || w == "--out" || w.starts_with("--dataset=") ||
          w.starts_with("--out=")) {
        throw io::InputError(file, number,
                             w.substr(0, w.find('=')) +
                                 " is set by the fleet (the dataset is the "
                                 "line's first word, the run folder is "
                                 "OUT/runs/NAME)");
      }
      if (w == "--name") {
        if (k + 1 >= words.size() || words[k + 1].empty() || words[k + 1].starts_with("-")) {
          throw io::InputError(file, number, "--name needs a value");
        }
        drive.name = words[++k];
        continue;
      }
      drive.run_args.push_back(w);
      if (takesPaths(w)) {
        // Every following word up to the next option is a path (--calib takes two).
        while (k + 1 < words.size() && !words[k + 1].starts_with("-")) {
          const std::string& value = words[++k];
          const bool preset =
              w == "--gnss-noise" && (value == "none" || value == "spp" || value == "rtk");
          drive.run_args.push_back(preset ? value : resolve(base, value).string());
        }
      }
    }
    if (drive.name.empty()) drive.name = defaultName(drive.dataset);
    if (drive.name.empty() || drive.name == "." || drive.name == ".." ||
        drive.name.find('/') != std::string::npos) {
      throw io::InputError(file, number,
                           "cannot name a run folder '" + drive.name + "'; give one with --name");
    }
    if (!names.insert(drive.name).second) {
      throw io::InputError(file, number,
                           "a drive named '" + drive.name +
                               "' is already in the list; give this one another with --name");
    }
    drives.push_back(std::move(drive));
  }
  if (drives.empty()) throw io::InputError(file, 0, "no drive in the list");
  return drives;
}

std::vector<DriveSpec> readDriveList(const fs::path& file) {
  std::ifstream in(file);
  if (!in || fs::is_directory(file)) {
    throw io::InputError(file, 0, "drive list not found or unreadable");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return parseDriveList(text.str(), file);
}

}  // namespace gvio::fleet
