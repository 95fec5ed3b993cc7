#include "pipeline/floes_io.h"

#include <cmath>
#include <cstdint>
#include <set>

#include "pipeline/atomic_file.h"
#include "pipeline/error.h"
#include "pipeline/options.h"

namespace floesim {

nlohmann::json floes_to_geojson(const FloeField& field) {
  nlohmann::json fc;
  fc["type"] = "FeatureCollection";
  // The legacy GeoJSON "crs" member (GDAL and so QGIS read it): a local engineering frame in metres, so that a GIS
  // neither takes the metres for degrees nor places them on the map (floes_wgs84.geojson does that).
  fc["crs"] = {{"type", "name"}, {"properties", {{"name", kLocalMetresCrs}}}};
  fc["floesim"] = {{"format", "floesim-floes/1"},
                   {"crs", "local metres: x to the right, y up, origin at the image's bottom-left corner"},
                   {"width_m", field.width_m},
                   {"height_m", field.height_m},
                   {"provenance", field.provenance}};
  if (!field.warnings.empty()) fc["floesim"]["warnings"] = field.warnings;
  nlohmann::json feats = nlohmann::json::array();
  for (const Floe& f : field.floes) {
    nlohmann::json ring = nlohmann::json::array();
    for (const Vec2& v : f.outline) ring.push_back({v.x(), v.y()});
    if (!f.outline.empty()) ring.push_back({f.outline[0].x(), f.outline[0].y()});  // GeoJSON rings are closed
    nlohmann::json props = {{"id", f.id}, {"area_m2", f.area_m2}, {"thickness_m", f.thickness_m}};
    if (f.level_ice) props["kind"] = "level_ice";
    feats.push_back({{"type", "Feature"},
                     {"id", f.id},
                     {"properties", props},
                     {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}}});
  }
  fc["features"] = feats;
  return fc;
}

namespace {

// Reading a user's GeoJSON must never let a nlohmann exception or an unchecked conversion through (fuzz_floes found
// "width_m": "wide" escaping as nlohmann::type_error, a geometry without "coordinates" read through a missing key
// and "id": 1e20 cast to int): every member is checked for its type first.
const nlohmann::json* member(const nlohmann::json& o, const char* key) {
  if (!o.is_object()) return nullptr;
  auto it = o.find(key);
  return it == o.end() ? nullptr : &*it;
}

bool is_string(const nlohmann::json* v, const char* s) { return v && v->is_string() && v->get<std::string>() == s; }

// A finite number >= 0, or `fallback` when absent.
double extent(const nlohmann::json& fl, const char* key, const std::string& file) {
  const nlohmann::json* v = member(fl, key);
  if (!v) return 0.0;
  FLOESIM_REQUIRE(v->is_number() && std::isfinite(v->get<double>()) && v->get<double>() >= 0, file, ": floesim.",
                  key, " must be a number >= 0 (the field's extent in metres), got ", v->dump());
  return v->get<double>();
}

// An integer that fits an int (1 and 1.0 alike); false otherwise.
bool int_value(const nlohmann::json& v, int& out) {
  if (!v.is_number()) return false;
  const double d = v.get<double>();
  if (v.is_number_integer() ? (v.get<int64_t>() < INT32_MIN || v.get<int64_t>() > INT32_MAX ||
                               (v.is_number_unsigned() && v.get<uint64_t>() > uint64_t(INT32_MAX)))
                            : !(std::floor(d) == d && d >= INT32_MIN && d <= INT32_MAX))
    return false;
  out = v.is_number_integer() ? static_cast<int>(v.get<int64_t>()) : static_cast<int>(d);
  return true;
}

}  // namespace

