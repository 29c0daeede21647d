#pragma once
// The run folder's map files read generically and written again: the point cloud (map.pcd /
// map.ply, any fields, through PCL) and the OctoMap occupancy (map.bt / map.ot). Reading them back
// through their own libraries is what validates them before an export.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <pcl/PCLPointCloud2.h>

#include "export/georef.hpp"
#include "export/las_writer.hpp"

namespace gvio::exporter {

// map.pcd or map.ply (by extension). Throws InputError naming `file` when it is missing,
// unreadable, has no float x/y/z fields, or holds 0 points.
pcl::PCLPointCloud2 readPointCloud2(const std::filesystem::path& file);

// PCD binary compressed / PLY binary (every field kept), written atomically.
void writePcd(const std::filesystem::path& file, const pcl::PCLPointCloud2& cloud);
void writePly(const std::filesystem::path& file, const pcl::PCLPointCloud2& cloud);

// The cloud's points for the LAS writer, read from the cloud in place (it must outlive the
// result): x/y/z (ENU), nullopt where not finite (PCL's invalid points) or when the cloud has no
// x/y/z fields, with the "intensity" field, when present, scaled to LAS's 16-bit range by the
// field's type: 8-bit x 257, 16-bit as is, floats in [0, 1] x 65535, floats up to 255 x 257,
// anything else clamped. Point count: width x height.
LasPointAt lasPointSource(const pcl::PCLPointCloud2& cloud);

// A map cloud (local ENU at georef's origin) as LAS 1.4 in georef's UTM zone, atomically: what
// `gvio export --to las` and gvio run's map.las write. Throws InputError naming `source` (the
// cloud's file, or the run's map.pcd) when the cloud has no finite point.
LasSummary writeMapLas(const std::filesystem::path& file, const pcl::PCLPointCloud2& cloud,
                       const Georef& georef, const std::filesystem::path& source);

struct OctreeSummary {
  std::string type;  // "OcTree", "ColorOcTree", ...
  double resolution_m = 0.0;
  std::size_t nodes = 0, leaves = 0;
};

// Reads an OctoMap file and writes it again atomically: .bt (OcTree binary, readBinary /
// writeBinary) or .ot (any AbstractOcTree, read / write). Throws InputError naming the input when
// it is missing, not an OctoMap file of that kind, or empty, and naming `out` when unwritable.
OctreeSummary copyOctreeBinary(const std::filesystem::path& in, const std::filesystem::path& out);
OctreeSummary copyOctreeFull(const std::filesystem::path& in, const std::filesystem::path& out);

}  // namespace gvio::exporter
