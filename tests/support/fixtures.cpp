#include "support/fixtures.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

#include "io/nmea.hpp"
#include "io/text.hpp"
#include "sim/kitti_convention.hpp"

namespace gvio::test {
namespace fs = std::filesystem;

TempDir::TempDir(const std::string& tag) {
  static std::atomic<int> counter{0};
  path_ = fs::temp_directory_path() /
          fmt::format("gvio_{}_{}_{}", tag, static_cast<long>(::getpid()), counter++);
  fs::remove_all(path_);
  fs::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

void writeText(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write fixture " + file.string());
}

std::vector<std::vector<double>> tumRows(const std::filesystem::path& file) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(readText(file));
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<double> row;
    for (double v; fields >> v;) row.push_back(v);
    rows.push_back(row);
  }
  return rows;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void replaceLine(const fs::path& file, std::size_t line, const std::string& text) {
  std::istringstream in(readText(file));
  std::string out, current;
  for (std::size_t n = 1; std::getline(in, current); ++n)
    out += (n == line ? text : current) + "\n";
  writeText(file, out);
}

namespace {

// KITTI's real IMU -> velodyne -> camera chain with intrinsics scaled to the tiny images.
void writeCalib(const fs::path& dir, const KittiFixture& s) {
  render::PinholeIntrinsics K;
  K.fx = K.fy = 0.5 * s.width;
  K.cx = 0.5 * s.width;
  K.cy = 0.5 * s.height;
  K.width = s.width;
  K.height = s.height;
  const sim::KittiCalibrationText text = sim::kittiCalibrationText(K, true);
  writeText(dir / "calib_imu_to_velo.txt", text.imu_to_velo);
  writeText(dir / "calib_velo_to_cam.txt", text.velo_to_cam);
  writeText(dir / "calib_cam_to_cam.txt", text.cam_to_cam);
}

std::string kittiStamp(std::int64_t t_ns_of_day) {
  const std::int64_t s = t_ns_of_day / 1'000'000'000LL;
  return fmt::format("2011-09-26 {:02d}:{:02d}:{:02d}.{:09d}", s / 3600, (s / 60) % 60, s % 60,
                     t_ns_of_day % 1'000'000'000LL);
}

constexpr std::int64_t kStartNs =
    13LL * 3600 * 1'000'000'000LL + 2LL * 60 * 1'000'000'000LL;  // 13:02
constexpr double kLat0 = 49.011, kLon0 = 8.4, kSpeed = 10.0;

void latLonAt(double t_s, double& lat, double& lon) {
  const double d = kSpeed * t_s / std::sqrt(2.0);  // metres north and east
  lat = kLat0 + d / 111'200.0;
  lon = kLon0 + d / (111'200.0 * std::cos(kLat0 * M_PI / 180.0));
}

void writeOxts(const fs::path& drive, const KittiFixture& s) {
  const int n = static_cast<int>(std::lround((s.frames / 10.0) * s.oxts_rate_hz));
  std::string stamps;
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / s.oxts_rate_hz;
    stamps += kittiStamp(kStartNs + static_cast<std::int64_t>(std::llround(t * 1e9))) + "\n";
    double lat = 0.0, lon = 0.0;
    latLonAt(t, lat, lon);
    // lat lon alt roll pitch yaw vn ve vf vl vu ax ay az af al au wx wy wz wf wl wu
    // pos_accuracy vel_accuracy navstat numsats posmode velmode orimode
    writeText(drive / "oxts" / "data" / fmt::format("{:010d}.txt", i),
              fmt::format("{:.12f} {:.12f} 116.4 0.01 -0.02 0.785398 7.0711 7.0711 10 0 0 "
                          "0.1 0.02 9.81 0.1 0.02 9.81 0.001 -0.002 0.003 0.001 -0.002 0.003 "
                          "0.2 0.05 4 9 4 4 6\n",
                          lat, lon));
  }
  writeText(drive / "oxts" / "timestamps.txt", stamps);
}

void writeImages(const fs::path& drive, const KittiFixture& s) {
  for (int cam = 0; cam < 2; ++cam) {
    std::string stamps;
    for (int i = 0; i < s.frames; ++i) {
      stamps += kittiStamp(kStartNs + i * 100'000'000LL + cam * 2'000) + "\n";
      cv::Mat image(s.height, s.width, CV_8UC1);
      for (int r = 0; r < s.height; ++r) {
        for (int c = 0; c < s.width; ++c) {
          image.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(
              (c * 7 + r * 13 + i * 5 + cam * 3 + ((r / 4 + c / 4) % 2) * 60) % 256);
        }
      }
      const fs::path file =
          drive / fmt::format("image_{:02d}", cam) / "data" / fmt::format("{:010d}.png", i);
      fs::create_directories(file.parent_path());
      cv::imwrite(file.string(), image);
    }
    writeText(drive / fmt::format("image_{:02d}", cam) / "timestamps.txt", stamps);
  }
}

std::string nmeaLatLon(double deg, bool is_lat) {
  const double a = std::abs(deg);
  const int d = static_cast<int>(a);
  const char hemisphere = is_lat ? (deg >= 0 ? 'N' : 'S') : (deg >= 0 ? 'E' : 'W');
  return fmt::format(fmt::runtime(is_lat ? "{:02d}{:010.7f},{}" : "{:03d}{:010.7f},{}"), d,
                     (a - d) * 60.0, hemisphere);
}

void writeNmea(const fs::path& drive, const KittiFixture& s) {
  std::string log;
  const int fixes = s.frames * s.nmea_rate_hz / 10;
  for (int i = 0; i < fixes; ++i) {
    const double t = static_cast<double>(i) / s.nmea_rate_hz;
    double lat = 0.0, lon = 0.0;
    latLonAt(t, lat, lon);
    const std::int64_t ms =
        kStartNs / 1'000'000 + static_cast<std::int64_t>(std::llround(t * 1000));
    const std::int64_t sec = ms / 1000;
    const std::string hms = fmt::format("{:02d}{:02d}{:02d}.{:02d}", sec / 3600, (sec / 60) % 60,
                                        sec % 60, (ms % 1000) / 10);
    log += io::withNmeaChecksum(fmt::format("GPGGA,{},{},{},1,09,0.9,68.4,M,48.0,M,,", hms,
                                            nmeaLatLon(lat, true), nmeaLatLon(lon, false))) +
           "\r\n";
    log += io::withNmeaChecksum(fmt::format("GPRMC,{},A,{},{},19.4,45.0,260911,,,A", hms,
                                            nmeaLatLon(lat, true), nmeaLatLon(lon, false))) +
           "\r\n";
  }
  writeText(drive / "gnss" / "fixes.nmea", log);
}

}  // namespace

fs::path writeKittiFixture(const fs::path& base, const KittiFixture& s) {
  const fs::path date_dir = base / "2011_09_26";
  const fs::path drive = date_dir / s.drive_name;
  fs::create_directories(drive);
  writeCalib(s.calib_in_parent ? date_dir : drive, s);
  writeOxts(drive, s);
  writeImages(drive, s);
  if (s.write_nmea) writeNmea(drive, s);
  if (s.write_groundtruth) {  // body (IMU) poses in ENU: 1 m per frame north-east, yaw 45 deg
    const std::int64_t midnight_ns = io::daysFromCivil(2011, 9, 26) * 86'400'000'000'000LL;
    std::string tum = "# t x y z qx qy qz qw\n";
    for (int i = 0; i < s.frames; ++i) {
      tum += fmt::format("{} {:.6f} {:.6f} 0 0 0 0.3826834 0.9238795\n",
                         io::formatSeconds(midnight_ns + kStartNs + i * 100'000'000LL),
                         std::sqrt(0.5) * i, std::sqrt(0.5) * i);
    }
    writeText(drive / "groundtruth.tum", tum);
  }
  return drive;
}

fs::path cachedSimulation(const std::string& args) {
  // The key covers the arguments and the binary, so a rebuilt simulator never serves stale data.
  const auto stamp = fs::last_write_time(GVIO_BINARY).time_since_epoch().count();
  const std::size_t key = std::hash<std::string>{}(args + "|" + std::to_string(stamp));
  const fs::path cache = fs::path(GVIO_TEST_CACHE_DIR) / fmt::format("sim_{:016x}", key);
  if (fs::exists(cache / "sim.yaml")) return cache;
  fs::create_directories(cache.parent_path());
  // ctest -j runs a suite's tests side by side, each its own process, and they ask for the same
  // drive at once: the first simulates it, the others wait on the lock and take its result
  // (without the lock each simulated the whole drive itself). The lock goes with the process.
  const int lock_fd =
      ::open((cache.string() + ".lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (lock_fd >= 0) ::flock(lock_fd, LOCK_EX);
  struct Unlock {
    int fd;
    ~Unlock() {
      if (fd >= 0) ::close(fd);
    }
  } unlock{lock_fd};
  if (fs::exists(cache / "sim.yaml")) return cache;
  const fs::path tmp = cache.string() + fmt::format(".tmp{}", static_cast<long>(::getpid()));
  fs::remove_all(tmp);
  const CommandResult r =
      runGvio(fmt::format("simulate {} --out {} --no-progress -q", args, tmp.string()));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::error_code ec;
  fs::rename(tmp, cache, ec);  // loses to a concurrent process that finished first: use theirs
  if (ec) fs::remove_all(tmp, ec);
  return cache;
}

KittiFixture demoFixture() {
  KittiFixture spec;
  spec.frames = 20;
  spec.write_nmea = true;
  spec.nmea_rate_hz = 5;
  spec.write_groundtruth = true;
  return spec;
}

Trajectory ellipseDrive() {
  Trajectory t;
  for (int i = 0; i < 100; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const double a = 0.0628 * i;
    T.translation() = Eigen::Vector3d(50 * std::cos(a), 30 * std::sin(a), 0.02 * i);
    T.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    t.poses.push_back(T);
    t.t_ns.push_back(1'317'300'000'000'000'000LL + i * 100'000'000LL);
  }
  return t;
}

Trajectory demoDrive() {
  Trajectory t;
  double x = 0, y = 0, yaw = 0;
  for (int i = 0; i <= 350; ++i) {
    const double s = 0.1 * i;
    const double yaw_rate = (s > 10 && s < 14) ? 0.39 : ((s > 22 && s < 26) ? -0.39 : 0.0);
    yaw += 0.1 * yaw_rate;
    x += 0.8 * std::cos(yaw);
    y += 0.8 * std::sin(yaw);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, y, 0.93 + 0.2 * std::sin(0.05 * s));
    t.poses.push_back(T);
    t.t_ns.push_back(static_cast<std::int64_t>(i) * 100'000'000LL);
  }
  return t;
}

fs::path sharedData(const std::string& relative) {
  const fs::path p = fs::path(GVIO_SHARED_DATA_DIR) / relative;
  return fs::exists(p) ? p : fs::path();
}

CommandResult runGvio(const std::string& args) {
  return runGvioWithEnv("", args);
}

CommandResult runGvioWithEnv(const std::string& env, const std::string& args) {
  static std::atomic<int> counter{0};
  const fs::path tmp = fs::temp_directory_path() /
                       fmt::format("gvio_cmd_{}_{}", static_cast<long>(::getpid()), counter++);
  const std::string cmd = fmt::format("{} {} {} > {}.out 2> {}.err < /dev/null", env, GVIO_BINARY,
                                      args, tmp.string(), tmp.string());
  const int status = std::system(cmd.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = readText(tmp.string() + ".out");
  r.err = readText(tmp.string() + ".err");
  fs::remove(tmp.string() + ".out");
  fs::remove(tmp.string() + ".err");
  return r;
}

}  // namespace gvio::test
