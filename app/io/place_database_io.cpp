#include "io/place_database_io.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <type_traits>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"

namespace gvio::io {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMagic = "GVIOKFDB";
constexpr std::uint32_t kVersion = 3;  // 2: a fix quality per fix; 3: its ellipse's shape
constexpr std::size_t kDescriptorBytes = 32;
constexpr std::size_t kThumbnail =
    static_cast<std::size_t>(mapping::kThumbnailWidth) * mapping::kThumbnailHeight;

static_assert(std::endian::native == std::endian::little, "keyframes.bin is little-endian");

class Writer {
 public:
  template <typename T>
  void put(T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void bytes(const void* p, std::size_t n) { out_.append(static_cast<const char*>(p), n); }
  void pose(const Eigen::Isometry3d& T) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) put<double>(T.matrix()(r, c));
    }
  }
  [[nodiscard]] const std::string& data() const { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  Reader(const std::string& in, const fs::path& file) : in_(in), file_(file) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(file_, 0, "byte " + std::to_string(pos_) + ": " + what);
  }
  template <typename T>
  T get() {
    need(sizeof(T), 1);
    T v;
    std::memcpy(&v, in_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  double finite() {
    const std::size_t at = pos_;
    const auto v = get<double>();
    if (!std::isfinite(v)) failAt(at, "a value that is not finite");
    return v;
  }
  [[noreturn]] void failAt(std::size_t at, const std::string& what) {
    pos_ = at;  // errors name where the bad value starts
    fail(what);
  }
  // A count of items of `item_bytes` each that the bytes left can hold.
  std::size_t count(std::uint64_t n, std::size_t item_bytes) {
    need(item_bytes, n);
    return static_cast<std::size_t>(n);
  }
  void copy(void* dst, std::size_t n) {
    need(n, 1);
    std::memcpy(dst, in_.data() + pos_, n);
    pos_ += n;
  }
  Eigen::Isometry3d pose() {
    const std::size_t at = pos_;
    Eigen::Matrix<double, 3, 4> m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = finite();
    }
    const Eigen::Matrix3d R = m.leftCols<3>();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6 || R.determinant() < 0) {
      failAt(at, "a pose whose rotation is not a rotation");
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R;
    T.translation() = m.col(3);
    return T;
  }
  [[nodiscard]] std::size_t left() const { return in_.size() - pos_; }
  [[nodiscard]] std::size_t offset() const { return pos_; }

 private:
  void need(std::size_t item_bytes, std::uint64_t n) {
    if (item_bytes != 0 && n > left() / item_bytes) fail("the file ends early");
  }

  const std::string& in_;
  const fs::path& file_;
  std::size_t pos_ = 0;
};

void writeKeyframe(Writer& w, const mapping::LoopKeyframe& kf, const mapping::KeyframePrior& prior,
                   const Eigen::Isometry3d& T_vio) {
  w.put<std::int64_t>(kf.t_ns);
  w.pose(T_vio);
  w.pose(prior.T_ref_b);
  w.put<double>(prior.sigma_m);
  w.put<double>(prior.sigma_rot_deg);
  w.put<double>(prior.path_m);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(kf.px.size()));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(kf.points));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(kf.thumbnail.size()));
  for (const Eigen::Vector2f& p : kf.px) w.bytes(p.data(), 2 * sizeof(float));
  for (int r = 0; r < kf.descriptors.rows; ++r) w.bytes(kf.descriptors.ptr(r), kDescriptorBytes);
  for (std::size_t k = 0; k < kf.points; ++k) w.bytes(kf.p_c[k].data(), 3 * sizeof(float));
  w.bytes(kf.thumbnail.data(), kf.thumbnail.size() * sizeof(float));
}

template <int N>
void readFloats(Reader& r, float* dst) {
  const std::size_t at = r.offset();
  r.copy(dst, N * sizeof(float));
  for (int k = 0; k < N; ++k) {
    if (!std::isfinite(dst[k])) r.failAt(at, "a value that is not finite");
  }
}

