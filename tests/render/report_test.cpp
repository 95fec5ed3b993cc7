// The report of a run of the tiny case: self-contained (no network reference in any src or href; every image and
// the video a data: URI that decodes, by the test's own base64 decoder, to the bytes of its artefact file), the
// reference error against hand-worked numbers, a run without its video says so, and a run without its summary is
// an error that writes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include "pipeline/error.h"
#include "pipeline/options.h"
#include "render/report.h"
#include "tests/test_util.h"

namespace fs = std::filesystem;
using floesim::tests::read_text;
using namespace floesim;
using namespace floesim::render;

namespace {

const fs::path kBin = FLOESIM_BIN_DIR;
const fs::path kSource = FLOESIM_SOURCE_DIR;

using Cmd = floesim::tests::CommandOutput;
Cmd sh(const std::string& cmd, const fs::path& log) { return floesim::tests::run_logged(cmd, log); }

// RFC 4648 base64, written here independently of the library's encoder (OpenSSL).
std::string decode_base64(const std::string& s) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  EXPECT_EQ(s.size() % 4, 0u);
  std::string out;
  for (size_t i = 0; i + 3 < s.size(); i += 4) {
    int v[4];
    int pad = 0;
    for (int k = 0; k < 4; ++k) {
      if (s[i + k] == '=') {
        v[k] = 0;
        ++pad;
      } else {
        v[k] = value(s[i + k]);
        EXPECT_GE(v[k], 0) << "not base64: '" << s[i + k] << "' at " << i + k;
      }
    }
    const uint32_t w = (v[0] << 18) | (v[1] << 12) | (v[2] << 6) | v[3];
    out += char((w >> 16) & 0xff);
    if (pad < 2) out += char((w >> 8) & 0xff);
    if (pad < 1) out += char(w & 0xff);
  }
  return out;
}

// The src values of every <img> and <video> tag, with the tag name (found by hand: std::regex recurses per
// character and overflows the stack on a megabyte of base64).
std::vector<std::pair<std::string, std::string>> media_sources(const std::string& html) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const std::string tag : {"img", "video"}) {
    for (size_t p = html.find("<" + tag + " "); p != std::string::npos; p = html.find("<" + tag + " ", p + 1)) {
      const size_t end = html.find('>', p);
      const size_t s = html.find(" src=\"", p);
      if (s == std::string::npos || s > end) {
        out.push_back({tag, ""});
        continue;
      }
      const size_t a = s + 6, b = html.find('"', a);
      out.push_back({tag, html.substr(a, b - a)});
    }
  }
  return out;
}

// True if a src or href attribute holds a network address (scheme http(s) or protocol-relative //).
bool has_network_attribute(const std::string& html) {
  for (const std::string attr : {"src=", "href="}) {
    for (size_t p = html.find(attr); p != std::string::npos; p = html.find(attr, p + 1)) {
      size_t v = p + attr.size();
      if (v < html.size() && (html[v] == '"' || html[v] == '\'')) ++v;
      const std::string head = html.substr(v, 8);
      if (head.rfind("http:", 0) == 0 || head.rfind("https:", 0) == 0 || head.rfind("//", 0) == 0) return true;
    }
  }
  return false;
}

// The first screen's table ("What was run"), or "" if the page has none.
std::string first_screen_table(const std::string& html) {
  const size_t a = html.find("<table id=\"what-was-run\">");
  return a == std::string::npos ? std::string() : html.substr(a, html.find("</table>", a) - a);
}

// One run of the tiny case shared by the tests (the tests copy it before editing).
class TinyRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("floesim_report_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    run_ = root_ / "run";
    ran_ = sh("'" + (kBin / "floesim").string() + "' run '" + (kSource / "tests/e2e/tiny").string() +
                  "' --out '" + run_.string() + "'",
              root_ / "run.log");
  }
  static void TearDownTestSuite() {
    if (!std::getenv("FLOESIM_KEEP_TEST_OUTPUT")) fs::remove_all(root_);
  }
  static fs::path copy_run(const std::string& name) {
    const fs::path d = root_ / name;
    fs::copy(run_, d, fs::copy_options::recursive);
    return d;
  }
  static fs::path root_, run_;
  static Cmd ran_;
};
fs::path TinyRun::root_, TinyRun::run_;
Cmd TinyRun::ran_;

}  // namespace

