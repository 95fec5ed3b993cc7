// floesim-hull: writes the parametric icebreaker (Oden's main particulars by default), a structure from parameters
// (a config with "structure": cylinder, caisson, cone), or places and decomposes a user's mesh (a config with
// "file"), as an OBJ of convex parts with a JSON sidecar of particulars, hydrostatics, the angles and lengths the
// ice-resistance formulas take (measured from the mesh) and provenance.
#include <iostream>

#include <CLI/CLI.hpp>

#include "pipeline/options.h"
#include "pipeline/options_describe.h"
#include "pipeline/stage_main.h"
#include "sim/vessel/hull.h"

namespace {

// A structure's config: {"structure": {...}} (errors name structure.<key>).
struct StructureHullConfig {
  floesim::sim::StructureShapeOptions structure;
  template <class V>
  void visit(V& v) {
    v.section("structure", structure, "a structure's hull from parameters: cylinder, caisson or cone");
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a hull as an OBJ of convex parts (one object per part) plus FILE.json with its hydrostatics\n"
               "and the particulars the ice-resistance formulas take (stem angle, entrance angle, flare, L, B, T,\n"
               "parallel midbody, bow length; measured from the mesh): the parametric icebreaker (config: generator\n"
               "options), a structure from parameters (config with \"structure\": cylinder, caisson, cone), or a\n"
               "user's mesh placed in the hull frame and cut into convex parts (config with \"file\":\n"
               "the case's hull section).",
               "floesim-hull"};
  std::string config, out;
  bool help_config = false, check_config = false;
  app.add_option("--config", config, "JSON object of hull options (see --help-config); defaults if omitted");
  app.add_option("--out", out, "output OBJ file; the sidecar is written beside it with extension .json");
  app.add_flag("--check-config", check_config, "read and check --config (strictly, as a run would), write nothing");
  app.add_flag("--help-config", help_config, "print the hull options as Markdown tables and exit");
  // One description for the three kinds of hull config: the generator's keys (a case's hull.generate), the
  // structure's ("structure.*") and the user mesh's (a case's hull section); where a key is in two, the first's.
  floesim::add_describe_config(app, [] {
    floesim::Json all = floesim::options_description(floesim::sim::HullGeneratorOptions{});
    for (const floesim::Json& more : {floesim::options_description(StructureHullConfig{}),
                                      floesim::options_description(floesim::sim::HullImportOptions{})})
      for (auto it = more.begin(); it != more.end(); ++it)
        if (!all.contains(it.key())) all[it.key()] = it.value();
    return all;
  });
  return floesim::run_stage(app, argc, argv, [&] {
    namespace sim = floesim::sim;
    if (help_config) {
      std::cout << "Parametric icebreaker (a config without \"file\" or \"structure\"):\n\n"
                << floesim::options_doc(sim::HullGeneratorOptions{})
                << "\nA structure (a config with \"structure\"; a case's hull.structure):\n\n"
                << floesim::options_doc(StructureHullConfig{})
                << "\nA user's mesh (a config with \"file\", as a case's hull section):\n\n"
                << floesim::options_doc(sim::HullImportOptions{});
      return;
    }
    const floesim::Json j = config.empty() ? floesim::Json::object() : floesim::load_json_file(config);
    if (j.is_object() && j.contains("file")) {  // a user's mesh
      const auto o = floesim::read_options<sim::HullImportOptions>(j, config);
      if (check_config) {
        std::filesystem::path f = o.file;
        if (f.is_relative()) f = std::filesystem::path(config).parent_path() / f;
        if (!std::filesystem::exists(f))
          throw floesim::Error(config + ": file names " + f.string() + ", which does not exist");
        return;
      }
      if (out.empty()) throw floesim::Error("--out FILE.obj is required");
      std::cout << sim::write_imported_hull(o, out, config);
      return;
    }
    if (j.is_object() && j.contains("structure")) {  // a structure from parameters
      const auto o = floesim::read_options<StructureHullConfig>(j, config);
      if (check_config) return;
      if (out.empty()) throw floesim::Error("--out FILE.obj is required");
      std::cout << sim::write_generated_structure(o.structure, out, config);
      return;
    }
    const auto o = floesim::read_options<sim::HullGeneratorOptions>(j, config);
    if (check_config) return;
    if (out.empty()) throw floesim::Error("--out FILE.obj is required");
    std::cout << sim::write_generated_hull(o, out, config);
  });
}
