// Fuzz targets for the dataset folders (KITTI raw, EuRoC, comma2k19: one file of a valid dataset
// replaced at a time), images, map files and ROS bags.
#include <dlfcn.h>
#include <fmt/format.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "export/map_files.hpp"
#include "fuzz/checks.hpp"
#include "fuzz/harness.hpp"
#include "fuzz/targets_list.hpp"
#include "io/dataset.hpp"
#include "io/dataset_sources.hpp"
#include "io/kalibr_writer.hpp"
#include "io/mesh_ply.hpp"
#include "io/ros_image.hpp"
#include "io/rosbag/bag_file.hpp"
#include "io/run_dir.hpp"
#include "support/fixtures.hpp"

namespace gvio::fuzz {

namespace fs = std::filesystem;

namespace {

// KITTI raw: 3 frames at 10 Hz, 10 Hz oxts, stereo 32x16, calibration beside the drive.
constexpr const char* kKittiDrive = "2011_09_26/2011_09_26_drive_0001_sync";

void prepareKitti(const fs::path& dir) {
  test::KittiFixture spec;
  spec.drive_name = "2011_09_26_drive_0001_sync";
  spec.frames = 3;
  spec.oxts_rate_hz = 10;
  spec.width = 32;
  spec.height = 16;
  spec.write_nmea = true;
  spec.nmea_rate_hz = 10;
  fs::remove_all(dir / "2011_09_26");
  (void)test::writeKittiFixture(dir, spec);
}

Target kitti(std::string name, const std::string& file) {
  return Target{std::move(name), std::string(kKittiDrive) + "/" + file, prepareKitti,
                [](const fs::path& d) { readWholeDataset(d / kKittiDrive); }, ""};
}

Target kittiCalib(std::string name, const std::string& file) {
  Target t = kitti(std::move(name), "");
  t.file = "2011_09_26/" + file;
  return t;
}

// EuRoC (ASL layout): stereo 32x16 at 20 Hz, 200 Hz IMU, GNSS and ground truth.
constexpr std::int64_t kT0 = 1'403'715'273'262'142'976;

void prepareEuroc(const fs::path& dir) {
  const fs::path mav0 = dir / "mav0";
  fs::remove_all(mav0);
  test::writeText(mav0 / "imu0" / "sensor.yaml",
                  "%YAML:1.0\nsensor_type: imu\nrate_hz: 200\n"
                  "T_BS:\n  cols: 4\n  rows: 4\n  data: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0,\n"
                  "         0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]\n"
                  "gyroscope_noise_density: 1.5e-04\ngyroscope_random_walk: 2.0e-05\n"
                  "accelerometer_noise_density: 2.5e-3\naccelerometer_random_walk: 3.5e-3\n");
  std::string imu = "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n";
  for (int i = 0; i < 24; ++i)
    imu += fmt::format("{},0.01,-0.02,0.03,0.1,0.2,9.81\n", kT0 + i * 5'000'000LL);
  test::writeText(mav0 / "imu0" / "data.csv", imu);
  for (const char* cam : {"cam0", "cam1"}) {
    const bool right = std::string(cam) == "cam1";
    test::writeText(
        mav0 / cam / "sensor.yaml",
        fmt::format("%YAML:1.0\nsensor_type: camera\nrate_hz: 20\nresolution: [32, 16]\n"
                    "T_BS:\n  cols: 4\n  rows: 4\n  data: [0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, "
                    "{},\n         0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]\n"
                    "camera_model: pinhole\nintrinsics: [20.0, 21.0, 16.0, 8.0]\n"
                    "distortion_model: radial-tangential\n"
                    "distortion_coefficients: [0.01, -0.002, 0.0001, 0.0002]\n",
                    right ? "-0.11" : "0.0"));
    std::string csv = "#timestamp [ns],filename\n";
    for (int i = 0; i < 2; ++i) {
      const std::int64_t t = kT0 + i * 50'000'000LL;
      csv += fmt::format("{},{}.png\n", t, t);
      fs::create_directories(mav0 / cam / "data");
      cv::Mat image(16, 32, CV_8UC1);
      cv::randu(image, 0, 255);
      cv::imwrite((mav0 / cam / "data" / fmt::format("{}.png", t)).string(), image);
    }
    test::writeText(mav0 / cam / "data.csv", csv);
  }
  test::writeText(mav0 / "gnss0" / "data.csv",
                  fmt::format("#timestamp [ns],lat [deg],lon [deg],h [m],sigma_h [m],sigma_v [m]\n"
                              "{},47.3667,8.55,500.0,1.5,3.0\n{},47.3668,8.5501,500.5,1.2,2.5\n",
                              kT0, kT0 + 100'000'000LL));
  std::string gt =
      "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z,v_x,v_y,v_z,b_w_x,b_w_y,b_w_z,b_a_x,"
      "b_a_y,b_a_z\n";
  for (int i = 0; i < 3; ++i)
    gt += fmt::format("{},{},0.5,1.0,1.0,0.0,0.0,0.0,1.0,0,0,0,0,0,0,0,0\n", kT0 + i * 50'000'000LL,
                      0.05 * i);
  test::writeText(mav0 / "state_groundtruth_estimate0" / "data.csv", gt);
}

Target euroc(std::string name, const std::string& file) {
  return Target{std::move(name), "mav0/" + file, prepareEuroc,
                [](const fs::path& d) { readWholeDataset(d); }, ""};
}

// comma2k19 converted to CSV: IMU, u-blox fixes and the fused truth (device frame FRD).
void prepareComma(const fs::path& dir) {
  std::string imu = "#t_boot_s,ax_fwd,ay_right,az_down,gx_fwd,gy_right,gz_down\n";
  for (int i = 0; i < 20; ++i)
    imu += fmt::format("{:.9f},0.1,0.2,-9.81,0.001,0.002,0.003\n", 100.0 + i * 0.01);
  test::writeText(dir / "comma" / "csv" / "imu.csv", imu);
  test::writeText(dir / "comma" / "csv" / "gnss_ublox_fix.csv",
                  "#t_boot_s,lat_deg,lon_deg,speed_mps,utc_timestamp,alt_m,bearing_deg\n"
                  "100.000000000,37.720000000,-122.470000000,10.0,1533226488299,30.000,0.0\n"
                  "100.100000000,37.720009000,-122.470000000,10.0,1533226488399,30.000,0.0\n");
  test::writeText(
      dir / "comma" / "csv" / "global_pose_gt.csv",
      "#t_boot_s,gps_week,gps_tow_s,ecef_x,ecef_y,ecef_z,q0,q1,q2,q3\n"
      "100.000000000,2012,404106.0,-2708470.391,-4260545.476,3881200.134,0.5,0.5,-0.5,0.5\n"
      "100.050000000,2012,404106.05,-2708470.091,-4260545.276,3881200.534,0.5,0.5,-0.5,0.5\n");
}

Target comma(std::string name, const std::string& file) {
  return Target{std::move(name), "comma/csv/" + file, prepareComma,
                [](const fs::path& d) { readWholeDataset(d / "comma"); }, ""};
}

// A ROS bag as `gvio simulate --format rosbag` writes one, with its Kalibr files.
void prepareBag(const fs::path& dir) {
  fs::remove(dir / "drive.bag");
  io::bag::BagWriter bag((dir / "drive.bag").string(), io::bag::Compression::kNone);
  const std::int64_t t0 = 1'600'000'000'000'000'000;
  for (int i = 0; i < 2; ++i) {
    for (int c = 0; c < 2; ++c) {
      cv::Mat image(16, 32, CV_8UC1, cv::Scalar(60 + 40 * c + i));
      io::bag::ImageMessage m = io::grayToRosImage(image, c == 1);
      m.t = {t0 + i * 100'000'000LL, t0 + i * 100'000'000LL + 1'000'000};
      bag.write(fmt::format("/cam{}/image_raw", c), m);
    }
  }
  for (int i = 0; i < 12; ++i) {
    io::bag::ImuMessage m;
    m.t = {t0 + i * 10'000'000LL, t0 + i * 10'000'000LL};
    m.acc_mps2 = {0.1, 0.2, 9.81};
    m.gyr_radps = {0.01, -0.02, 0.03};
    bag.write("/imu0", m);
  }
  io::bag::NavSatFixMessage fix;
  fix.t = {t0, t0};
  fix.status = 0;
  fix.lat_deg = 48.1;
  fix.lon_deg = 11.5;
  fix.alt_m = 500.0;
  fix.covariance_enu_m2 = {1.0, 0, 0, 0, 1.0, 0, 0, 0, 4.0};
  fix.covariance_type = 2;
  bag.write("/gnss/fix", fix);
  bag.close();
  test::writeText(dir / "camchain.yaml", smallCamchainYaml());
  test::writeText(dir / "imu.yaml", io::kalibrImuYaml(ImuNoise{}, 100.0, "/imu0"));
}

// Every rosbag::Bag loads librosbag's encryption plugin through class_loader (dlopen) and unloads
// it again (dlclose): 58 % of the fuzzer's time went to the dynamic linker and each input's
// allocations looked like a leak to libFuzzer, which then ran LeakSanitizer's scan on every input.
// Held resident here (RTLD_NODELETE), class_loader finds the plugin's factories already registered
// and uses them (its "library opened outside class_loader" path); the reader's code is the same.
// Without the library (another layout) nothing is pinned and the fuzzer is only slower.
void keepBagPluginsLoaded() {
  static const bool pinned = [] {
    return dlopen(GVIO_ROSBAG_PLUGIN_DIR "/librosbag_default_encryption_plugins.so",
                  RTLD_NOW | RTLD_NODELETE) != nullptr;
  }();
  (void)pinned;
}

void readBag(const fs::path& d) {
  keepBagPluginsLoaded();
  readWholeDataset(d / "drive.bag", {d / "camchain.yaml", d / "imu.yaml"});
}

// One image message from raw bytes: [kind, width, height, step lo, step hi, payload...].
void readRosImage(const fs::path& d) {
  std::ifstream in(d / "message.bin", std::ios::binary);
  std::vector<std::uint8_t> b((std::istreambuf_iterator<char>(in)), {});
  if (b.size() < 5) return;
  static const std::vector<std::string> kEncodings = {
      "mono8", "8UC1",  "mono16",      "16UC1",        "bgr8",   "rgb8",
      "bgra8", "rgba8", "bayer_rggb8", "bayer_grbg16", "yuv422", "32FC1"};
  io::bag::ImageMessage m;
  const std::size_t kind = b[0] % (kEncodings.size() + 3);
  m.compressed = kind >= kEncodings.size();
  if (m.compressed) {
    m.format = kind == kEncodings.size() ? "png" : kind == kEncodings.size() + 1 ? "jpeg" : "bmp";
  } else {
    m.encoding = kEncodings[kind];
  }
  m.width = b[1];
  m.height = b[2];
  m.step = static_cast<std::uint32_t>(b[3] | (b[4] << 8));
  m.big_endian = (b[0] & 0x80) != 0;
  m.data.assign(b.begin() + 5, b.end());
  const cv::Mat gray = io::rosImageToGray(m);
  require(gray.type() == CV_8UC1, "image not 8-bit grey");
  if (!m.compressed)
    require(gray.cols == static_cast<int>(m.width) && gray.rows == static_cast<int>(m.height),
            "image size differs from the message's");
}

void prepareRosImage(const fs::path& dir) {
  std::string bytes = {0, 4, 3, 4, 0};
  for (int i = 0; i < 12; ++i) bytes.push_back(static_cast<char>(20 * i));
  test::writeText(dir / "message.bin", bytes);
}

void prepareMaps(const fs::path& dir) {
  test::writeText(dir / "map.pcd",
                  "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
                  "FIELDS x y z intensity source\nSIZE 4 4 4 4 1\nTYPE F F F F U\nCOUNT 1 1 1 1 1\n"
                  "WIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
                  "1.0 2.0 0.5 120 0\n1.5 2.0 0.5 90 1\n-3.25 7.0 1.75 255 1\n");
  octomap::OcTree tree(0.2);
  octomap::ColorOcTree color(0.2);
  for (int i = 0; i < 5; ++i) {
    tree.updateNode(octomap::point3d(0.2F * i, 1.0F, 0.5F), true);
    color.updateNode(octomap::point3d(0.2F * i, 1.0F, 0.5F), true)->setColor(200, 10, 20);
  }
  tree.writeBinary((dir / "map.bt").string());
  color.write((dir / "map.ot").string());
  io::TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0.5}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  io::writeMeshPly(dir / "mesh.ply", mesh);
}

Target mapTarget(std::string name, std::string file, std::function<void(const fs::path&)> read) {
  return Target{std::move(name), std::move(file), prepareMaps, std::move(read), ""};
}

void checkOccupancy(const io::OccupancyMap& map) {
  require(std::isfinite(map.resolution_m) && map.resolution_m > 0.0, "resolution not positive");
  for (const io::OccupiedVoxel& v : map.voxels)
    require(v.center_enu.allFinite() && std::isfinite(v.size_m) && v.size_m > 0.0F,
            "voxel not finite");
}

}  // namespace

