#pragma once
// An independent LAS 1.4 reader for the tests (ASPRS LAS 1.4 R15: public header block, VLRs,
// point data record formats 6 and 7), written from the specification's tables, sharing no code
// with app/export/las_writer. Throws std::runtime_error on anything it cannot parse.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace gvio::test {

struct LasVlr {
  std::string user_id;
  std::uint16_t record_id = 0;
  std::string description;
  std::string data;
};

struct LasRecord {
  Eigen::Matrix<std::int32_t, 3, 1> raw = Eigen::Matrix<std::int32_t, 3, 1>::Zero();
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  // raw * scale + offset
  std::uint16_t intensity = 0;
  int return_number = 0, number_of_returns = 0;
  std::uint8_t classification = 0;
  std::uint16_t point_source_id = 0;
  double gps_time = 0.0;
  std::optional<std::array<std::uint16_t, 3>> rgb;  // format 7
};

struct LasFile {
  std::string signature;
  int version_major = 0, version_minor = 0;
  std::uint16_t global_encoding = 0;
  std::string system_identifier, generating_software;
  std::uint16_t header_size = 0;
  std::uint32_t offset_to_points = 0;
  std::uint32_t vlr_count = 0;
  int point_format = 0;
  std::uint16_t point_length = 0;
  std::uint32_t legacy_point_count = 0;
  std::array<std::uint32_t, 5> legacy_by_return{};
  Eigen::Vector3d scale = Eigen::Vector3d::Zero(), offset = Eigen::Vector3d::Zero();
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();
  std::uint64_t evlr_start = 0;
  std::uint32_t evlr_count = 0;
  std::uint64_t point_count = 0;
  std::array<std::uint64_t, 15> by_return{};
  std::vector<LasVlr> vlrs;
  std::vector<LasRecord> points;

  // The data of the OGC WKT VLR ("LASF_Projection", 2112) without its terminating null; empty
  // when absent.
  [[nodiscard]] std::string wkt() const;
};

LasFile readLas(const std::filesystem::path& file);

}  // namespace gvio::test
