#include "support/tracker_drive.hpp"

#include <fmt/format.h>

#include <optional>
#include <stdexcept>

#include "io/image_loader.hpp"
#include "odometry/rectifier.hpp"
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

std::vector<StereoPair> eurocClipRectified() {
  const std::filesystem::path root = sharedData("euroc_v101_micro");
  if (root.empty()) return {};
  const io::Dataset ds = io::readDataset(root, std::nullopt, io::ReaderConfig{});
  if (ds.cameras.size() != 2U) {
    throw std::runtime_error("euroc_v101_micro: expected 2 cameras, got " +
                             std::to_string(ds.cameras.size()));
  }
  const odometry::Rectifier rectifier(ds.cameras[0], ds.cameras[1]);
  std::vector<StereoPair> pairs;
  for (std::size_t k = 0; k < ds.frames.size(); k += 2) {
    odometry::RectifiedImages images =
        rectifier.rectify(io::loadGrayImage(ds.frames[k].image_paths[0], ds.cameras[0]),
                          io::loadGrayImage(ds.frames[k].image_paths[1], ds.cameras[1]));
    pairs.push_back({ds.frames[k].t_ns, std::move(images.left), std::move(images.right)});
  }
  return pairs;
}

}  // namespace gvio::test
