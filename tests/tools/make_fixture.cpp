// gvio_make_fixture OUT_DIR: writes the embedded demo drive (assets/demo) into OUT_DIR.
// The committed copy is checked against this generator by DemoAssets.MatchGenerator.
#include <cstdio>
#include <exception>

#include "support/fixtures.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: gvio_make_fixture OUT_DIR\n");
    return 2;
  }
  try {
    const auto drive = gvio::test::writeKittiFixture(argv[1], gvio::test::demoFixture());
    std::printf("%s\n", drive.string().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvio_make_fixture: %s\n", e.what());
    return 1;
  }
  return 0;
}
