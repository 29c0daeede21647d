// gvio_make_fixture OUT_DIR: writes the embedded demo inputs (assets/demo) into OUT_DIR: a small
// KITTI raw drive and drive.tum, the trajectory the Quick-start demo simulates.
// The committed copy is checked against this generator by DemoAssets.MatchGenerator.
#include <cstdio>
#include <exception>

#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: gvio_make_fixture OUT_DIR\n");
    return 2;
  }
  try {
    const auto drive = gvio::test::writeKittiFixture(argv[1], gvio::test::demoFixture());
    std::printf("%s\n", drive.string().c_str());
    gvio::io::writeTum(std::filesystem::path(argv[1]) / "drive.tum", gvio::test::demoDrive());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvio_make_fixture: %s\n", e.what());
    return 1;
  }
  return 0;
}