void addFileTargets(std::vector<Target>& out) {
  out.push_back(kitti("kitti_oxts", "oxts/data/0000000001.txt"));
  out.push_back(kitti("kitti_oxts_timestamps", "oxts/timestamps.txt"));
  out.push_back(kitti("kitti_image_timestamps", "image_00/timestamps.txt"));
  out.push_back(kitti("kitti_nmea", "gnss/fixes.nmea"));
  out.push_back(kitti("kitti_image", "image_01/data/0000000001.png"));
  out.push_back(kittiCalib("kitti_calib_cam_to_cam", "calib_cam_to_cam.txt"));
  out.push_back(kittiCalib("kitti_calib_imu_to_velo", "calib_imu_to_velo.txt"));
  out.push_back(kittiCalib("kitti_calib_velo_to_cam", "calib_velo_to_cam.txt"));
  out.push_back(euroc("euroc_cam_csv", "cam0/data.csv"));
  out.push_back(euroc("euroc_cam_yaml", "cam1/sensor.yaml"));
  out.push_back(euroc("euroc_imu_csv", "imu0/data.csv"));
  out.push_back(euroc("euroc_imu_yaml", "imu0/sensor.yaml"));
  out.push_back(euroc("euroc_gnss_csv", "gnss0/data.csv"));
  out.push_back(euroc("euroc_groundtruth", "state_groundtruth_estimate0/data.csv"));
  out.push_back(comma("comma2k19_imu", "imu.csv"));
  out.push_back(comma("comma2k19_gnss", "gnss_ublox_fix.csv"));
  out.push_back(comma("comma2k19_groundtruth", "global_pose_gt.csv"));
  out.push_back(Target{"rosbag", "drive.bag", prepareBag, readBag, ""});
  out.push_back(Target{"ros_image", "message.bin", prepareRosImage, readRosImage, "-"});
  out.push_back(mapTarget("map_pcd", "map.pcd", [](const fs::path& d) {
    const io::MapCloud cloud = io::readMapCloud(d / "map.pcd");
    for (const auto& p : cloud.p_enu) require(p.allFinite(), "map point not finite");
    (void)exporter::readPointCloud2(d / "map.pcd");
  }));
  out.push_back(mapTarget("octomap_bt", "map.bt", [](const fs::path& d) {
    checkOccupancy(io::readOccupancy(d / "map.bt"));
  }));
  out.push_back(mapTarget("octomap_ot", "map.ot", [](const fs::path& d) {
    checkOccupancy(io::readOccupancy(d / "map.ot"));
  }));
  out.push_back(mapTarget("mesh_ply", "mesh.ply", [](const fs::path& d) {
    const io::TriangleMesh mesh = io::readMeshPly(d / "mesh.ply");
    for (const auto& v : mesh.vertices) require(v.allFinite(), "mesh vertex not finite");
    for (const auto& t : mesh.triangles)
      for (std::uint32_t i : t) require(i < mesh.vertices.size(), "triangle index out of range");
  }));
}

}  // namespace gvio::fuzz