void readKeyframe(Reader& r, mapping::PlaceDatabase& db) {
  mapping::LoopKeyframe kf;
  mapping::KeyframePrior prior;
  kf.t_ns = prior.t_ns = r.get<std::int64_t>();
  if (!db.priors.empty() && kf.t_ns <= db.priors.back().t_ns)
    r.fail("keyframe stamps must increase");
  const Eigen::Isometry3d T_vio = r.pose();
  prior.T_ref_b = r.pose();
  prior.sigma_m = r.get<double>();  // infinite without GNSS
  prior.sigma_rot_deg = r.get<double>();
  prior.path_m = r.finite();
  if (std::isnan(prior.sigma_m) || prior.sigma_m < 0.0 || std::isnan(prior.sigma_rot_deg) ||
      prior.sigma_rot_deg < 0.0) {
    r.fail("a negative or NaN sigma");
  }
  const auto keypoints = r.get<std::uint32_t>();
  const auto points = r.get<std::uint32_t>();
  const auto thumbnail = r.get<std::uint32_t>();
  if (points > keypoints) r.fail("more 3-D points than keypoints");
  if (thumbnail != 0 && thumbnail != kThumbnail) r.fail("a thumbnail of the wrong size");
  const std::size_t n = r.count(keypoints, 2 * sizeof(float) + kDescriptorBytes);
  kf.px.resize(n);
  for (Eigen::Vector2f& p : kf.px) readFloats<2>(r, p.data());
  kf.descriptors.create(static_cast<int>(n), static_cast<int>(kDescriptorBytes), CV_8U);
  if (n > 0) r.copy(kf.descriptors.data, n * kDescriptorBytes);
  kf.p_c.resize(r.count(points, 3 * sizeof(float)));
  for (Eigen::Vector3f& p : kf.p_c) readFloats<3>(r, p.data());
  kf.points = kf.p_c.size();
  kf.thumbnail.resize(r.count(thumbnail, sizeof(float)));
  for (float& v : kf.thumbnail) readFloats<1>(r, &v);
  db.keyframes.push_back(std::move(kf));
  db.priors.push_back(prior);
  db.T_vio.push_back(T_vio);
}

void readFix(Reader& r, mapping::PlaceDatabase& db, std::uint32_t version) {
  fusion::GraphFix f;
  const auto node = r.get<std::uint64_t>();
  if (node >= db.keyframes.size()) r.fail("a fix on a keyframe that does not exist");
  f.node = static_cast<std::size_t>(node);
  f.t_ns = r.get<std::int64_t>();
  if (!db.fixes.empty() && f.t_ns < db.fixes.back().t_ns) r.fail("fix stamps must not decrease");
  for (int a = 0; a < 3; ++a) f.q_b(a) = r.finite();
  for (int a = 0; a < 3; ++a) f.p_enu(a) = r.finite();
  f.sigma_h_m = r.finite();
  f.sigma_v_m = r.finite();
  if (!(f.sigma_h_m > 0.0 && f.sigma_v_m > 0.0)) r.fail("a fix sigma that is not > 0");
  if (version >= 2) {
    f.quality = r.get<std::int32_t>();
    if (f.quality < 0 || f.quality > 9) r.fail("a fix quality that is not 0..9");
  }
  if (version >= 3) {
    const double ee = r.finite(), nn = r.finite(), en = r.finite();
    f.shape_en << ee, en, en, nn;
    // What horizontalShape writes: positive definite, trace 2 (a file's rounding allowed).
    if (!(ee > 0.0 && nn > 0.0 && ee * nn - en * en > 0.0 && std::abs(ee + nn - 2.0) < 1e-9)) {
      r.fail("a fix ellipse shape that is not positive definite with trace 2");
    }
  }
  db.fixes.push_back(f);
}

void readLoop(Reader& r, mapping::PlaceDatabase& db) {
  fusion::GraphLoop l;
  const auto i = r.get<std::uint64_t>();
  const auto j = r.get<std::uint64_t>();
  if (i >= db.keyframes.size() || j >= db.keyframes.size() || i == j) {
    r.fail("a loop between keyframes that do not exist");
  }
  l.i = static_cast<std::size_t>(i);
  l.j = static_cast<std::size_t>(j);
  l.T_i_j = r.pose();
  for (int a = 0; a < 6; ++a) {
    for (int b = 0; b < 6; ++b) l.covariance(a, b) = r.finite();
  }
  const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(l.covariance);
  if (llt.info() != Eigen::Success || !l.covariance.isApprox(l.covariance.transpose())) {
    r.fail("a loop covariance that is not symmetric positive definite");
  }
  db.loops.push_back(l);
}

}  // namespace

