#pragma once
// A structural check of a ROS bag (format 2.0) before librosbag_storage opens it: every top-level
// record's header and data must lie inside the file, and a chunk's declared size must be
// plausible. librosbag_storage allocates whatever a length field says (a damaged 4-byte field
// asked it for 2.3 GB; found by fuzzing), so such bags are refused here with the byte offset.
// http://wiki.ros.org/Bags/Format/2.0
#include <string>

namespace gvio::io::bag {

// Throws BagError (bag_file.hpp) for a record that overruns the file or its chunk, a malformed
// record header, a chunk that declares more than 1 GiB uncompressed (or, uncompressed, a size
// other than its data; lz4, more than lz4 can expand to), a compressed chunk that does not
// decompress to its declared size, an index entry that is not a message record of its chunk, an
// index_pos / chunk_pos that is not the start of a record (of a chunk), or a version line of
// another format than 2.0. The records inside lz4 and bz2 chunks are decompressed and walked as
// those of uncompressed ones. A file without a ROS version line is left to the library.
void checkBagRecords(const std::string& path);

}  // namespace gvio::io::bag
