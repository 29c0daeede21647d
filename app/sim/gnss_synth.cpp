#include "sim/gnss_synth.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "fusion/gnss_covariance.hpp"
#include "io/gps_time.hpp"
#include "io/nmea.hpp"
#include "odometry/error.hpp"

namespace gvio::sim {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;
constexpr std::int64_t kNsPerDay = 86'400 * kNsPerSecond;
// GGA altitude is above the geoid; the simulator has no geoid model, so it writes a constant
// separation and the altitude that makes altitude + separation the simulated ellipsoidal height.
constexpr double kGeoidSeparationM = 47.0;
// Period of the slow HDOP / satellite-count variation (constellation geometry changes in minutes).
constexpr double kGeometryPeriodS = 900.0;

std::int64_t periodNs(double rate_hz) {
  if (rate_hz != 1.0 && rate_hz != 5.0 && rate_hz != 10.0) {
    throw InvalidInput(fmt::format("GNSS rate must be 1, 5 or 10 Hz (got {})", rate_hz));
  }
  return static_cast<std::int64_t>(std::llround(1e9 / rate_hz));
}

bool inOutage(std::int64_t t_ns, const GnssSimOptions& options) {
  for (const auto& [a, b] : options.outages_ns) {
    if (t_ns >= a && t_ns <= b) return true;
  }
  return false;
}

struct Geometry {
  double hdop = 0.0;
  int num_sats = 0;
};

// HDOP and the satellite count follow the constellation geometry: one slow sinusoid (random phase)
// drives both, fewer satellites going with a higher HDOP. HDOP is rounded to the 0.1 that GGA
// carries, so a written and re-read log reproduces it.
Geometry geometryAt(const GnssErrorModel& m, double t_s, double phase) {
  const double poor = 0.5 + 0.5 * std::sin(2.0 * std::numbers::pi * t_s / kGeometryPeriodS + phase);
  Geometry g;
  g.hdop = std::round((m.hdop_min + poor * (m.hdop_max - m.hdop_min)) * 10.0) / 10.0;
  g.num_sats = m.sats_max - static_cast<int>(std::lround(poor * (m.sats_max - m.sats_min)));
  return g;
}

GnssFix reportedFix(std::int64_t t_ns, const Eigen::Vector3d& p_enu, const Geometry& geometry,
                    const GnssErrorModel& m, const fusion::EnuFrame& enu) {
  GnssFix fix;
  fix.t_ns = t_ns;
  reportAs(fix, enu.toLla(p_enu), m);
  fix.hdop = geometry.hdop;
  fix.num_sats = geometry.num_sats;
  return fix;
}

// "hhmmss.ss" UTC; more decimals (up to 9) only when the time is not on a 10 ms grid, so any
// nanosecond time stamp survives a write/read round trip.
std::string timeOfDay(std::int64_t t_ns) {
  const std::int64_t tod = ((t_ns % kNsPerDay) + kNsPerDay) % kNsPerDay;
  const std::int64_t s = tod / kNsPerSecond;
  std::string text =
      fmt::format("{:02}{:02}{:02}.{:09}", s / 3600, s / 60 % 60, s % 60, tod % kNsPerSecond);
  while (text.size() > 9 && text.back() == '0') text.pop_back();
  return text;
}

struct CivilDate {
  std::int64_t year, month, day;
};

// The UTC calendar date of a Unix time (H. Hinnant's civil_from_days, the inverse of
// io::daysFromCivil).
CivilDate civilDateOf(std::int64_t t_ns) {
  const std::int64_t days = (t_ns >= 0 ? t_ns : t_ns - kNsPerDay + 1) / kNsPerDay;
  const std::int64_t z = days + 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const std::int64_t doe = z - era * 146097;
  const std::int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const std::int64_t mp = (5 * doy + 2) / 153;
  const std::int64_t day = doy - (153 * mp + 2) / 5 + 1;
  const std::int64_t month = mp < 10 ? mp + 3 : mp - 9;
  return {yoe + era * 400 + (month <= 2 ? 1 : 0), month, day};
}

// "ddmmyy" UTC of a Unix time.
std::string dateOf(std::int64_t t_ns) {
  const CivilDate d = civilDateOf(t_ns);
  return fmt::format("{:02}{:02}{:02}", d.day, d.month, ((d.year % 100) + 100) % 100);
}

// "yyyy/mm/dd hh:mm:ss.sss" as RTKLIB writes its times; more decimals (up to 9) only when the
// time is not on a 1 ms grid.
std::string calendarTime(std::int64_t t_ns) {
  const CivilDate d = civilDateOf(t_ns);
  const std::int64_t tod = ((t_ns % kNsPerDay) + kNsPerDay) % kNsPerDay;
  const std::int64_t s = tod / kNsPerSecond;
  std::string text = fmt::format("{:04}/{:02}/{:02} {:02}:{:02}:{:02}.{:09}", d.year, d.month,
                                 d.day, s / 3600, s / 60 % 60, s % 60, tod % kNsPerSecond);
  while (text.size() > 23 && text.back() == '0') text.pop_back();
  return text;
}

// "ddmm.mmmmmmm,N" / "dddmm.mmmmmmm,E": minutes rounded to 1e-7 (0.2 mm) in integers, so rounding
// up to 60 minutes carries into the degrees instead of printing "60.0000000".
std::string coordinate(double deg, int degree_digits, char positive, char negative) {
  constexpr std::int64_t kUnitsPerMinute = 10'000'000;
  const std::int64_t units = std::llround(std::abs(deg) * 60.0 * kUnitsPerMinute);
  const std::int64_t minutes = units % (60 * kUnitsPerMinute);
  return fmt::format("{:0{}}{:02}.{:07},{}", units / (60 * kUnitsPerMinute), degree_digits,
                     minutes / kUnitsPerMinute, minutes % kUnitsPerMinute,
                     deg < 0.0 ? negative : positive);
}

std::string latLon(const GnssFix& fix) {
  return coordinate(fix.lat_deg, 2, 'N', 'S') + "," + coordinate(fix.lon_deg, 3, 'E', 'W');
}

std::string ggaBody(const GnssFix& fix, const std::string& time) {
  return fmt::format("GPGGA,{},{},{},{:02},{:.1f},{:.3f},M,{:.3f},M,,", time, latLon(fix),
                     fix.quality, fix.num_sats, fix.hdop, fix.h_ellipsoid_m - kGeoidSeparationM,
                     kGeoidSeparationM);
}

// Speed and course are not known from positions alone; 0.0 is a valid value for both.
std::string rmcBody(const GnssFix& fix, const std::string& time) {
  return fmt::format("GPRMC,{},A,{},0.0,0.0,{},,,A", time, latLon(fix), dateOf(fix.t_ns));
}

// The shortest text that reads back as the same double ("1.5", "0.02"), with a decimal point kept
// ("3.0", not "3") as NMEA fields usually show one.
std::string exactDecimal(double value) {
  std::string text = fmt::format("{}", value);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

// GST carries the sigmas GGA lacks (rms, error ellipse, lat/lon/alt sigma), written exactly so a
// reader recovers the reported sigmas: a circle of the horizontal sigma, or the fix's ellipse
// (a replayed receiver's) with its semi-axes, orientation and the latitude and longitude sigmas.
std::string gstBody(const GnssFix& fix, const std::string& time) {
  const std::string h = exactDecimal(fix.sigma_h_m);
  const std::string v = exactDecimal(fix.sigma_v_m);
  if (fix.shape_en == Eigen::Matrix2d::Identity()) {
    return fmt::format("GPGST,{},{},{},{},0.0,{},{},{}", time, h, h, h, h, h, v);
  }
  const Eigen::Matrix2d cov_en = fix.sigma_h_m * fix.sigma_h_m * fix.shape_en;
  const fusion::Ellipse e = fusion::ellipseOf(cov_en);
  return fmt::format("GPGST,{},{},{},{},{},{},{},{}", time, h, exactDecimal(e.major_m),
                     exactDecimal(e.minor_m), exactDecimal(e.orientation_deg),
                     exactDecimal(std::sqrt(cov_en(1, 1))), exactDecimal(std::sqrt(cov_en(0, 0))),
                     v);
}

}  // namespace

std::vector<GnssSimFix> synthesizeGnss(
    const std::function<Eigen::Isometry3d(std::int64_t)>& T_w_b_at, std::int64_t t0_ns,
    std::int64_t t1_ns, const fusion::EnuFrame& enu, const GnssSimOptions& options,
    std::uint64_t seed) {
  const std::int64_t period_ns = periodNs(options.rate_hz);
  const GnssErrorModel model = GnssErrorModel::preset(options.noise);
  GnssErrorProcess errors(model, seed, t0_ns);
  std::vector<GnssSimFix> fixes;
  for (std::int64_t t_ns = t0_ns; t_ns <= t1_ns; t_ns += period_ns) {
    if (inOutage(t_ns, options)) continue;
    GnssSimFix sim;
    sim.p_enu_true = T_w_b_at(t_ns) * options.lever_arm_b;
    sim.error_enu = errors.draw(t_ns, sim.outlier);
    const double t_s = static_cast<double>(t_ns - t0_ns) * 1e-9;
    sim.fix = reportedFix(t_ns, sim.p_enu_true + sim.error_enu,
                          geometryAt(model, t_s, errors.geometryPhase()), model, enu);
    fixes.push_back(sim);
  }
  return fixes;
}

std::string toNmeaLog(const std::vector<GnssFix>& fixes) {
  std::string log;
  for (const GnssFix& fix : fixes) {
    const std::string time = timeOfDay(fix.t_ns);
    for (const std::string& body : {ggaBody(fix, time), rmcBody(fix, time), gstBody(fix, time)}) {
      log += io::withNmeaChecksum(body) + "\r\n";
    }
  }
  return log;
}

std::string toRtklibPos(const std::vector<GnssFix>& fixes) {
  // RTKLIB's Q of an NMEA quality (the inverse of io::nmeaQualityOfRtklibQ).
  const auto q_of = [](int quality) {
    switch (quality) {
      case 4:
        return 1;  // RTK fixed -> fix
      case 5:
        return 2;  // RTK float -> float
      case 2:
        return 4;  // DGPS
      default:
        return 5;  // single
    }
  };
  std::string pos =
      "% program   : gvio simulate\n"
      "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns   sdn(m)   "
      "sde(m)   sdu(m)  sdne(m)  sdeu(m)  sdun(m) age(s)  ratio\n";
  for (const GnssFix& f : fixes) {
    // sdn, sde and sdne (RTKLIB writes a covariance as sign(c) sqrt(|c|)) of the fix's ellipse.
    const Eigen::Matrix2d cov_en = f.sigma_h_m * f.sigma_h_m * f.shape_en;
    const double sdne = std::copysign(std::sqrt(std::abs(cov_en(0, 1))), cov_en(0, 1));
    // GPST runs ahead of UTC by the leap seconds of that instant; io/gps_time.hpp's table is
    // indexed by GPST, so the offset read at UTC is read again at the GPST it gives.
    const std::int64_t utc_ahead_s = io::gpsMinusUtcSeconds(f.t_ns);
    const std::int64_t t_gpst =
        f.t_ns + io::gpsMinusUtcSeconds(f.t_ns + utc_ahead_s * kNsPerSecond) * kNsPerSecond;
    pos += fmt::format(
        "{} {:14.9f} {:14.9f} {:10.4f} {:3} {:3} {:8.4f} {:8.4f} {:8.4f} {:8.4f} {:8.4f} {:8.4f} "
        "{:6.2f} {:6.1f}\n",
        calendarTime(t_gpst), f.lat_deg, f.lon_deg, f.h_ellipsoid_m, q_of(f.quality), f.num_sats,
        std::sqrt(cov_en(1, 1)), std::sqrt(cov_en(0, 0)), f.sigma_v_m, sdne, 0.0, 0.0, 0.0, 0.0);
  }
  return pos;
}

std::string toGnssCsv(const std::vector<GnssFix>& fixes) {
  std::string csv = "#timestamp [ns],lat_deg,lon_deg,height_m,sigma_h_m,sigma_v_m\n";
  for (const GnssFix& f : fixes) {
    csv += fmt::format("{},{:.10f},{:.10f},{:.4f},{:.4f},{:.4f}\n", f.t_ns, f.lat_deg, f.lon_deg,
                       f.h_ellipsoid_m, f.sigma_h_m, f.sigma_v_m);
  }
  return csv;
}

}  // namespace gvio::sim
