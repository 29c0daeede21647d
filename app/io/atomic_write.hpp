#pragma once
// Every output file is written to a temporary sibling and renamed into place, so a reader never
// sees a half-written file and a failed run never leaves a truncated one behind. Temporaries are
// created exclusively (O_EXCL: never someone else's file or link) as hidden siblings named
// `.NAME.gvio-tmp-PID-N[SUFFIX]`; one left behind by a process that was killed (SIGKILL, power
// loss) is recognised by its dead PID and removed by removeStaleTemporaries.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string_view>
#include <vector>

namespace gvio::io {

// Calls `write` with a stream on a temporary file next to `path`, then renames it to `path`.
// Throws InputError (naming `path`) when the directory is missing or unwritable, or a write fails
// (disk full, file size limit): the temporary is removed and `path` keeps its earlier content.
void writeFileAtomic(const std::filesystem::path& path,
                     const std::function<void(std::ostream&)>& write);
void writeTextAtomic(const std::filesystem::path& path, std::string_view text);

// For writers that need a file path of their own (e.g. PCL's): a new, empty temporary sibling of
// `path`, created exclusively, ending in `suffix` (some libraries choose the format by
// extension), and the rename into place (the temporary is removed and InputError naming `path`
// thrown when that fails). Throws InputError naming `path` when the temporary cannot be created.
std::filesystem::path createTemporarySibling(const std::filesystem::path& path,
                                             std::string_view suffix = "");
void moveIntoPlace(const std::filesystem::path& tmp, const std::filesystem::path& path);

// Both of the above around a writer that takes a file name (PCL's PLY, GDAL): `write` gets the
// temporary and throws when it fails; then the temporary (or a folder a library left under its
// name) is removed and `path` keeps its earlier content; else it is renamed into place.
void writeViaPathAtomic(const std::filesystem::path& path, std::string_view suffix,
                        const std::function<void(const std::filesystem::path& tmp)>& write);

// A whole folder the same way: `write` fills a new folder beside `dir` (named like the
// temporaries above), which then replaces `dir` (an earlier one is removed first: the caller
// checks that it is its own kind of folder). On any failure the new folder is removed and
// InputError naming `dir` thrown (or `write`'s exception passed on).
void writeFolderAtomic(const std::filesystem::path& dir,
                       const std::function<void(const std::filesystem::path& tmp)>& write);

// Whether `file` is named like one of our temporaries (any process's).
bool isTemporaryName(const std::filesystem::path& file);

// Removes the temporaries in `dir` whose process is gone (left by a killed run); returns them.
std::vector<std::filesystem::path> removeStaleTemporaries(const std::filesystem::path& dir);

}  // namespace gvio::io
