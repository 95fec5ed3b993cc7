#include <gtest/gtest.h>

#include <filesystem>

#include "pipeline/error.h"
#include "pipeline/floes_io.h"
#include "pipeline/options.h"

using namespace floesim;
namespace fs = std::filesystem;

namespace {
Json square_feature(int id, double x0, bool clockwise = false) {
  Json ring = Json::array({{x0, 0}, {x0 + 10, 0}, {x0 + 10, 10}, {x0, 10}, {x0, 0}});
  if (clockwise) ring = Json::array({{x0, 0}, {x0, 10}, {x0 + 10, 10}, {x0 + 10, 0}, {x0, 0}});
  return {{"type", "Feature"},
          {"properties", {{"id", id}, {"thickness_m", 1.0}}},
          {"geometry", {{"type", "Polygon"}, {"coordinates", {ring}}}}};
}
Json collection(std::vector<Json> feats) { return {{"type", "FeatureCollection"}, {"features", feats}}; }
std::string error_of(const Json& j) {
  try {
    floes_from_geojson(j, "floes.geojson");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(FloesIo, RoundTripKeepsGeometryAndIds) {
  FloeField f;
  f.width_m = 100;
  f.height_m = 50;
  f.floes.push_back({3, {{0, 0}, {4, 0}, {4, 2}, {0, 2}}, 8.0, 0.7});
  const fs::path p = fs::temp_directory_path() / "floesim_floes_rt.geojson";
  write_floes(p, f);
  FloeField g = read_floes(p);
  ASSERT_EQ(g.floes.size(), 1u);
  EXPECT_EQ(g.floes[0].id, 3);
  EXPECT_DOUBLE_EQ(g.floes[0].area_m2, 8.0);
  EXPECT_DOUBLE_EQ(g.floes[0].thickness_m, 0.7);
  EXPECT_EQ(g.width_m, 100);
  EXPECT_TRUE(g.warnings.empty());
  fs::remove(p);
}

// The file declares its CRS (a local frame in metres, so that a GIS does not read degrees) and carries its maker's
// warnings to the simulation, which puts them into summary.json.
TEST(FloesIo, TheCrsIsDeclaredAndWarningsRoundTrip) {
  FloeField f;
  f.floes.push_back({1, {{0, 0}, {4, 0}, {4, 2}, {0, 2}}, 8.0, 1.0});
  f.warnings = {"image.png: no water found"};
  const nlohmann::json j = floes_to_geojson(f);
  EXPECT_EQ(j["crs"]["type"], "name");
  EXPECT_EQ(j["crs"]["properties"]["name"].get<std::string>().rfind("LOCAL_CS[", 0), 0u);
  EXPECT_EQ(floes_from_geojson(j, "f.geojson").warnings, f.warnings);
  nlohmann::json bad = j;
  bad["floesim"]["warnings"] = "one";
  EXPECT_NE(error_of(bad).find("floesim.warnings"), std::string::npos);
}

TEST(FloesIo, ClockwiseRingsAreStoredCounterClockwise) {
  FloeField g = floes_from_geojson(collection({square_feature(1, 0, true)}), "f");
  EXPECT_GT(signed_area(g.floes[0].outline), 0);
  EXPECT_DOUBLE_EQ(g.floes[0].area_m2, 100.0);
}

TEST(FloesIo, RejectsSelfIntersectionNamingTheFloe) {
  Json bow = square_feature(7, 0);
  // Json::array around the ring: a one-element brace list `{ring}` is the ring itself under clang, a list of it
  // under gcc (nlohmann's initializer-list rule; the clang build of tests/sanitize/sanitize found it).
  bow["geometry"]["coordinates"] = Json::array({Json::array({{0, 0}, {10, 10}, {10, 0}, {0, 10}, {0, 0}})});
  const std::string e = error_of(collection({bow}));
  EXPECT_NE(e.find("floe id 7"), std::string::npos) << e;
  EXPECT_NE(e.find("intersects itself"), std::string::npos) << e;
}

// A vertex farther than any ice field (10,000 km; a far larger one would overflow the collision detection's
// bounding volumes): an error naming the floe and the vertex, not a crash in the simulation.
TEST(FloesIo, RejectsAVertexBeyondAnyField) {
  Json far = square_feature(5, 0);
  far["geometry"]["coordinates"] = Json::array({Json::array({{0, 0}, {10, 0}, {10, 3.8e199}, {0, 10}, {0, 0}})});
  const std::string e = error_of(collection({far}));
  EXPECT_NE(e.find("floe id 5: vertex [10,3.8e+199] is more than 10000 km from the origin"), std::string::npos) << e;
  Json utm = square_feature(6, 0);  // a UTM northing at 79 deg N is fine
  utm["geometry"]["coordinates"] = Json::array({Json::array({{5e5, 8.77e6}, {5e5 + 10, 8.77e6}, {5e5, 8.77e6 + 10}})});
  EXPECT_EQ(floes_from_geojson(collection({utm}), "f").floes.size(), 1u);
}

TEST(FloesIo, RejectsHolesDuplicatesAndBadThickness) {
  Json holed = square_feature(1, 0);
  holed["geometry"]["coordinates"].push_back(Json::array({{2, 2}, {3, 2}, {3, 3}, {2, 2}}));
  EXPECT_NE(error_of(collection({holed})).find("hole"), std::string::npos);
  EXPECT_NE(error_of(collection({square_feature(2, 0), square_feature(2, 20)})).find("duplicate id"),
            std::string::npos);
  Json thin = square_feature(4, 0);
  thin["properties"]["thickness_m"] = -1;
  EXPECT_NE(error_of(collection({thin})).find("thickness_m must be > 0"), std::string::npos);
  EXPECT_NE(error_of(Json::object()).find("not a GeoJSON FeatureCollection"), std::string::npos);
}

// Members of the wrong type are clear errors, never a nlohmann exception or an unchecked cast (found by
// tests/fuzz/fuzz_floes; the inputs are in tests/fuzz/crashes/fuzz_floes/).
TEST(FloesIo, WrongTypesAreClearErrors) {
  Json wide = collection({square_feature(1, 0)});
  wide["floesim"] = {{"width_m", "wide"}};
  EXPECT_NE(error_of(wide).find("floesim.width_m must be a number >= 0"), std::string::npos) << error_of(wide);
  Json typed = collection({square_feature(1, 0)});
  typed["type"] = 7;
  EXPECT_NE(error_of(typed).find("not a GeoJSON FeatureCollection"), std::string::npos);
  Json no_coords = square_feature(1, 0);
  no_coords["geometry"].erase("coordinates");
  EXPECT_NE(error_of(collection({no_coords})).find("has no coordinates"), std::string::npos);
  Json geometry_type = square_feature(1, 0);
  geometry_type["geometry"]["type"] = 3;
  EXPECT_NE(error_of(collection({geometry_type})).find("has geometry type 3"), std::string::npos);
  for (Json id : {Json(1e20), Json(1.5), Json("one"), Json(4294967297ll)}) {
    Json f = square_feature(1, 0);
    f["properties"]["id"] = id;
    EXPECT_NE(error_of(collection({f})).find("properties.id must be an integer"), std::string::npos) << id;
  }
  Json thick = square_feature(1, 0);
  thick["properties"]["thickness_m"] = "1 m";
  EXPECT_NE(error_of(collection({thick})).find("properties.thickness_m must be a number"), std::string::npos);
  Json ring = square_feature(1, 0);
  ring["geometry"]["coordinates"] = Json::array({5});
  EXPECT_NE(error_of(collection({ring})).find("coordinates[0] must be an array"), std::string::npos);
  Json whole = square_feature(1, 0);
  whole["properties"]["id"] = 2.0;  // an integral number is an integer
  EXPECT_EQ(floes_from_geojson(collection({whole}), "f.geojson").floes.at(0).id, 2);
}
