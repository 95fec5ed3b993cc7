#include "pipeline/floes_io.h"

#include <cmath>
#include <set>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/options.h"

namespace floesim {

nlohmann::json floes_to_geojson(const FloeField& field) {
  nlohmann::json fc;
  fc["type"] = "FeatureCollection";
  fc["floesim"] = {{"format", "floesim-floes/1"},
                   {"crs", "local metres: x to the right, y up, origin at the image's bottom-left corner"},
                   {"width_m", field.width_m},
                   {"height_m", field.height_m},
                   {"provenance", field.provenance}};
  nlohmann::json feats = nlohmann::json::array();
  for (const Floe& f : field.floes) {
    nlohmann::json ring = nlohmann::json::array();
    for (const Vec2& v : f.outline) ring.push_back({v.x(), v.y()});
    if (!f.outline.empty()) ring.push_back({f.outline[0].x(), f.outline[0].y()});  // GeoJSON rings are closed
    feats.push_back({{"type", "Feature"},
                     {"id", f.id},
                     {"properties", {{"id", f.id}, {"area_m2", f.area_m2}, {"thickness_m", f.thickness_m}}},
                     {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}}});
  }
  fc["features"] = feats;
  return fc;
}

FloeField floes_from_geojson(const nlohmann::json& j, const std::string& file) {
  FloeField field;
  FLOESIM_REQUIRE(j.is_object() && j.value("type", "") == "FeatureCollection", file,
                  ": not a GeoJSON FeatureCollection (expected {\"type\": \"FeatureCollection\", ...})");
  FLOESIM_REQUIRE(j.contains("features") && j["features"].is_array(), file, ": has no \"features\" array");
  if (j.contains("floesim") && j["floesim"].is_object()) {
    field.width_m = j["floesim"].value("width_m", 0.0);
    field.height_m = j["floesim"].value("height_m", 0.0);
    if (j["floesim"].contains("provenance")) field.provenance = j["floesim"]["provenance"];
  }
  std::set<int> ids;
  int index = 0;
  for (const auto& feat : j["features"]) {
    const std::string where = file + ": feature #" + std::to_string(index++);
    FLOESIM_REQUIRE(feat.is_object() && feat.contains("geometry") && feat["geometry"].is_object(), where,
                    " has no geometry object");
    const auto& g = feat["geometry"];
    FLOESIM_REQUIRE(g.value("type", "") == "Polygon", where, " has geometry type ", g.value("type", "?"),
                    "; only Polygon is supported (split MultiPolygons into one feature per floe)");
    const auto& coords = g["coordinates"];
    FLOESIM_REQUIRE(coords.is_array() && !coords.empty(), where, " has no coordinates");
    FLOESIM_REQUIRE(coords.size() == 1, where, " has ", coords.size() - 1,
                    " hole(s); floes must be simple polygons without holes (melt ponds are ice: close them)");
    Floe f;
    const auto& props = feat.contains("properties") && feat["properties"].is_object() ? feat["properties"]
                                                                                      : nlohmann::json::object();
    try {
      f.id = props.contains("id") ? props["id"].get<int>() : feat.at("id").get<int>();
      f.thickness_m = props.value("thickness_m", 1.0);
    } catch (const std::exception&) {
      throw Error(where + ": properties.id must be an integer and properties.thickness_m a number");
    }
    const std::string fw = file + ": floe id " + std::to_string(f.id);
    FLOESIM_REQUIRE(f.id >= 1, fw, ": id must be >= 1 (0 means water in the label image)");
    FLOESIM_REQUIRE(ids.insert(f.id).second, fw, ": duplicate id");
    FLOESIM_REQUIRE(std::isfinite(f.thickness_m) && f.thickness_m > 0, fw, ": thickness_m must be > 0, got ",
                    f.thickness_m);
    for (const auto& pt : coords[0]) {
      FLOESIM_REQUIRE(pt.is_array() && pt.size() >= 2 && pt[0].is_number() && pt[1].is_number(), fw,
                      ": a vertex is not [x, y]: ", pt.dump());
      const double x = pt[0].get<double>(), y = pt[1].get<double>();
      FLOESIM_REQUIRE(std::isfinite(x) && std::isfinite(y), fw, ": a vertex is not finite");
      f.outline.emplace_back(x, y);
    }
    if (f.outline.size() > 1 && f.outline.front() == f.outline.back()) f.outline.pop_back();
    f.outline = clean_polygon(f.outline);
    FLOESIM_REQUIRE(f.outline.size() >= 3, fw, ": fewer than 3 distinct vertices");
    make_ccw(f.outline);
    auto [a, b] = find_self_intersection(f.outline);
    FLOESIM_REQUIRE(a < 0, fw, ": the outline intersects itself (edges ", a, " and ", b,
                    " cross); fix the polygon or re-run digitise");
    f.area_m2 = signed_area(f.outline);
    FLOESIM_REQUIRE(f.area_m2 > 0, fw, ": zero area");
    field.floes.push_back(std::move(f));
  }
  return field;
}

void write_floes(const std::filesystem::path& file, const FloeField& field) {
  write_text_atomic(file, floes_to_geojson(field).dump(1) + "\n");
}

FloeField read_floes(const std::filesystem::path& file) {
  return floes_from_geojson(load_json_file(file), file.string());
}

}  // namespace floesim