FloeField floes_from_geojson(const nlohmann::json& j, const std::string& file) {
  FloeField field;
  FLOESIM_REQUIRE(j.is_object() && is_string(member(j, "type"), "FeatureCollection"), file,
                  ": not a GeoJSON FeatureCollection (expected {\"type\": \"FeatureCollection\", ...})");
  const nlohmann::json* features = member(j, "features");
  FLOESIM_REQUIRE(features && features->is_array(), file, ": has no \"features\" array");
  if (const nlohmann::json* fl = member(j, "floesim"); fl && fl->is_object()) {
    const nlohmann::json* format = member(*fl, "format");
    FLOESIM_REQUIRE(!is_string(format, "floesim-floes-wgs84/1"), file,
                    ": is the floes in WGS 84 degrees (a map layer, floes_wgs84.geojson); give the floes in metres "
                    "(floes.geojson beside it)");
    field.width_m = extent(*fl, "width_m", file);
    field.height_m = extent(*fl, "height_m", file);
    if (const nlohmann::json* p = member(*fl, "provenance")) field.provenance = *p;
    if (const nlohmann::json* w = member(*fl, "warnings")) {
      FLOESIM_REQUIRE(w->is_array(), file, ": floesim.warnings must be a list of strings");
      for (const nlohmann::json& line : *w) {
        FLOESIM_REQUIRE(line.is_string(), file, ": floesim.warnings must be a list of strings");
        field.warnings.push_back(line.get<std::string>());
      }
    }
  }
  std::set<int> ids;
  int index = 0;
  for (const auto& feat : *features) {
    const std::string where = file + ": feature #" + std::to_string(index++);
    const nlohmann::json* geometry = member(feat, "geometry");
    FLOESIM_REQUIRE(geometry && geometry->is_object(), where, " has no geometry object");
    const auto& g = *geometry;
    const nlohmann::json* type = member(g, "type");
    FLOESIM_REQUIRE(is_string(type, "Polygon"), where, " has geometry type ", type ? type->dump() : "(none)",
                    "; only Polygon is supported (split MultiPolygons into one feature per floe)");
    const nlohmann::json* coordinates = member(g, "coordinates");
    FLOESIM_REQUIRE(coordinates && coordinates->is_array() && !coordinates->empty(), where, " has no coordinates");
    const auto& coords = *coordinates;
    FLOESIM_REQUIRE(coords.size() == 1, where, " has ", coords.size() - 1,
                    " hole(s); floes must be simple polygons without holes (melt ponds are ice: close them)");
    FLOESIM_REQUIRE(coords[0].is_array(), where, ": coordinates[0] must be an array of [x, y] vertices, got ",
                    coords[0].dump());
    Floe f;
    const nlohmann::json* props = member(feat, "properties");
    if (props && !props->is_object()) props = nullptr;
    const nlohmann::json* id = props ? member(*props, "id") : nullptr;
    if (!id) id = member(feat, "id");
    FLOESIM_REQUIRE(id && int_value(*id, f.id), where, ": properties.id must be an integer, got ",
                    id ? id->dump() : "none");
    if (const nlohmann::json* t = props ? member(*props, "thickness_m") : nullptr) {
      FLOESIM_REQUIRE(t->is_number(), where, ": properties.thickness_m must be a number, got ", t->dump());
      f.thickness_m = t->get<double>();
    }
    const std::string fw = file + ": floe id " + std::to_string(f.id);
    if (const nlohmann::json* k = props ? member(*props, "kind") : nullptr) {
      FLOESIM_REQUIRE(k->is_string() && (*k == "floe" || *k == "level_ice"), fw,
                      ": properties.kind must be \"floe\" or \"level_ice\" (a sheet), got ", k->dump());
      f.level_ice = *k == "level_ice";
    }
    FLOESIM_REQUIRE(f.id >= 1, fw, ": id must be >= 1 (0 means water in the label image)");
    FLOESIM_REQUIRE(ids.insert(f.id).second, fw, ": duplicate id");
    FLOESIM_REQUIRE(std::isfinite(f.thickness_m) && f.thickness_m > 0, fw, ": thickness_m must be > 0, got ",
                    f.thickness_m);
    for (const auto& pt : coords[0]) {
      FLOESIM_REQUIRE(pt.is_array() && pt.size() >= 2 && pt[0].is_number() && pt[1].is_number(), fw,
                      ": a vertex is not [x, y]: ", pt.dump());
      const double x = pt[0].get<double>(), y = pt[1].get<double>();
      FLOESIM_REQUIRE(std::isfinite(x) && std::isfinite(y), fw, ": a vertex is not finite");
      FLOESIM_REQUIRE(std::abs(x) <= kMaxWorldCoordinateM && std::abs(y) <= kMaxWorldCoordinateM, fw, ": vertex ",
                      pt.dump(), " is more than ", kMaxWorldCoordinateM / 1e3,
                      " km from the origin; give the floes in metres of a local or projected frame");
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