TEST(Report, ReferenceErrorAgainstHandValues) {
  // 1100 kN simulated against the seed's 1038 kN full scale: +62 kN, 62 / 1038 = +5.973 %.
  const auto c = compare_to_reference(1100, {"full scale", 1038});
  EXPECT_EQ(c.label, "full scale");
  EXPECT_DOUBLE_EQ(c.error_kN, 62);
  EXPECT_NEAR(c.error_percent, 5.97303, 1e-5);
  // Against SAMS, 974 kN: +126 kN, +12.936 %.
  EXPECT_NEAR(compare_to_reference(1100, {"SAMS", 974}).error_percent, 12.93634, 1e-5);
}

TEST(Report, Base64AndEscaping) {
  EXPECT_EQ(base64_encode(""), "");
  EXPECT_EQ(base64_encode("f"), "Zg==");
  EXPECT_EQ(base64_encode("fo"), "Zm8=");
  EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
  // Across the encoder's chunk boundary (3 MiB) the text is one unbroken stream.
  std::string big(3 * (1 << 20) + 5, '\0');
  for (size_t i = 0; i < big.size(); ++i) big[i] = char(i * 131 + 7);
  EXPECT_EQ(decode_base64(base64_encode(big)), big);
  EXPECT_EQ(html_escape("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
}

TEST(Report, ReferencesFromTheConfig) {
  const auto o = read_options<ReportOptions>(
      Json::parse(R"({"reference_kN": 1038, "reference_label": "full scale", "references": [{"label": "SAMS",
                  "kN": 974}]})"),
      "report.json");
  const auto r = o.all_references();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].label, "full scale");
  EXPECT_EQ(r[1].kN, 974);
  // A typo and a bad value are reported together, naming the key.
  try {
    read_options<ReportOptions>(Json::parse(R"({"referense_kN": 1, "references": [{"label": "x", "kN": -1}]})"),
                                "report.json");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("referense_kN"), std::string::npos) << m;
    EXPECT_NE(m.find("references[0].kN"), std::string::npos) << m;
  }
}

TEST_F(TinyRun, ReportIsSelfContainedAndEmbedsTheArtefacts) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const fs::path config = root_ / "report.json", out = root_ / "out" / "report.html";
  std::ofstream(config) << R"({"reference_kN": 1038, "reference_label": "full scale",
                              "references": [{"label": "SAMS", "kN": 974}]})";
  // Through the executable: exit code and what it prints.
  const Cmd c = sh("'" + (kBin / "floesim-report").string() + "' --run '" + run_.string() + "' --config '" +
                       config.string() + "' --out '" + out.string() + "'",
                   root_ / "report.log");
  ASSERT_EQ(c.code, 0) << c.text;
  EXPECT_NE(c.text.find("video embedded"), std::string::npos) << c.text;
  EXPECT_EQ(c.text.find("missing"), std::string::npos) << c.text;
  ASSERT_TRUE(fs::exists(out));
  const std::string html = read_text(out);

  // No network reference in any src or href attribute (nor anywhere: the page names none).
  EXPECT_FALSE(has_network_attribute(html));
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);

  // Every image and the video: a data: URI decoding to the bytes of one artefact, each artefact once.
  std::map<std::string, std::string> expected = {
      {"image/image.png", read_text(run_ / "image/image.png")},
      {"floes/overlay.png", read_text(run_ / "floes/overlay.png")},
      {"floes/fsd.png", read_text(run_ / "floes/fsd.png")},
      {"plots/surge_ice_load.png", read_text(run_ / "plots/surge_ice_load.png")},
      {"video/transit.mp4", read_text(run_ / "video/transit.mp4")}};
  const auto sources = media_sources(html);
  EXPECT_EQ(sources.size(), expected.size());
  for (const auto& [tag, src] : sources) {
    const std::string prefix = tag == "img" ? "data:image/png;base64," : "data:video/mp4;base64,";
    ASSERT_EQ(src.rfind(prefix, 0), 0u) << tag << " src starts " << src.substr(0, 40);
    const std::string bytes = decode_base64(src.substr(prefix.size()));
    bool found = false;
    for (auto it = expected.begin(); it != expected.end(); ++it)
      if (it->second == bytes) {
        expected.erase(it);
        found = true;
        break;
      }
    EXPECT_TRUE(found) << tag << ": " << bytes.size() << " decoded bytes match no artefact";
  }
  for (const auto& [name, bytes] : expected) ADD_FAILURE() << name << " is not embedded";

  // The reference rows from the run's own mean (read here from summary.json).
  const Json summary = load_json_file(run_ / "sim/summary.json");
  const double mean_kN = summary["mean_surge_ice_resistance_N"].get<double>() / 1000,
               hw_kN = summary["mean_surge_ice_load_interval"]["half_width_N"].get<double>() / 1000;
  char row[160];
  std::snprintf(row, sizeof row, "%+.1f &plusmn; %.1f</td><td class=\"n\">%+.1f &plusmn; %.1f", mean_kN - 1038,
                hw_kN, 100 * (mean_kN - 1038) / 1038, 100 * hw_kN / 1038);
  EXPECT_NE(html.find(row), std::string::npos) << row;
  EXPECT_NE(html.find("SAMS"), std::string::npos);
  // The settings, escaped: every stage's config file is on the page.
  for (const char* s : {"config/simulate.json", "config/digitise.json", "config/plot.json"})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  EXPECT_EQ(html.find("id=\"missing\""), std::string::npos);
}

