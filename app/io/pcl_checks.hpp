#pragma once
// Checks of PCD and PLY files before PCL reads them. PCL 1.13's readers trust their input: on
// damaged files they read past the data, use freed memory (PCD), assert or loop for ever (PLY), and
// print multi-line complaints of their own (all found by fuzzing, tests/fuzz). These checks follow
// the formats' specifications (PCD v0.7 at pointclouds.org; PLY as in Greg Turk's description)
// and refuse such files with one line naming the file.
#include <cstddef>
#include <cstdint>
#include <filesystem>

namespace gvio::io {

// The PCD header's consistency (each key once, printable text, FIELDS/SIZE/TYPE/COUNT agree,
// WIDTH x HEIGHT = POINTS) and a data section as long as the header says. Returns the number of
// points; throws InputError (file and header line).
std::size_t checkPcdFile(const std::filesystem::path& file);

// The PLY header: "ply", one known format, then only comment/obj_info/element/property lines with
// known types and counts the file can hold, up to end_header; no list property in the vertex
// element. Throws InputError (file and header line).
void checkPlyFile(const std::filesystem::path& file);

// PCL's writers that take a file name do not check their stream: on a full disk or past the file
// size limit they report success with a short file. `written` is what such a writer produced for
// `file`; throws InputError naming `file` unless it holds a whole PLY header and exactly
// `body_bytes` after it.
void checkWrittenPly(const std::filesystem::path& written, const std::filesystem::path& file,
                     std::uint64_t body_bytes);

}  // namespace gvio::io
