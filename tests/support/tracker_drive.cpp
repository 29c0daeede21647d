#include "support/tracker_drive.hpp"

#include <fmt/format.h>

#include <optional>

#include "io/image_loader.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {

StereoDrive trackerTestDrive() {
  const std::filesystem::path path = cachedSimulation(
      fmt::format("--trajectory {}/assets/demo/drive.tum --seconds 3 --seed 11", GVIO_SOURCE_DIR));
  StereoDrive drive{io::readDataset(path, std::nullopt, io::ReaderConfig{}), {}, {}};
  for (const auto& f : drive.dataset.frames) {
    drive.left.push_back(io::loadGrayImage(f.image_paths[0], drive.dataset.cameras.at(0)));
    drive.right.push_back(io::loadGrayImage(f.image_paths[1], drive.dataset.cameras.at(1)));
  }
  return drive;
}

}  // namespace gvio::test