TEST_F(TinyRun, ReferenceErrorOnThePageAgainstAHandValue) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const fs::path run = copy_run("hand");
  Json s = load_json_file(run / "sim/summary.json");
  s["mean_surge_ice_resistance_N"] = 1100e3;
  s["mean_surge_ice_load_interval"]["half_width_N"] = 55e3;
  s["mean_surge_ice_load_interval"]["meaningful"] = false;
  s["mean_surge_ice_load_interval"]["note"] = "a note for the test";
  std::ofstream(run / "sim/summary.json") << s.dump(2);
  ReportOptions o;
  o.reference_kN = 1038;
  o.reference_label = "full scale";
  o.references = {{"SAMS", 974}};
  const auto r = write_report(run, o, root_ / "hand.html", Json::object());
  ASSERT_EQ(r.references.size(), 2u);
  EXPECT_NEAR(r.references[0].error_percent, 5.97303, 1e-5);
  const std::string html = read_text(root_ / "hand.html");
  // 1100 - 1038 = +62.0 kN, +6.0 %; 1100 - 974 = +126.0 kN, +12.9 %; the 55 kN interval is 5.3 % of 1038 kN and
  // 5.6 % of 974 kN.
  EXPECT_NE(html.find("<th>full scale</th><td class=\"n\">1038</td><td class=\"n\">+62.0 &plusmn; 55.0</td>"
                      "<td class=\"n\">+6.0 &plusmn; 5.3"),
            std::string::npos);
  EXPECT_NE(html.find("<th>SAMS</th><td class=\"n\">974</td><td class=\"n\">+126.0 &plusmn; 55.0</td>"
                      "<td class=\"n\">+12.9 &plusmn; 5.6"),
            std::string::npos);
  EXPECT_NE(html.find("1100</span> &plusmn; 55</td>"), std::string::npos) << "the mean with its interval";
  EXPECT_NE(html.find("The run is too short for its interval: a note for the test"), std::string::npos);
}

