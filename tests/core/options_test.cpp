#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

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

// A typo names the key it most likely meant: one deletion ("sped_mps": 1 from speed_mps), a transposition (2
// substitutions), and nothing for a key that is no typo of any (over a third of its letters differ).
TEST(Options, UnknownKeyNamesTheKeyItMostLikelyMeant) {
  const std::string e = error_of(Json::parse(R"({"thickness": 0.5, "inner": {"sped_mps": 1}, "mdoe": "slice"})"));
  EXPECT_NE(e.find("sim.inner.sped_mps is not a known key; did you mean speed_mps?"), std::string::npos) << e;
  EXPECT_NE(e.find("sim.mdoe is not a known key; did you mean mode?"), std::string::npos) << e;
  EXPECT_NE(e.find("sim.thickness is not a known key; did you mean thickness_m?"), std::string::npos) << e;
  EXPECT_EQ(closest_key("duraton_s", {"time_step_s", "duration_s", "output_interval_s"}), "duration_s");
  EXPECT_EQ(closest_key("lenght_m", {"length_m", "beam_m"}), "length_m");
  EXPECT_EQ(closest_key("colour", {"length_m", "beam_m", "sections"}), "");
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

// An integer field takes only an integral value that fits: nlohmann's unchecked cast read 2.5 as 2 (silently) and
// 1e20 as undefined behaviour (UBSan: float-cast-overflow; tests/fuzz/crashes/fuzz_options/int_overflow.json).
TEST(Options, IntegerFieldRefusesFractionsAndValuesOutOfRange) {
  for (const char* bad : {R"({"sections": 12.5})", R"({"sections": 1e20})", R"({"sections": -1e300})",
                          R"({"sections": 4294967308})", R"({"sections": 18446744073709551615})"}) {
    const std::string e = error_of(Json::parse(bad));
    EXPECT_NE(e.find("sim.sections has the wrong type: expected an integer"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_EQ(read_options<Opts>(Json::parse(R"({"sections": 12.0})"), "x.json").sections, 12);
  EXPECT_EQ(read_options<Opts>(Json::parse(R"({"sections": 1.2e1})"), "x.json").sections, 12);
}

namespace {
struct Seeded {
  std::uint64_t seed = 1;
  template <class V>
  void visit(V& v) {
    v.field("seed", seed, "-", "seed");
  }
};
}  // namespace

TEST(Options, UnsignedFieldRefusesNegativeAndFractionalValues) {
  for (const char* bad : {R"({"seed": -1})", R"({"seed": -1.5})", R"({"seed": 1e30})", R"({"seed": 0.5})"}) {
    try {
      read_options<Seeded>(Json::parse(bad), "x.json");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("seed has the wrong type"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(read_options<Seeded>(Json::parse(R"({"seed": 18446744073709551615})"), "x.json").seed,
            18446744073709551615ull);
}

// A number too large for a double is nlohmann's out_of_range, not a parse_error: it escaped load_json_file and
// was not the clear error every other bad file gives (found by tests/fuzz/fuzz_floes, crashes/fuzz_floes/crash-*).
TEST(Options, NumberOverflowInAJsonFileIsAClearError) {
  const std::filesystem::path f = std::filesystem::temp_directory_path() / "floesim_overflow.json";
  std::ofstream(f) << R"({"thickness_m": 66e566})";
  try {
    load_json_file(f);
    ADD_FAILURE() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("floesim_overflow.json: not valid JSON"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("number overflow"), std::string::npos) << e.what();
  }
  std::filesystem::remove(f);
}
