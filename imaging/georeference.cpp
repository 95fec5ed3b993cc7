#include "imaging/georeference.h"

#include <cmath>
#include <cstdio>

#include <GeographicLib/AzimuthalEquidistant.hpp>
#include <GeographicLib/Geodesic.hpp>

#include "pipeline/error.h"

namespace floesim::imaging {

GeoReference georeference_from(const std::vector<double>& v) {
  const std::string problem = georeference_problem(v);
  FLOESIM_REQUIRE(problem.empty(), "internal: digitise.georeference ", problem);
  return {v[0], v[1], v[2]};
}

std::array<double, 2> image_to_wgs84(const GeoReference& g, double width_m, double height_m, double x_m, double y_m) {
  // Offsets from the centre along the image's right and up axes, turned into east and north by the heading.
  const double dx = x_m - width_m / 2, dy = y_m - height_m / 2;
  const double h = g.heading_deg * M_PI / 180, east = dx * std::cos(h) + dy * std::sin(h),
               north = -dx * std::sin(h) + dy * std::cos(h);
  static const GeographicLib::AzimuthalEquidistant map(GeographicLib::Geodesic::WGS84());
  double lat = 0, lon = 0, azimuth = 0, scale = 0;
  map.Reverse(g.latitude_deg, g.longitude_deg, east, north, lat, lon, azimuth, scale);
  return {lon, lat};
}

nlohmann::json floes_to_wgs84_geojson(const FloeField& field, const GeoReference& g) {
  nlohmann::json fc = floes_to_geojson(field);
  fc["crs"] = {{"type", "name"}, {"properties", {{"name", "urn:ogc:def:crs:OGC:1.3:CRS84"}}}};
  fc["floesim"]["format"] = "floesim-floes-wgs84/1";
  fc["floesim"]["crs"] = "WGS 84 longitude, latitude (degrees); from the image frame of floes.geojson";
  fc["floesim"]["georeference"] = {{"latitude_deg", g.latitude_deg},
                                   {"longitude_deg", g.longitude_deg},
                                   {"heading_deg", g.heading_deg}};
  for (nlohmann::json& feature : fc["features"])
    for (nlohmann::json& vertex : feature["geometry"]["coordinates"][0]) {
      const auto ll = image_to_wgs84(g, field.width_m, field.height_m, vertex[0].get<double>(), vertex[1].get<double>());
      vertex = {ll[0], ll[1]};
    }
  return fc;
}

WorldFile raster_world_file(double width_m, double height_m, double mpp, const GeoReference* g) {
  // The top-left pixel's centre in the image frame (x right, y up from the bottom-left corner).
  const double x0 = 0.5 * mpp, y0 = height_m - 0.5 * mpp;
  double a = mpp, d = 0, b = 0, e = -mpp, c = x0, f = y0;
  WorldFile w;
  if (!g) {
    w.prj = kLocalMetresCrs;
  } else {
    // East and north of the image point (x, y): its offsets from the centre turned by the heading (image_to_wgs84).
    const double h = g->heading_deg * M_PI / 180, ch = std::cos(h), sh = std::sin(h);
    const double dx = x0 - width_m / 2, dy = y0 - height_m / 2;
    a = mpp * ch, d = -mpp * sh, b = -mpp * sh, e = -mpp * ch;
    c = dx * ch + dy * sh, f = -dx * sh + dy * ch;
    char prj[768];
    std::snprintf(prj, sizeof prj,
                  "PROJCS[\"floesim image: azimuthal equidistant about its centre\",GEOGCS[\"GCS_WGS_1984\","
                  "DATUM[\"D_WGS_1984\",SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],"
                  "UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Azimuthal_Equidistant\"],"
                  "PARAMETER[\"False_Easting\",0.0],PARAMETER[\"False_Northing\",0.0],"
                  "PARAMETER[\"Central_Meridian\",%.12g],PARAMETER[\"Latitude_Of_Origin\",%.12g],UNIT[\"Meter\",1.0]]",
                  g->longitude_deg, g->latitude_deg);
    w.prj = prj;
  }
  char pgw[256];
  std::snprintf(pgw, sizeof pgw, "%.15g\n%.15g\n%.15g\n%.15g\n%.15g\n%.15g\n", a, d, b, e, c, f);
  w.pgw = pgw;
  w.prj += "\n";
  return w;
}

}  // namespace floesim::imaging
