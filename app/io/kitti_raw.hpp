#pragma once
// KITTI raw drive folders (2011_09_26_drive_0001_sync / _extract) and the simulator's output,
// which uses the same layout plus gnss/fixes.nmea and groundtruth.tum.
#include <filesystem>

#include "io/dataset.hpp"
#include "io/reader_config.hpp"

namespace gvio::io {

Dataset readKittiRaw(const std::filesystem::path& drive_dir, const ReaderConfig& config);

// True when the folder looks like a KITTI raw drive (oxts/ or image_00/ with timestamps.txt).
bool looksLikeKittiRaw(const std::filesystem::path& dir);

}  // namespace gvio::io
