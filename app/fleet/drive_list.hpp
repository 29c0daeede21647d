#pragma once
// The drive list of `gvio fleet --drives LIST`: one drive per line, its dataset (any format
// `gvio run` reads) first, then options for that drive's `gvio run`:
//
//   # comment lines and blank lines are ignored
//   /data/2011_10_03_drive_0027_extract
//   /data/morning.bag --calib camchain.yaml imu.yaml --gnss-file morning.pos
//   "/data/with space/drive" --name evening --set vio.mode=stereo
//
// Words are split at blanks; '...' and "..." quote. A relative dataset or option path is taken
// relative to the list file's folder (the list travels with its data). `--name N` names the run
// folder (default: the dataset's file name without a .bag extension); --dataset and --out are the
// fleet's to set.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace gvio::fleet {

struct DriveSpec {
  std::size_t line = 0;               // in the list file (1-based), for messages
  std::string name;                   // the run folder's name, unique in the list
  std::filesystem::path dataset;      // absolute (relative ones: against the list's folder)
  std::vector<std::string> run_args;  // the drive's own `gvio run` options, in order
};

// Splits one line into words (blanks separate, quotes group, '#' at a word's start ends the
// line). Throws InvalidInput("unterminated quote") for an open quote.
std::vector<std::string> splitWords(const std::string& line);

// Parses the list text of `file` (for messages and relative paths). Throws InputError naming the
// file and line: an unterminated quote, --dataset/--out given, --name without a value or with a
// '/' in it, two drives with the same name, no drive at all.
std::vector<DriveSpec> parseDriveList(const std::string& text, const std::filesystem::path& file);

// Reads and parses `file`; InputError when it cannot be read.
std::vector<DriveSpec> readDriveList(const std::filesystem::path& file);

}  // namespace gvio::fleet
