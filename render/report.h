// The report: one self-contained HTML file for a run folder as `floesim run` writes it. It holds the case and the
// settings that produced the run (RUN/config/*.json), the input photo and the digitised field with its statistics,
// the hull's particulars, the load plot, a table of mean loads with the error against reference values given in
// the report config, the fracture statistics and the video. Everything is inlined (images and the video as base64
// data: URIs, a small inline style), so the page opens from disk with no network. Missing artefacts are listed in
// a box on the page (and returned); a run without sim/summary.json is an error and nothing is written.
// floesim-report is a thin main over write_report().
#pragma once
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/options.h"

namespace floesim::render {

// A measured or published mean surge ice load to compare the simulation with.
struct ReferenceLoad {
  std::string label;  // e.g. "full scale (Oden, 2018)"
  double kN = 0;      // kN; the mean surge ice resistance

  template <class V>
  void visit(V& v) {
    v.field("label", label, "-", "what the reference is (shown in the table)");
    v.field("kN", kN, "kN", "mean surge ice resistance of the reference", positive());
  }
};

struct ReportOptions {
  std::string title = "";                        // page title; "" for "floesim report: <case name>"
  double reference_kN = 0;                       // kN; one reference value (0: none)
  std::string reference_label = "reference";     // its label
  std::vector<ReferenceLoad> references;         // further references, e.g. [{"label": "SAMS", "kN": 974}]
  double max_video_mb = 50;                      // MB (10^6 bytes); a larger video is named, not embedded

  template <class V>
  void visit(V& v) {
    v.field("title", title, "-",
            "page title (empty: \"floesim report: <case folder name>\", else the run folder's name)");
    v.field("reference_kN", reference_kN, "kN", "a reference mean surge ice resistance (0: none)", non_negative());
    v.field("reference_label", reference_label, "-", "label of reference_kN");
    v.list("references", references, "further references: a list of {\"label\", \"kN\"}");
    v.field("max_video_mb", max_video_mb, "MB", "largest video embedded; a larger one is named instead",
            positive());
  }
  // reference_kN (when > 0) first, then `references`.
  std::vector<ReferenceLoad> all_references() const;
};

ReportOptions read_report_options(const std::filesystem::path& config);

// The simulated mean against one reference: error = mean - reference, relative = error / reference.
struct ReferenceComparison {
  std::string label;
  double reference_kN = 0;
  double error_kN = 0;
  double error_percent = 0;
};
ReferenceComparison compare_to_reference(double mean_kN, const ReferenceLoad& ref);

struct ReportSummary {
  std::filesystem::path out;
  uintmax_t bytes = 0;                      // size of the page
  double mean_kN = 0;                       // summary.json mean_surge_ice_resistance_N / 1000
  double std_kN = 0;                        // summary.json std_surge_ice_load_N / 1000 (NaN if absent)
  // summary.json mean_surge_ice_load_interval: the 95 % half width of the mean (NaN if absent or none), how it was
  // taken, whether it means anything and, if not, why.
  double half_width_kN = 0;
  std::string interval_method, interval_note;
  bool interval_meaningful = false;
  double moving_average_max_kN = 0;         // the applying moving average's largest resistance (NaN if absent)
  double moving_average_window_s = 0;
  std::vector<ReferenceComparison> references;
  std::vector<std::string> missing;         // artefacts the page lacks, "path (what)", relative to the run folder
  double identified_kN = NAN;                // identify/identified.json's mean resistance (NaN: no identification)
  double identified_known_kN = NAN;          // ... the known (simulated) load's over the same window (round trip)
  double identified_error_percent = NAN;     // identified against known, % (round trip)
  bool video_embedded = false;
  uintmax_t video_bytes = 0;                // 0 if no video
};

// Standard base64 (RFC 4648, with padding, no line breaks); OpenSSL's EVP_EncodeBlock in chunks.
std::string base64_encode(std::string_view bytes);
// Escapes &, <, >, " and ' for HTML text and attribute values.
std::string html_escape(std::string_view text);

// Writes the page to `out` atomically. Error (nothing written) if run_dir has no sim/summary.json or it is not a
// readable summary.
ReportSummary write_report(const std::filesystem::path& run_dir, const ReportOptions& o,
                           const std::filesystem::path& out, const Json& resolved_config);
// `config` may be empty: the defaults (no reference).
ReportSummary write_report(const std::filesystem::path& run_dir, const std::filesystem::path& config,
                           const std::filesystem::path& out);

// ---- A sweep's report (floesim-report --sweep) ----

struct SweepReportSummary {
  std::filesystem::path out;
  uintmax_t bytes = 0;
  size_t grid_points = 0, members = 0, failed = 0;
  std::vector<std::string> missing;  // artefacts the page lacks, relative to the sweep folder
};

// One self-contained page for a sweep folder as `floesim sweep` leaves it (the gather's sweep.json and plots,
// plan.json): the sweep and its base case, the ensemble mean of every grid point with its 95 % interval and its
// error against each reference value of `o`, the gathered plots, every member's row, and the failed members with
// their errors. Error (nothing written) if the folder has no readable sweep.json (the gather has not run).
SweepReportSummary write_sweep_report(const std::filesystem::path& sweep_dir, const ReportOptions& o,
                                      const std::filesystem::path& out, const Json& resolved_config);

}  // namespace floesim::render