// A structure's summary gets a section of its own, every figure named by its path; a ship's run has none.
TEST_F(TinyRun, AStructuresFiguresHaveASectionOfTheirOwn) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const fs::path run = copy_run("structure");
  write_report(run, ReportOptions{}, root_ / "ship.html", Json::object());
  EXPECT_EQ(read_text(root_ / "ship.html").find("<h2>Structure</h2>"), std::string::npos);
  Json s = load_json_file(run / "sim/summary.json");
  s["structure"] = {{"kind", "moored"},
                    {"cycles", {{"mean_peak_N", 1.25e6}}},
                    {"station_keeping", {{"lines", Json::array({{{"fairlead_tension_N", {{"max", 3.4e5}}}}})}}}};
  std::ofstream(run / "sim/summary.json") << s.dump(2);
  write_report(run, ReportOptions{}, root_ / "structure.html", Json::object());
  const std::string html = read_text(root_ / "structure.html");
  EXPECT_NE(html.find("<h2>Structure</h2>"), std::string::npos);
  EXPECT_NE(html.find("<th>kind</th><td>moored</td>"), std::string::npos);
  // Labels a reader knows and numbers for reading (issue #37): no raw keys, no exponents.
  EXPECT_NE(html.find("<th>cycles: mean peak (N)</th><td>1&thinsp;250&thinsp;000</td>"), std::string::npos);
  EXPECT_NE(html.find("<th>station keeping: lines 0: fairlead tension (N): max</th><td>340&thinsp;000</td>"),
            std::string::npos);
}

// A structure's hull (a cylinder, a cone) has no ship particulars: floesim-hull writes "particulars": null and says
// why in "particulars_error". The page then describes the hull by its waterline's hydrostatics, and says why.
TEST_F(TinyRun, AStructuresHullWithoutShipParticularsIsDescribedByItsWaterline) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const fs::path run = copy_run("structure-hull");
  Json hull = load_json_file(run / "hull/hull.json");
  hull["particulars"] = nullptr;
  hull["particulars_error"] = "no bow to measure a stem angle on";
  std::ofstream(run / "hull/hull.json") << hull.dump(2);
  write_report(run, ReportOptions{}, root_ / "structure-hull.html", Json::object());
  const std::string html = read_text(root_ / "structure-hull.html");
  const std::string table = first_screen_table(html);
  ASSERT_FALSE(table.empty());
  char length[80];
  std::snprintf(length, sizeof length, "length %.1f&nbsp;m at the waterline",
                hull["hydrostatics"]["length_wl_m"].get<double>());
  EXPECT_NE(table.find(length), std::string::npos) << table;
  EXPECT_EQ(table.find("stem angle"), std::string::npos) << table;
  EXPECT_NE(html.find("no bow to measure a stem angle on"), std::string::npos);
}

// A structure is held, not driven: its first screen says how it is held and how the ice drifts to it, with no
// propulsion row or vessel speed (the vessel's propulsion settings, resolved with their defaults, do not apply to
// it), and its loads are named ice loads, not resistance.
TEST_F(TinyRun, AStructuresFirstScreenSaysHowItIsHeldAndHowTheIceDrifts) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const fs::path run = copy_run("structure-held");
  Json s = load_json_file(run / "sim/summary.json");
  ASSERT_TRUE(s["settings"]["vessel"].contains("propulsion")) << "the settings the page must not show";
  s["settings"]["vessel"]["station_keeping"] = {
      {"mode", "compliant"}, {"compliant", {{"natural_frequency_hz", 0.45}, {"damping_ratio", 0.02}}}};
  s["settings"]["drift"] = {{"speed_mps", 0.5}, {"direction_deg", 180.0}};
  std::ofstream(run / "sim/summary.json") << s.dump(2);
  write_report(run, ReportOptions{}, root_ / "structure-held.html", Json::object());
  const std::string html = read_text(root_ / "structure-held.html");
  const std::string table = first_screen_table(html);
  ASSERT_FALSE(table.empty());
  EXPECT_EQ(table.find("Propulsion"), std::string::npos) << table;
  EXPECT_EQ(table.find("Mean speed"), std::string::npos) << table;
  EXPECT_NE(table.find("<th>Station keeping</th><td>compliant: its first mode at 0.45&nbsp;Hz, damping 2&nbsp;% "
                       "of critical</td>"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("<th>Ice drift</th><td>0.50&nbsp;m/s towards 180&nbsp;&deg;"), std::string::npos) << table;
  const size_t loads = html.find("<h2>Mean loads"), next = html.find("<h2>", loads + 1);
  const std::string load_table = html.substr(loads, next - loads);
  EXPECT_NE(load_table.find("mean ice load on the structure (&minus;Fx, steady part"), std::string::npos)
      << load_table;
  EXPECT_EQ(load_table.find("resistance"), std::string::npos) << load_table;
  // A ship's run keeps its propulsion row.
  write_report(run_, ReportOptions{}, root_ / "ship-first.html", Json::object());
  EXPECT_NE(read_text(root_ / "ship-first.html").find("<th>Propulsion</th>"), std::string::npos);
}

