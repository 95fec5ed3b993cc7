// Where a digitised image lies on the Earth: its centre's latitude and longitude (WGS 84) and the heading of its
// up axis (degrees clockwise from true north), given in the case (digitise.georeference). The floes of
// floes.geojson are in the image's own metres (x right, y up, origin at the bottom-left corner: the frame the
// simulation works in); with a georeference they are also written in WGS 84 longitude and latitude
// (floes_wgs84.geojson, RFC 7946) so that a GIS (QGIS) places them on a map.
#pragma once
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/floes_io.h"

namespace floesim::imaging {

struct GeoReference {
  double latitude_deg = 0;   // the image centre
  double longitude_deg = 0;
  double heading_deg = 0;    // the image's up axis, clockwise from true north
};

// What is wrong with the option's value [latitude_deg, longitude_deg, heading_deg], "" if nothing (digitise's
// option check: three finite numbers, the latitude in [-90, 90], the longitude in [-180, 180]). Inline: the
// options header, which harnesses use without the imaging library, calls it.
inline std::string georeference_problem(const std::vector<double>& g) {
  if (g.size() != 3) return "must be [latitude_deg, longitude_deg, heading_deg]";
  for (double x : g)
    if (!std::isfinite(x)) return "must be finite numbers";
  if (std::abs(g[0]) > 90) return "latitude must be in [-90, 90]";
  if (std::abs(g[1]) > 180) return "longitude must be in [-180, 180]";
  return "";
}
// A checked option value as a GeoReference.
GeoReference georeference_from(const std::vector<double>& values);

// [longitude, latitude] in degrees of the image point (x, y) metres (image frame) of an image width_m x height_m.
// The image is taken as an azimuthal equidistant map about its centre on the WGS 84 ellipsoid (GeographicLib): a
// photograph of a few kilometres differs from any other map projection there by far less than a pixel.
std::array<double, 2> image_to_wgs84(const GeoReference& g, double width_m, double height_m, double x_m, double y_m);

// The floes as a GeoJSON FeatureCollection in WGS 84 (longitude, latitude; CRS84), with the same ids and
// properties; its floesim member names the format floesim-floes-wgs84/1 (a map layer: the simulation reads the
// metres of floes.geojson, and refuses this one).
nlohmann::json floes_to_wgs84_geojson(const FloeField& field, const GeoReference& g);

// What places a raster on the image's pixel grid (labels.png, overlay.png) where its floes are, for a GIS: an ESRI
// world file (`pgw`: six lines A, D, B, E, C, F; a pixel (column, row) lies at x = A col + B row + C,
// y = D col + E row + F, C and F at the centre of the top-left pixel) and its CRS as ESRI WKT (`prj`). With a
// georeference: the azimuthal equidistant map about the image centre on WGS 84 (east and north in metres, the image
// turned by its heading) that floes_wgs84.geojson is drawn from, so that QGIS lays the raster under those floes;
// without one: the image's own metres, under floes.geojson.
struct WorldFile {
  std::string pgw, prj;
};
WorldFile raster_world_file(double width_m, double height_m, double metres_per_pixel, const GeoReference* g);

}  // namespace floesim::imaging
