// The floe field artefact: a GeoJSON FeatureCollection of Polygon features in metres
// (x to the right, y up, origin at the image's bottom-left corner). Each feature's properties hold
// `id` (>= 1, equal to its value in the label image), `area_m2`, `thickness_m` and optionally `kind` ("floe", the
// default, or "level_ice": a level ice sheet, simulated as fixed tiles that only fracture breaks).
// A top-level member "floesim" holds the field extent and the provenance.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/geometry2d.h"

namespace floesim {

struct Floe {
  int id = 0;
  Polygon outline;  // counter-clockwise, open ring, metres
  double area_m2 = 0;
  double thickness_m = 1.0;
  bool level_ice = false;  // properties.kind "level_ice": a sheet held by the ice around it (sim: fixed tiles)
};

struct FloeField {
  std::vector<Floe> floes;
  double width_m = 0, height_m = 0;  // extent of the source image (0 if unknown)
  nlohmann::json provenance = nlohmann::json::object();
  // What the stage that made the field warned of (digitise: an image of one class, ...): carried in the file's
  // floesim member so that the simulation's summary and the report show it.
  std::vector<std::string> warnings;
};

// The CRS floes.geojson declares (its legacy "crs" member, as WKT): a local frame in metres, x right, y up.
inline constexpr const char* kLocalMetresCrs =
    "LOCAL_CS[\"floesim image frame, metres (x right, y up, origin at the image's bottom-left corner)\","
    "LOCAL_DATUM[\"image\",32767],UNIT[\"metre\",1],AXIS[\"x\",EAST],AXIS[\"y\",NORTH]]";

nlohmann::json floes_to_geojson(const FloeField& field);
// Strict: errors name the file and the feature. Rings may come in either orientation (stored CCW).
// Rejects holes, fewer than 3 distinct vertices, non-finite numbers, self-intersection, duplicate ids.
FloeField floes_from_geojson(const nlohmann::json& j, const std::string& file);

void write_floes(const std::filesystem::path& file, const FloeField& field);  // atomic
FloeField read_floes(const std::filesystem::path& file);

}  // namespace floesim