TEST_F(TinyRun, MissingVideoIsSaidOnThePageAndInStdout) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const fs::path run = copy_run("novideo");
  fs::remove(run / "video/transit.mp4");
  const fs::path out = root_ / "novideo.html";
  const Cmd c = sh("'" + (kBin / "floesim-report").string() + "' --run '" + run.string() + "' --out '" +
                       out.string() + "'",
                   root_ / "novideo.log");
  ASSERT_EQ(c.code, 0) << c.text;
  EXPECT_NE(c.text.find("missing from the run (1)"), std::string::npos) << c.text;
  EXPECT_NE(c.text.find("video/transit.mp4"), std::string::npos) << c.text;
  const std::string html = read_text(out);
  EXPECT_NE(html.find("id=\"missing\""), std::string::npos);
  EXPECT_NE(html.find("The video is missing (video/transit.mp4)"), std::string::npos);
  EXPECT_EQ(html.find("<video"), std::string::npos);
}

TEST_F(TinyRun, VideoLargerThanTheLimitIsNamedNotEmbedded) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  ReportOptions o;
  o.max_video_mb = 1e-6;  // 1 byte
  const auto r = write_report(run_, o, root_ / "big.html", Json::object());
  EXPECT_FALSE(r.video_embedded);
  const std::string html = read_text(root_ / "big.html");
  EXPECT_EQ(html.find("<video"), std::string::npos);
  EXPECT_NE(html.find("id=\"video-not-embedded\""), std::string::npos);
}

TEST_F(TinyRun, NoSummaryIsAnErrorAndWritesNothing) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const fs::path run = copy_run("nosummary");
  fs::remove(run / "sim/summary.json");
  const fs::path out = root_ / "nosummary" / "report.html";
  const Cmd c = sh("'" + (kBin / "floesim-report").string() + "' --run '" + run.string() + "' --out '" +
                       out.string() + "'",
                   root_ / "nosummary.log");
  EXPECT_NE(c.code, 0);
  EXPECT_NE(c.text.find("sim/summary.json is missing"), std::string::npos) << c.text;
  EXPECT_FALSE(fs::exists(out));
  // No page and no temporary one (the run's own report/ folder is the runner's).
  for (const auto& e : fs::directory_iterator(out.parent_path())) {
    if (e.is_directory()) continue;
    EXPECT_EQ(e.path().filename().string().find("report"), std::string::npos) << e.path();
  }
}

