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

}  // namespace gvio::io
