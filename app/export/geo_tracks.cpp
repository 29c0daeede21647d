#include "export/geo_tracks.hpp"

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <chrono>
#include <memory>
#include <vector>

#include "export/gdal_support.hpp"
#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "odometry/error.hpp"

namespace gvio::exporter {
namespace {
namespace fs = std::filesystem;

struct UtcTime {
  int year, month, day, hour, minute;
  float second;
};

UtcTime utc(std::int64_t t_ns) {
  using namespace std::chrono;
  const sys_time<nanoseconds> t{nanoseconds(t_ns)};
  const sys_days day = floor<days>(t);
  const year_month_day ymd(day);
  const hh_mm_ss<nanoseconds> hms(t - day);
  return {
      static_cast<int>(ymd.year()),
      static_cast<int>(static_cast<unsigned>(ymd.month())),
      static_cast<int>(static_cast<unsigned>(ymd.day())),
      static_cast<int>(hms.hours().count()),
      static_cast<int>(hms.minutes().count()),
      static_cast<float>(static_cast<double>((hms.seconds() + hms.subseconds()).count()) * 1e-9)};
}

void setTime(OGRFeature& f, const char* field, std::int64_t t_ns) {
  const UtcTime u = utc(t_ns);
  f.SetField(field, u.year, u.month, u.day, u.hour, u.minute, u.second, 100);  // 100 = UTC
}

struct DatasetCloser {
  void operator()(GDALDataset* ds) const { GDALClose(ds); }
};
using DatasetPtr = std::unique_ptr<GDALDataset, DatasetCloser>;

// Opens a dataset on the temporary file with the named driver.
DatasetPtr create(const char* driver_name, const fs::path& tmp, const fs::path& file,
                  const GdalErrorCapture& errors, char** options = nullptr) {
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(driver_name);
  if (driver == nullptr) throw InvalidInput(std::string("GDAL has no ") + driver_name + " driver");
  DatasetPtr ds(driver->Create(tmp.c_str(), 0, 0, 0, GDT_Unknown, options));
  if (!ds) throw io::InputError(file, 0, "cannot write: " + errors.lastMessage());
  return ds;
}

OGRLayer* addLayer(GDALDataset& ds, const char* name, OGRwkbGeometryType type, const fs::path& file,
                   const GdalErrorCapture& errors, char** options = nullptr) {
  OGRSpatialReference wgs84;
  wgs84.importFromEPSG(4326);
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);  // x = lon, y = lat
  OGRLayer* layer = ds.CreateLayer(name, &wgs84, type, options);
  if (layer == nullptr)
    throw io::InputError(file, 0, "cannot create layer: " + errors.lastMessage());
  return layer;
}

void addField(OGRLayer& layer, const char* name, OGRFieldType type) {
  OGRFieldDefn defn(name, type);
  if (layer.CreateField(&defn) != OGRERR_NONE) {
    throw std::runtime_error(std::string("OGR: cannot create field ") + name);
  }
}

void addFeature(OGRLayer& layer, OGRFeature& feature, const fs::path& file,
                const GdalErrorCapture& errors) {
  if (layer.CreateFeature(&feature) != OGRERR_NONE) {
    throw io::InputError(file, 0, "cannot write feature: " + errors.lastMessage());
  }
}

OGRLineString line(std::span<const TrackPoint> track, const std::vector<double>& heights) {
  OGRLineString l;
  for (std::size_t i = 0; i < track.size(); ++i) {
    l.addPoint(track[i].lla.lon_deg, track[i].lla.lat_deg, heights[i]);
  }
  return l;
}

std::vector<double> ellipsoidalHeights(std::span<const TrackPoint> track) {
  std::vector<double> h;
  for (const auto& p : track) h.push_back(p.lla.h_ellipsoid_m);
  return h;
}

std::vector<double> geoidHeights(std::span<const TrackPoint> track) {
  std::vector<fusion::Lla> lla;
  for (const auto& p : track) lla.push_back(p.lla);
  return egm96HeightsM(lla);
}

void writeGeoJson(GDALDataset& ds, std::span<const TrackPoint> track, const std::string& name,
                  const fs::path& file, const GdalErrorCapture& errors) {
  const char* options[] = {"RFC7946=YES", "COORDINATE_PRECISION=9", nullptr};
  OGRLayer* layer =
      addLayer(ds, "trajectory", wkbLineString25D, file, errors, const_cast<char**>(options));
  addField(*layer, "name", OFTString);
  addField(*layer, "start_time", OFTDateTime);
  addField(*layer, "end_time", OFTDateTime);
  addField(*layer, "t_s", OFTRealList);
  OGRFeature feature(layer->GetLayerDefn());
  feature.SetField("name", name.c_str());
  setTime(feature, "start_time", track.front().t_ns);
  setTime(feature, "end_time", track.back().t_ns);
  std::vector<double> t_s;
  for (const auto& p : track) t_s.push_back(static_cast<double>(p.t_ns) / 1e9);
  feature.SetField("t_s", static_cast<int>(t_s.size()), t_s.data());
  OGRLineString geometry = line(track, ellipsoidalHeights(track));
  feature.SetGeometry(&geometry);
  addFeature(*layer, feature, file, errors);
}

void writeKml(GDALDataset& ds, bool libkml, std::span<const TrackPoint> track,
              const std::string& name, const fs::path& file, const GdalErrorCapture& errors) {
  OGRLayer* layer = addLayer(ds, "trajectory", wkbLineString25D, file, errors);
  // LIBKML maps these field names to <name>, <TimeSpan> and <altitudeMode>; the plain KML
  // driver knows only Name (its altitude mode is a dataset option).
  addField(*layer, libkml ? "name" : "Name", OFTString);
  if (libkml) {
    addField(*layer, "begin", OFTDateTime);
    addField(*layer, "end", OFTDateTime);
    addField(*layer, "altitudeMode", OFTString);
  }
  OGRFeature feature(layer->GetLayerDefn());
  feature.SetField(libkml ? "name" : "Name", name.c_str());
  if (libkml) {
    setTime(feature, "begin", track.front().t_ns);
    setTime(feature, "end", track.back().t_ns);
    feature.SetField("altitudeMode", "absolute");
  }
  OGRLineString geometry = line(track, geoidHeights(track));
  feature.SetGeometry(&geometry);
  addFeature(*layer, feature, file, errors);
}

// GDAL's GPX writer turns a "track_points" layer into <trk>/<trkseg>/<trkpt>, grouped by the
// track_fid and track_seg_id fields (GDAL GPX driver documentation).
void writeGpx(GDALDataset& ds, std::span<const TrackPoint> track, const std::string& name,
              const fs::path& file, const GdalErrorCapture& errors) {
  OGRLayer* layer = addLayer(ds, "track_points", wkbPoint, file, errors);
  addField(*layer, "track_fid", OFTInteger);
  addField(*layer, "track_seg_id", OFTInteger);
  addField(*layer, "track_name", OFTString);
  addField(*layer, "ele", OFTReal);
  addField(*layer, "time", OFTDateTime);
  const std::vector<double> ele = geoidHeights(track);
  for (std::size_t i = 0; i < track.size(); ++i) {
    OGRFeature feature(layer->GetLayerDefn());
    feature.SetField("track_fid", 0);
    feature.SetField("track_seg_id", 0);
    feature.SetField("track_name", name.c_str());
    feature.SetField("ele", ele[i]);
    setTime(feature, "time", track[i].t_ns);
    OGRPoint point(track[i].lla.lon_deg, track[i].lla.lat_deg);
    feature.SetGeometry(&point);
    addFeature(*layer, feature, file, errors);
  }
}

const char* extension(TrackFormat format) {
  switch (format) {
    case TrackFormat::kGeoJson:
      return ".geojson";
    case TrackFormat::kKml:
      return ".kml";
    case TrackFormat::kGpx:
      return ".gpx";
  }
  return "";
}

}  // namespace

