// Options described for programs: each field's unit and meaning by its key path, from the same visit that reads,
// writes and documents the options (pipeline/options.h). A stage prints it with --describe-config
// (pipeline/stage_main.h), and the sweep runner labels its axes with it.
#pragma once
#include <string>
#include <vector>

#include "pipeline/options.h"

namespace floesim {

// Every field's unit and meaning by its key path: {"vessel.propulsion.speed_mps": {"unit": "m/s", "doc": "..."},
// "ridges[].keel_depth_m": {...}}; a list's item fields as `key[].field`, as in the Markdown table.
class OptionDescriber {
 public:
  explicit OptionDescriber(std::string prefix = "") : prefix_(std::move(prefix)) {}
  template <class T>
  void field(const char* key, const T&, const char* unit, const char* doc, Check<T> = {}) {
    out[prefix_ + key] = {{"unit", unit}, {"doc", doc}};
  }
  template <class S>
  void section(const char* key, S& sub, const char*) {
    OptionDescriber w(prefix_ + key + ".");
    sub.visit(w);
    out.update(w.out);
  }
  template <class S>
  void list(const char* key, std::vector<S>&, const char* doc) {
    out[prefix_ + key] = {{"unit", "-"}, {"doc", doc}};
    S item;
    OptionDescriber w(prefix_ + key + "[].");
    item.visit(w);
    out.update(w.out);
  }
  void problem(const std::string&, const std::string&) {}
  Json out = Json::object();

 private:
  std::string prefix_;
};

template <class S>
Json options_description(const S& s) {
  OptionDescriber w;
  S copy = s;
  copy.visit(w);
  return w.out;
}

}  // namespace floesim
