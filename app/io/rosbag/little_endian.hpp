#pragma once
// The bag format and ROS serialisation store integers little-endian
// (http://wiki.ros.org/Bags/Format/2.0, http://wiki.ros.org/msg).
#include <cstdint>

namespace gvio::io::bag {

inline std::uint32_t littleEndian32(const unsigned char* p) {
  return std::uint32_t{p[0]} | std::uint32_t{p[1]} << 8 | std::uint32_t{p[2]} << 16 |
         std::uint32_t{p[3]} << 24;
}

}  // namespace gvio::io::bag
