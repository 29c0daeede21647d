#pragma once
// Small datasets the tests write themselves (no real data needed), and helpers around them.
#include <filesystem>
#include <string>
#include <vector>

#include "odometry/trajectory.hpp"

namespace gvio::test {

// A fresh folder under the system temp dir, removed with its contents on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& tag);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

void writeText(const std::filesystem::path& file, const std::string& text);
// A TUM file's rows of numbers (comment and empty lines skipped), to compare two runs' outputs.
std::vector<std::vector<double>> tumRows(const std::filesystem::path& file);
std::string readText(const std::filesystem::path& file);
// Replaces line `line` (1-based) of a text file.
void replaceLine(const std::filesystem::path& file, std::size_t line, const std::string& text);

struct KittiFixture {
  std::string drive_name = "2011_09_26_drive_0001_extract";
  int frames = 6;          // camera frames at 10 Hz
  int oxts_rate_hz = 100;  // 100 = extract style, 10 = sync style
  int width = 64, height = 24;
  bool calib_in_parent = true;  // KITTI download layout: calib beside the drive folder
  bool write_nmea = false;      // gnss/fixes.nmea (the simulator's layout)
  int nmea_rate_hz = 1;
  bool write_groundtruth = false;
};

// Writes a complete, valid KITTI raw drive under `base`/2011_09_26/ and returns the drive folder.
// The drive moves north-east at 10 m/s from 49.011 N, 8.4 E; images are a textured gradient.
std::filesystem::path writeKittiFixture(const std::filesystem::path& base,
                                        const KittiFixture& spec);

// The embedded demo drive (assets/demo): 2 s, stereo 64x24, 100 Hz oxts, 5 Hz NMEA, truth.
KittiFixture demoFixture();

// A 35 s urban drive at 8 m/s with two 90-degree turns: body poses (x forward, z up) in a local
// ENU frame at 10 Hz, stamps from 0. The demo's and the simulator tests' input
// (assets/demo/drive.tum).
Trajectory demoDrive();

// 100 poses at 10 Hz around an ellipse (50 m x 30 m, rising 2 cm a pose), heading along it,
// stamps from 1317300000 s: a georeferenced run's trajectory for the export and view tests.
Trajectory ellipseDrive();

// Path of the real data folder (../shared/data beside the project), empty when absent.
std::filesystem::path sharedData(const std::string& relative);

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};
// A path single-quoted for the shell command runGvio builds (test paths hold no single quote).
inline std::string quoted(const std::filesystem::path& p) {
  return "'" + p.string() + "'";
}
// `gvio run` options for the simulator's ENU origin and antenna lever arm (its defaults): the fused
// trajectory is then directly comparable with groundtruth.tum.
inline constexpr const char* kSimGeo =
    "--set fusion.origin=48.98253,8.39035,116.4 --set fusion.lever_arm_b=[0,0,0.8]";
// Runs the built gvio binary with `args` (shell-quoted by the caller), capturing stdout/stderr.
CommandResult runGvio(const std::string& args);
// The output folder of `gvio simulate <args> --out <folder>`, simulated once per build of the gvio
// binary and shared by every test process (ctest runs each test in its own process). The folder
// is created under a temporary name and renamed into place, so concurrent tests never see a
// half-written one. Fails the calling test when the simulation fails.
std::filesystem::path cachedSimulation(const std::string& args);

// The same with environment assignments ("NAME=value ...") in front of the command.
CommandResult runGvioWithEnv(const std::string& env, const std::string& args);

}  // namespace gvio::test
