// GeoJSON / KML / GPX tracks read back through OGR; EGM96 heights against a published geoid value.
#include <gdal_priv.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <memory>

#include "export/gdal_support.hpp"
#include "export/geo_tracks.hpp"
#include "io/input_error.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using exporter::TrackFormat;
using exporter::TrackPoint;
using testing::HasSubstr;

constexpr std::int64_t kStartNs = 1'317'300'000'123'000'000LL;  // 2011-09-29T12:40:00.123Z

std::vector<TrackPoint> track(int n) {
  std::vector<TrackPoint> t;
  for (int i = 0; i < n; ++i) {
    t.push_back(
        {kStartNs + i * 100'000'000LL, {49.011 + 1e-5 * i, 8.4 + 2e-5 * i, 112.0 + 0.1 * i}});
  }
  return t;
}

struct Closer {
  void operator()(GDALDataset* ds) const { GDALClose(ds); }
};
std::unique_ptr<GDALDataset, Closer> openVector(const std::filesystem::path& file) {
  exporter::registerGdal();
  return std::unique_ptr<GDALDataset, Closer>(
      GDALDataset::Open(file.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
}

// The single LineString feature of a GeoJSON or KML track.
std::unique_ptr<OGRLineString> onlyLine(GDALDataset& ds) {
  EXPECT_EQ(ds.GetLayerCount(), 1);
  OGRLayer* layer = ds.GetLayer(0);
  EXPECT_EQ(layer->GetFeatureCount(), 1);
  std::unique_ptr<OGRFeature> f(layer->GetNextFeature());
  if (!f || f->GetGeometryRef() == nullptr ||
      wkbFlatten(f->GetGeometryRef()->getGeometryType()) != wkbLineString) {
    ADD_FAILURE() << "no LineString feature";
    return nullptr;
  }
  return std::unique_ptr<OGRLineString>(f->GetGeometryRef()->clone()->toLineString());
}

TEST(ExportGeoTracks, GeoJsonIsRfc7946WithEllipsoidalHeights) {
  TempDir dir("geojson");
  const auto t = track(50);
  exporter::writeTrack(dir.path() / "t.geojson", t, TrackFormat::kGeoJson, "drive");
  const std::string text = readText(dir.path() / "t.geojson");
  EXPECT_THAT(text, testing::Not(HasSubstr("\"crs\"")));  // RFC 7946 drops the crs member
  auto ds = openVector(dir.path() / "t.geojson");
  ASSERT_TRUE(ds);
  const auto line = onlyLine(*ds);
  ASSERT_TRUE(line);
  ASSERT_EQ(line->getNumPoints(), 50);
  for (int i = 0; i < 50; ++i) {
    EXPECT_NEAR(line->getX(i), t[i].lla.lon_deg, 1e-9);  // [lon, lat, h]
    EXPECT_NEAR(line->getY(i), t[i].lla.lat_deg, 1e-9);
    EXPECT_NEAR(line->getZ(i), t[i].lla.h_ellipsoid_m, 1e-6);
  }
  ds->GetLayer(0)->ResetReading();
  std::unique_ptr<OGRFeature> f(ds->GetLayer(0)->GetNextFeature());
  EXPECT_STREQ(f->GetFieldAsString("name"), "drive");
  int n = 0;
  const double* t_s = f->GetFieldAsDoubleList("t_s", &n);
  ASSERT_EQ(n, 50);
  EXPECT_NEAR(t_s[49], static_cast<double>(t[49].t_ns) * 1e-9, 1e-5);
}

// GeographicLib's GeoidEval documentation: 16:46:33N 3:00:34W has an EGM96 geoid height of
// 28.7068 m (egm96-5 grid); PROJ's 15' grid agrees to a few cm.
TEST(ExportGeoTracks, Egm96HeightsMatchPublishedGeoid) {
  const std::vector<fusion::Lla> timbuktu = {
      {16.0 + 46.0 / 60 + 33.0 / 3600, -(3.0 + 34.0 / 3600), 100.0}};
  const auto h = exporter::egm96HeightsM(timbuktu);
  ASSERT_EQ(h.size(), 1U);
  EXPECT_NEAR(100.0 - h[0], 28.7068, 0.05);
}

TEST(ExportGeoTracks, KmlIsOneAbsoluteLineAboveTheGeoid) {
  TempDir dir("kml");
  const auto t = track(30);
  exporter::writeTrack(dir.path() / "t.kml", t, TrackFormat::kKml);
  EXPECT_THAT(readText(dir.path() / "t.kml"), HasSubstr("absolute"));
  auto ds = openVector(dir.path() / "t.kml");
  ASSERT_TRUE(ds);
  const auto line = onlyLine(*ds);
  ASSERT_TRUE(line);
  ASSERT_EQ(line->getNumPoints(), 30);
  std::vector<fusion::Lla> lla;
  for (const auto& p : t) lla.push_back(p.lla);
  const auto geoid = exporter::egm96HeightsM(lla);
  for (int i = 0; i < 30; ++i) {
    EXPECT_NEAR(line->getX(i), t[i].lla.lon_deg, 1e-9);
    EXPECT_NEAR(line->getY(i), t[i].lla.lat_deg, 1e-9);
    EXPECT_NEAR(line->getZ(i), geoid[i], 1e-3);
    // Karlsruhe: the geoid is ~48 m above the ellipsoid.
    EXPECT_NEAR(t[i].lla.h_ellipsoid_m - line->getZ(i), 48.0, 1.0);
  }
}

TEST(ExportGeoTracks, GpxTrackPointsCarryTimeAndElevation) {
  TempDir dir("gpx");
  const auto t = track(40);
  exporter::writeTrack(dir.path() / "t.gpx", t, TrackFormat::kGpx, "drive");
  const std::string text = readText(dir.path() / "t.gpx");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n') > 0, true);
  EXPECT_THAT(text, HasSubstr("<trkseg>"));
  EXPECT_THAT(text, HasSubstr("<time>2011-09-29T12:40:00.123Z</time>"));
  auto ds = openVector(dir.path() / "t.gpx");
  ASSERT_TRUE(ds);
  OGRLayer* tracks = ds->GetLayerByName("tracks");
  ASSERT_NE(tracks, nullptr);
  EXPECT_EQ(tracks->GetFeatureCount(), 1);
  OGRLayer* points = ds->GetLayerByName("track_points");
  ASSERT_NE(points, nullptr);
  ASSERT_EQ(points->GetFeatureCount(), 40);
  int i = 0;
  for (auto& f : *points) {
    const OGRPoint* p = f->GetGeometryRef()->toPoint();
    EXPECT_NEAR(p->getX(), t[i].lla.lon_deg, 1e-9);
    EXPECT_NEAR(p->getY(), t[i].lla.lat_deg, 1e-9);
    EXPECT_NEAR(t[i].lla.h_ellipsoid_m - f->GetFieldAsDouble("ele"), 48.0, 1.0);
    int y = 0, mo = 0, d = 0, h = 0, mi = 0, tz = 0;
    float s = 0;
    ASSERT_TRUE(f->GetFieldAsDateTime(f->GetFieldIndex("time"), &y, &mo, &d, &h, &mi, &s, &tz));
    const double expected_s = 0.123 + 0.1 * i;  // seconds past 12:40:00
    EXPECT_EQ(y, 2011);
    EXPECT_EQ(mo, 9);
    EXPECT_EQ(d, 29);
    EXPECT_NEAR((h - 12) * 3600.0 + (mi - 40) * 60.0 + static_cast<double>(s), expected_s, 1e-3)
        << i;
    ++i;
  }
}

TEST(ExportGeoTracks, BadInput) {
  TempDir dir("geo_bad");
  for (const auto format : {TrackFormat::kGeoJson, TrackFormat::kKml, TrackFormat::kGpx}) {
    EXPECT_THROW(exporter::writeTrack("/nonexistent/dir/t.x", track(3), format), io::InputError);
    EXPECT_THROW(exporter::writeTrack(dir.path() / "t.x", {}, format), InvalidInput);
  }
  auto bad = track(3);
  bad[1].lla.lat_deg = 91.0;
  EXPECT_THROW(exporter::writeTrack(dir.path() / "t.gpx", bad, TrackFormat::kGpx), InvalidInput);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "no temporary left behind";
}

}  // namespace
}  // namespace gvio::test
