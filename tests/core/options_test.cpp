#include <gtest/gtest.h>

#include "pipeline/options.h"

using namespace floesim;

namespace {
struct Inner {
  double speed_mps = 2.0;
  template <class V>
  void visit(V& v) {
    v.field("speed_mps", speed_mps, "m/s", "speed", positive());
  }
};
struct Opts {
  double thickness_m = 1.0;
  int sections = 30;
  std::string mode = "slice";
  Inner inner;
  template <class V>
  void visit(V& v) {
    v.field("thickness_m", thickness_m, "m", "ice thickness", positive());
    v.field("sections", sections, "-", "parts", int_in_range(4, 64));
    v.field("mode", mode, "-", "mode", one_of({"slice", "refuse"}));
    v.section("inner", inner, "nested");
  }
};
std::string error_of(const Json& j) {
  try {
    read_options<Opts>(j, "case.json", "sim");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Options, DefaultsWhenKeysAbsent) {
  Opts o = read_options<Opts>(Json::object(), "case.json");
  EXPECT_EQ(o.thickness_m, 1.0);
  EXPECT_EQ(o.inner.speed_mps, 2.0);
}

TEST(Options, ReadsValuesAndNestedSections) {
  Opts o = read_options<Opts>(Json::parse(R"({"thickness_m": 0.5, "inner": {"speed_mps": 3}})"), "case.json");
  EXPECT_EQ(o.thickness_m, 0.5);
  EXPECT_EQ(o.inner.speed_mps, 3.0);
}

TEST(Options, UnknownKeyIsAnErrorNamingFileAndPath) {
  const std::string e = error_of(Json::parse(R"({"thickness": 0.5, "inner": {"sped_mps": 1}})"));
  EXPECT_NE(e.find("case.json"), std::string::npos) << e;
  EXPECT_NE(e.find("sim.thickness is not a known key"), std::string::npos) << e;
  EXPECT_NE(e.find("sim.inner.sped_mps is not a known key"), std::string::npos) << e;
  EXPECT_NE(e.find("2 problems"), std::string::npos) << e;
}

TEST(Options, ReportsEveryViolationWithTheValue) {
  const std::string e = error_of(Json::parse(R"({"thickness_m": -2, "sections": 100, "mode": "hull"})"));
  EXPECT_NE(e.find("sim.thickness_m must be > 0, got -2"), std::string::npos) << e;
  EXPECT_NE(e.find("sim.sections must be in [4, 64], got 100"), std::string::npos) << e;
  EXPECT_NE(e.find("sim.mode must be one of"), std::string::npos) << e;
}

TEST(Options, WrongTypeIsAnError) {
  const std::string e = error_of(Json::parse(R"({"thickness_m": "thick"})"));
  EXPECT_NE(e.find("sim.thickness_m has the wrong type: expected a number"), std::string::npos) << e;
}

TEST(Options, EchoRoundTrips) {
  Opts o = read_options<Opts>(Json::parse(R"({"sections": 12})"), "x.json");
  Json echo = options_to_json(o);
  EXPECT_EQ(echo["sections"], 12);
  EXPECT_EQ(echo["inner"]["speed_mps"], 2.0);
  Opts back = read_options<Opts>(echo, "echo.json");
  EXPECT_EQ(back.sections, 12);
  EXPECT_NE(options_doc(o).find("`inner.speed_mps`"), std::string::npos);
}