void writeTrack(const fs::path& file, std::span<const TrackPoint> track, TrackFormat format,
                const std::string& name) {
  if (track.empty()) throw InvalidInput(file.string() + ": no poses to write");
  for (const auto& p : track) {
    if (!fusion::isValidLla(p.lla)) throw InvalidInput(file.string() + ": invalid lat/lon/h");
  }
  registerGdal();
  const GdalErrorCapture errors;
  io::writeViaPathAtomic(file, extension(format), [&](const fs::path& tmp) {
    // The name was reserved exclusively; it is freed for GDAL, whose drivers refuse to create a
    // dataset over an existing file (the name stays unique: PID and a random part). LIBKML may
    // leave a folder under it on failure, which writeViaPathAtomic removes too.
    fs::remove(tmp);
    {
      const bool libkml = GetGDALDriverManager()->GetDriverByName("LIBKML") != nullptr;
      const char* driver = format == TrackFormat::kGeoJson ? "GeoJSON"
                           : format == TrackFormat::kGpx   ? "GPX"
                           : libkml                        ? "LIBKML"
                                                           : "KML";
      const char* kml_options[] = {"AltitudeMode=absolute", nullptr};
      DatasetPtr ds = create(
          driver, tmp, file, errors,
          format == TrackFormat::kKml && !libkml ? const_cast<char**>(kml_options) : nullptr);
      switch (format) {
        case TrackFormat::kGeoJson:
          writeGeoJson(*ds, track, name, file, errors);
          break;
        case TrackFormat::kKml:
          writeKml(*ds, libkml, track, name, file, errors);
          break;
        case TrackFormat::kGpx:
          writeGpx(*ds, track, name, file, errors);
          break;
      }
      CPLErrorReset();
    }  // closing the dataset writes the file out
    if (CPLGetLastErrorType() >= CE_Failure || !fs::exists(tmp)) {
      throw io::InputError(file, 0, "write failed: " + errors.lastMessage());
    }
  });
}

}  // namespace gvio::exporter
