#pragma once
// Every output file is written to a temporary sibling and renamed into place, so a reader never
// sees a half-written file and a failed run never leaves a truncated one behind.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>

namespace gvio::io {

// Calls `write` with a stream on a temporary file next to `path`, then renames it to `path`.
// Throws InputError (naming `path`) when the directory is missing or unwritable.
void writeFileAtomic(const std::filesystem::path& path,
                     const std::function<void(std::ostream&)>& write);
void writeTextAtomic(const std::filesystem::path& path, std::string_view text);

// For writers that need a file path of their own (e.g. PCL's): the temporary sibling to write,
// ending in `suffix` (some libraries choose the format by extension), and the rename into place
// (the temporary is removed and InputError naming `path` thrown when that fails).
std::filesystem::path temporarySibling(const std::filesystem::path& path,
                                       std::string_view suffix = "");
void moveIntoPlace(const std::filesystem::path& tmp, const std::filesystem::path& path);

}  // namespace gvio::io