// Every stage's warnings on the first screen (issue #37, part 3): a run without any says so; the simulation's own
// and a warning of the floes' maker carried into summary.json are listed, escaped. The video's sidecar and note say how fast it plays:
// the case's output interval times the frames per second.
TEST_F(TinyRun, WarningsAndThePlaybackSpeedAreOnThePage) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  const Json summary = load_json_file(run_ / "sim/summary.json");
  ASSERT_TRUE(summary.contains("warnings")) << "summary.json lists the warnings, also when there are none";
  // The tiny run's floes come from a clean digitisation. The simulation warns of its own, each warning naming the
  // stage: of floes it left out (summary.json's removed_floes: those under the vessel at the start) and of an
  // interval that cannot be trusted (the interval's own flag).
  const size_t removed = summary["removed_floes"].get<size_t>();
  const bool trusted = summary["mean_surge_ice_load_interval"]["meaningful"].get<bool>();
  std::vector<std::string> expected;
  if (!trusted) expected.push_back("simulate: the mean surge ice load's 95 % interval cannot be trusted");
  if (removed > 0)
    expected.push_back("simulate: " + std::to_string(removed) + (removed == 1 ? " floe was" : " floes were") +
                       " left out of the run");
  ASSERT_EQ(summary["warnings"].size(), expected.size()) << summary["warnings"].dump();
  write_report(run_, ReportOptions{}, root_ / "own.html", Json::object());
  const std::string own = read_text(root_ / "own.html");
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(summary["warnings"][k].get<std::string>().rfind(expected[k], 0), 0u) << summary["warnings"][k];
    EXPECT_NE(own.find("<li class=\"warning\">" + expected[k]), std::string::npos) << expected[k];
  }
  const fs::path quiet = copy_run("quiet");
  Json none = summary;
  none["warnings"] = Json::array();
  std::ofstream(quiet / "sim/summary.json") << none.dump(2);
  write_report(quiet, ReportOptions{}, root_ / "nowarn.html", Json::object());
  const std::string clean = read_text(root_ / "nowarn.html");
  EXPECT_NE(clean.find("No stage warned."), std::string::npos);
  const Json side = load_json_file(run_ / "video/transit.json");
  const double every = load_json_file(run_ / "config/simulate.json").value("output_interval_s", 0.2);
  EXPECT_DOUBLE_EQ(side["playback_speed"].get<double>(), every * side["fps"].get<double>());
  EXPECT_NE(clean.find("real time ("), std::string::npos);
  const fs::path run = copy_run("warned");
  Json s = summary;
  s["warnings"] = {"floes (floes.geojson): image.png: no water found <one class>"};
  std::ofstream(run / "sim/summary.json") << s.dump(2);
  write_report(run, ReportOptions{}, root_ / "warned.html", Json::object());
  const std::string html = read_text(root_ / "warned.html");
  EXPECT_NE(html.find("<li class=\"warning\">floes (floes.geojson): image.png: no water found &lt;one class&gt;</li>"),
            std::string::npos);
  EXPECT_LT(html.find("<h2>Warnings</h2>"), html.find("<h2>Video</h2>")) << "before the details";
  // The video sidecar's warnings too, named by their stage.
  Json cut = side;
  cut["warnings"] = {"the video shows the first 5 of the run's 12 frames"};
  std::ofstream(run / "video/transit.json") << cut.dump(2);
  write_report(run, ReportOptions{}, root_ / "cut.html", Json::object());
  EXPECT_NE(read_text(root_ / "cut.html").find("<li class=\"warning\">render: the video shows the first 5"),
            std::string::npos);
}

// The first screen says what was run in words a reader knows (issue #37, part 2): no raw key (a dot or an
// underscore) in a label, the hull's waterline length and the floes' concentration as their artefacts give them,
// how the vessel was driven.
TEST_F(TinyRun, TheFirstScreenSaysWhatWasRunInHumanLabels) {
  ASSERT_EQ(ran_.code, 0) << ran_.text;
  write_report(run_, ReportOptions{}, root_ / "first.html", Json::object());
  const std::string html = read_text(root_ / "first.html");
  const std::string table = first_screen_table(html);
  ASSERT_FALSE(table.empty());
  EXPECT_LT(html.find("<table id=\"what-was-run\">"), html.find("<h2>Mean loads")) << "before the answer";
  std::vector<std::string> labels;
  for (size_t p = table.find("<th>"); p != std::string::npos; p = table.find("<th>", p + 1))
    labels.push_back(table.substr(p + 4, table.find("</th>", p) - p - 4));
  for (const std::string& l : labels)
    EXPECT_EQ(l.find_first_of("._"), std::string::npos) << "a raw key as a label: " << l;
  for (const char* want : {"Hull", "Ice", "Propulsion", "Duration"})
    EXPECT_NE(std::find(labels.begin(), labels.end(), want), labels.end()) << want;
  const Json hull = load_json_file(run_ / "hull/hull.json");
  char length[64];
  std::snprintf(length, sizeof length, "length %.1f&nbsp;m at the waterline", hull["particulars"]["length_m"].get<double>());
  EXPECT_NE(table.find(length), std::string::npos) << table;
  const Json stats = load_json_file(run_ / "floes/stats.json");
  char conc[64];
  std::snprintf(conc, sizeof conc, "concentration %.0f&nbsp;%%", 100 * stats["ice_concentration"].get<double>());
  EXPECT_NE(table.find(conc), std::string::npos) << table;
}
