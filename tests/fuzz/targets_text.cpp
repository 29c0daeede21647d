// Fuzz targets for the one-file text readers: trajectories, GNSS files, run-folder files,
// configuration and Kalibr YAML.
#include <fmt/format.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli/config.hpp"
#include "export/georef.hpp"
#include "fuzz/checks.hpp"
#include "fuzz/harness.hpp"
#include "fuzz/targets_list.hpp"
#include "io/euroc.hpp"
#include "io/intervals.hpp"
#include "io/kalibr.hpp"
#include "io/kalibr_writer.hpp"
#include "io/loops_csv.hpp"
#include "io/nmea.hpp"
#include "io/rtklib_pos.hpp"
#include "io/run_dir.hpp"
#include "io/run_sources.hpp"
#include "io/trajectory_io.hpp"
#include "support/fixtures.hpp"

namespace gvio::fuzz {

namespace fs = std::filesystem;
using io::StampOrder;
using io::TrajectoryFormat;

namespace {

// A file of its own: prepare() writes `seed` as `name`.

// A 3-pose trajectory: stamps, then positions and unit quaternions.
Trajectory smallTrajectory() {
  Trajectory t;
  for (int i = 0; i < 3; ++i) {
    t.t_ns.push_back(1'317'000'000'000'000'000 + i * 100'000'000LL);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(1.5 * i, 0.2 * i, 0.01);
    t.poses.push_back(T);
  }
  return t;
}

std::string trajectoryText(TrajectoryFormat format) {
  const fs::path tmp = fs::temp_directory_path() / fmt::format("gvio-fuzz-seed-{}", ::getpid());
  const Trajectory t = smallTrajectory();
  if (format == TrajectoryFormat::kTum) io::writeTum(tmp, t);
  if (format == TrajectoryFormat::kKitti) io::writeKitti(tmp, t);
  if (format == TrajectoryFormat::kEuroc) io::writeEurocCsv(tmp, t);
  std::string text = test::readText(tmp);
  fs::remove(tmp);
  return text;
}

// Reads as `gvio eval` does (stamps as given) and as the datasets do (strictly increasing).
Target trajectoryTarget(std::string name, TrajectoryFormat format, std::string file) {
  // KITTI's R is used as written (as evo does), within the reader's 1e-3.
  const double tolerance = format == TrajectoryFormat::kKitti ? 1e-3 : 1e-6;
  return plain(std::move(name), file, trajectoryText(format), [=](const fs::path& d) {
    checkTrajectory(io::readTrajectory(d / file, format, std::nullopt, StampOrder::kAsGiven), false,
                    tolerance);
    checkTrajectory(io::readTrajectory(d / file, format), true, tolerance);
  });
}

constexpr const char* kNmea =
    "$GPGGA,123519.00,4807.0380,N,01131.0000,E,1,08,0.9,545.4,M,46.9,M,,*69\n"
    "$GPRMC,123519.00,A,4807.0380,N,01131.0000,E,022.4,084.4,230394,003.1,W*44\n"
    "$GPGST,123519.00,0.006,0.023,0.020,273.6,0.023,0.020,0.031*5E\n"
    "$GPGGA,123520.00,4807.0390,N,01131.0010,E,4,08,0.9,545.5,M,46.9,M,,*67\n"
    "$GPRMC,123520.00,A,4807.0390,N,01131.0010,E,022.4,084.4,230394,003.1,W*4E\n";

constexpr const char* kPos =
    "% program   : RTKPOST ver.2.4.3\n"
    "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of "
    "satellites)\n"
    "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   sde(m)   "
    "sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio\n"
    "2019/03/04 01:02:03.000   35.681234567  139.767123456    40.1234   1  12   0.0030   0.0025   "
    "0.0080   0.0001   0.0002  -0.0003   0.00  999.9\n"
    "2019/03/04 01:02:03.200   35.681234600  139.767123500    40.1240   5   9   1.2000   1.1000   "
    "2.5000   0.0100   0.0200  -0.0300   0.00    0.0\n";

constexpr const char* kGnssCsv =
    "#timestamp [ns],lat [deg],lon [deg],h [m],sigma_h [m],sigma_v [m]\n"
    "1403715273262142976,47.3667,8.55,500.0,1.5,3.0\n"
    "1403715274262142976,47.3668,8.5501,500.5,1.2,2.5\n";

constexpr const char* kLoopsCsv =
    "query_t_s,candidate_t_s,distance_m,search_radius_m,matches,inliers,reprojection_px,"
    "correction_m,correction_deg,verdict,reason\n"
    "12.100000000,1.000000000,2.5,10.0,80,40,0.8,0.3,0.5,accepted,ok\n"
    "12.200000000,1.100000000,2.4,10.0,20,0,nan,nan,nan,rejected,few_matches\n";

constexpr const char* kGnssFixes =
    "t_s,e_m,n_m,u_m,status\n0.100000000,1.0,2.0,0.5,used\n0.200000000,nan,nan,nan,skipped\n";

constexpr const char* kReport =
    R"({"gvio_version":"0.1.0","outages":[{"t0_s":1.5,"t1_s":3.0}],"loops":{"accepted":1}})"
    "\n";

constexpr const char* kReportSources =
    R"({"mode":"stereo-imu","sources":{"dataset":"/data/drive","format":"euroc",)"
    R"("calib_files":["/data/camchain.yaml","/data/imu.yaml"],"gnss_file":null}})"
    "\n";

constexpr const char* kGeoref =
    R"({"enu_origin":{"lat_deg":48.98253,"lon_deg":8.39035,"h_ellipsoid_m":116.4},)"
    R"("utm":{"zone":32,"north":true}})"
    "\n";

constexpr const char* kNoise =
    "white_h_m: 0.8\nwhite_v_m: 1.5\nbias_m: 0.6\nbias_tau_s: 60\noutlier_probability: 0.01\n"
    "quality: 1\n";

}  // namespace

Target plain(std::string name, std::string file, std::string seed,
             std::function<void(const fs::path&)> read) {
  std::string path = file;
  return Target{
      std::move(name), std::move(file),
      [seed = std::move(seed), path](const fs::path& dir) { test::writeText(dir / path, seed); },
      std::move(read), ""};
}

std::string smallCamchainYaml() {
  CameraModel c;
  c.name = "cam0";
  c.width_px = 32;
  c.height_px = 16;
  c.fx = 20.0;
  c.fy = 21.0;
  c.cx = 16.0;
  c.cy = 8.0;
  c.distortion = {0.01, -0.002, 0.0001, 0.0002};
  CameraModel r = c;
  r.name = "cam1";
  r.T_b_c.translation() = Eigen::Vector3d(0.0, -0.5, 0.0);
  return io::kalibrCamchainYaml({c, r}, {"/cam0/image_raw", "/cam1/image_raw"}, 0.004);
}

void addTextTargets(std::vector<Target>& out) {
  out.push_back(trajectoryTarget("traj_tum", TrajectoryFormat::kTum, "traj.tum"));
  out.push_back(trajectoryTarget("traj_kitti", TrajectoryFormat::kKitti, "poses.txt"));
  out.push_back(trajectoryTarget("traj_euroc", TrajectoryFormat::kEuroc, "data.csv"));
  out.push_back(plain("nmea", "fixes.nmea", kNmea, [](const fs::path& d) {
    checkFixes(io::readNmea(d / "fixes.nmea", io::ReaderConfig{}).fixes);
  }));
  out.push_back(plain("rtklib_pos", "solution.pos", kPos, [](const fs::path& d) {
    checkFixes(io::readRtklibPos(d / "solution.pos", io::ReaderConfig{}).fixes);
  }));
  out.push_back(plain("gnss_csv", "gnss.csv", kGnssCsv, [](const fs::path& d) {
    std::vector<std::string> warnings;
    checkFixes(io::readGnssCsv(d / "gnss.csv", warnings));
  }));
  out.push_back(plain("intervals", "outages.txt", "10.0 20.0\n# comment\n35.5 36.25\n",
                      [](const fs::path& d) {
                        for (const auto& [t0, t1] : io::readIntervals(d / "outages.txt"))
                          require(t1 > t0, "interval not positive");
                      }));
  out.push_back(plain("loops_csv", "loops.csv", kLoopsCsv,
                      [](const fs::path& d) { (void)io::readLoopsCsv(d / "loops.csv"); }));
  out.push_back(plain("gnss_fixes_csv", "gnss_fixes.csv", kGnssFixes,
                      [](const fs::path& d) { (void)io::readGnssFixes(d / "gnss_fixes.csv"); }));
  out.push_back(plain("report_json", "report.json", kReport, [](const fs::path& d) {
    for (const io::TimeSpan& s : io::readOutages(d / "report.json"))
      require(std::isfinite(s.t0_s) && std::isfinite(s.t1_s), "outage not finite");
  }));
  out.push_back(plain("report_sources", "report.json", kReportSources, [](const fs::path& d) {
    const io::RunSources s = io::readRunSources(d / "report.json");
    require(!s.mode.empty(), "empty mode accepted");
    if (s.dataset) require(!s.dataset->dataset.empty() && s.dataset->format, "empty source");
  }));
  out.push_back(plain("georef_json", "georef.json", kGeoref, [](const fs::path& d) {
    const exporter::Georef g = exporter::readGeoref(d / "georef.json");
    require(g.utm_zone >= 1 && g.utm_zone <= 60, "UTM zone out of range");
    checkFixes({GnssFix{0, g.enu_origin.lat_deg, g.enu_origin.lon_deg, g.enu_origin.h_ellipsoid_m,
                        1.0, 1.0}});
  }));
  out.push_back(plain("config_yaml", "config.yaml", cli::dumpConfigYaml(cli::AppConfig{}),
                      [](const fs::path& d) {
                        (void)cli::loadConfig(cli::ConfigSources{d / "config.yaml", {}});
                      }));
  // --set assignments, one per line of the input (what a user types on the command line).
  Target set = plain(
      "config_set", "set.txt",
      "vio.tracker.max_features=150\nfusion.lever_arm_b=[0,0,0.8]\nmap.dense.voxel_size_m=0.2\n",
      [](const fs::path& d) {
        std::ifstream in(d / "set.txt", std::ios::binary);
        cli::ConfigSources sources;
        for (std::string line; std::getline(in, line);) sources.overrides.push_back(line);
        (void)cli::loadConfig(sources);
      });
  set.names = "-";
  out.push_back(set);
  out.push_back(plain("gnss_noise_yaml", "noise.yaml", kNoise, [](const fs::path& d) {
    (void)cli::loadGnssNoiseModel((d / "noise.yaml").string());
  }));
  out.push_back(
      plain("kalibr_camchain", "camchain.yaml", smallCamchainYaml(), [](const fs::path& d) {
        const io::KalibrCalibration k = io::readKalibr({d / "camchain.yaml"});
        for (const CameraModel& c : k.cameras) checkCamera(c);
        require(std::isfinite(k.timeshift_cam_imu_s), "timeshift not finite");
      }));
  out.push_back(plain("kalibr_imu", "imu.yaml", io::kalibrImuYaml(ImuNoise{}, 200.0, "/imu0"),
                      [](const fs::path& d) {
                        const io::KalibrCalibration k = io::readKalibr({d / "imu.yaml"});
                        if (k.imu_noise) checkImuNoise(*k.imu_noise);
                      }));
}

}  // namespace gvio::fuzz