void writePlaceDatabase(const fs::path& file, const mapping::PlaceDatabase& db) {
  Writer w;
  w.bytes(kMagic.data(), kMagic.size());
  w.put<std::uint32_t>(kVersion);
  w.put<std::uint32_t>(db.has_imu ? 1U : 0U);
  w.put<std::int32_t>(db.camera.width_px);
  w.put<std::int32_t>(db.camera.height_px);
  for (const double v : {db.camera.fx, db.camera.fy, db.camera.cx, db.camera.cy}) w.put(v);
  w.pose(db.camera.T_b_c);
  w.put<std::uint64_t>(db.keyframes.size());
  w.put<std::uint64_t>(db.fixes.size());
  w.put<std::uint64_t>(db.loops.size());
  for (std::size_t k = 0; k < db.keyframes.size(); ++k) {
    writeKeyframe(w, db.keyframes[k], db.priors[k], db.T_vio[k]);
  }
  for (const fusion::GraphFix& f : db.fixes) {
    w.put<std::uint64_t>(f.node);
    w.put<std::int64_t>(f.t_ns);
    for (int a = 0; a < 3; ++a) w.put<double>(f.q_b(a));
    for (int a = 0; a < 3; ++a) w.put<double>(f.p_enu(a));
    w.put<double>(f.sigma_h_m);
    w.put<double>(f.sigma_v_m);
    w.put<std::int32_t>(f.quality);
    for (const double v : {f.shape_en(0, 0), f.shape_en(1, 1), f.shape_en(0, 1)}) w.put<double>(v);
  }
  for (const fusion::GraphLoop& l : db.loops) {
    w.put<std::uint64_t>(l.i);
    w.put<std::uint64_t>(l.j);
    w.pose(l.T_i_j);
    for (int a = 0; a < 6; ++a) {
      for (int b = 0; b < 6; ++b) w.put<double>(l.covariance(a, b));
    }
  }
  writeFileAtomic(file, [&](std::ostream& os) {
    os.write(w.data().data(), static_cast<std::streamsize>(w.data().size()));
  });
}

mapping::PlaceDatabase parsePlaceDatabase(const std::string& bytes, const fs::path& file) {
  Reader r(bytes, file);
  char magic[8];
  if (bytes.size() < kMagic.size()) r.fail("not a gvio keyframe database (too short)");
  r.copy(magic, sizeof(magic));
  if (std::string_view(magic, sizeof(magic)) != kMagic) r.fail("not a gvio keyframe database");
  const auto version = r.get<std::uint32_t>();
  if (version < 1 || version > kVersion) r.fail("a version this gvio does not read");
  mapping::PlaceDatabase db;
  db.has_imu = (r.get<std::uint32_t>() & 1U) != 0;
  CameraModel& cam = db.camera;
  cam.width_px = r.get<std::int32_t>();
  cam.height_px = r.get<std::int32_t>();
  cam.fx = r.finite();
  cam.fy = r.finite();
  cam.cx = r.finite();
  cam.cy = r.finite();
  if (cam.width_px <= 0 || cam.height_px <= 0 || !(cam.fx > 0.0 && cam.fy > 0.0)) {
    r.fail("a camera without a size or focal length");
  }
  cam.T_b_c = r.pose();
  const auto keyframes = r.get<std::uint64_t>();
  const auto fixes = r.get<std::uint64_t>();
  const auto loops = r.get<std::uint64_t>();
  // The smallest record of each kind bounds the counts before anything is allocated.
  const std::size_t n_kf = r.count(keyframes, 8 + 24 * 8 + 3 * 8 + 3 * 4);
  for (std::size_t k = 0; k < n_kf; ++k) readKeyframe(r, db);
  const std::size_t n_fix =
      r.count(fixes, 2 * 8 + 8 * 8 + (version >= 2 ? 4 : 0) + (version >= 3 ? 3 * 8 : 0));
  for (std::size_t k = 0; k < n_fix; ++k) readFix(r, db, version);
  const std::size_t n_loop = r.count(loops, 2 * 8 + 48 * 8);
  for (std::size_t k = 0; k < n_loop; ++k) readLoop(r, db);
  if (r.left() != 0) r.fail("bytes after the last record");
  return db;
}

mapping::PlaceDatabase readPlaceDatabase(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, 0, "cannot open the file");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file, 0, "cannot read the file");
  return parsePlaceDatabase(bytes, file);
}

}  // namespace gvio::io
