// Strict reading of JSON options structs (Drake-style visitor): one `visit` per struct serves reading,
// writing (the echo of the resolved configuration) and documentation. Unknown keys are errors; all problems
// are collected and reported at once with the file and the full key path.
//
//   struct DigitiseOptions {
//     double min_floe_area_m2 = 20.0;  // smallest floe kept
//     template <class V> void visit(V& v) {
//       v.field("min_floe_area_m2", min_floe_area_m2, "m^2", "smallest floe kept", positive());
//     }
//   };
//   auto opts = read_options<DigitiseOptions>(json, "case.json", "digitise");
#pragma once
#include <array>
#include <cmath>
#include <memory>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/error.h"

namespace floesim {

using Json = nlohmann::json;

// A check returns an empty string when the value is acceptable, else what is wrong ("must be > 0").
template <class T>
using Check = std::function<std::string(const T&)>;

Check<double> positive();
Check<double> non_negative();
Check<double> in_range(double lo, double hi);  // closed interval
Check<int> positive_int();
Check<int> int_in_range(int lo, int hi);
Check<std::string> one_of(std::vector<std::string> choices);
// A point in the plane: [x, y], two finite numbers.
Check<std::vector<double>> plane_point();

// Reads a JSON file; errors name the file and the line/column of a syntax error.
Json load_json_file(const std::filesystem::path& file);

// Collects problems while visiting; throws one Error listing all of them in finish().
// The known key a mistyped one most likely meant (edit distance at most a third of its length, 2 for short keys);
// "" when none is that close.
std::string closest_key(const std::string& key, const std::vector<std::string>& known);

class OptionReader {
 public:
  OptionReader(const Json& j, std::string file, std::string path);

  template <class T>
  void field(const char* key, T& value, const char* unit, const char* doc, Check<T> check = {}) {
    (void)unit;
    (void)doc;
    seen_.push_back(key);
    if (!j_.is_object() || !j_.contains(key)) {
      if (check) check_value(key, value, check);  // defaults are checked too (a default of 0 may be a "must set")
      return;
    }
    bool ok = false;
    try {
      ok = get_value(j_.at(key), value);
    } catch (const std::exception&) {
    }
    if (!ok) {
      problems_->push_back(where(key) + " has the wrong type: expected " + type_name<T>() + ", got " +
                           j_.at(key).dump());
      return;
    }
    if (check) check_value(key, value, check);
  }

  // A nested options struct under `key`.
  template <class S>
  void section(const char* key, S& sub, const char* doc) {
    (void)doc;
    seen_.push_back(key);
    Json empty = Json::object();
    const Json& sj = (j_.is_object() && j_.contains(key)) ? j_.at(key) : empty;
    if (!sj.is_object()) {
      problems_->push_back(where(key) + " must be an object, got " + sj.dump());
      return;
    }
    OptionReader r(sj, file_, where(key), problems_);
    sub.visit(r);
    r.check_unknown();
  }

  // A list of options structs under `key` (a JSON array of objects; absent: the default list). Problems name the
  // item: "vessel.propellers[1].diameter_m must be > 0".
  template <class S>
  void list(const char* key, std::vector<S>& items, const char* doc) {
    (void)doc;
    seen_.push_back(key);
    if (!j_.is_object() || !j_.contains(key)) return;
    const Json& a = j_.at(key);
    if (!a.is_array()) {
      problems_->push_back(where(key) + " must be an array of objects, got " + a.dump());
      return;
    }
    items.assign(a.size(), S{});
    for (size_t i = 0; i < a.size(); ++i) {
      const std::string path = where(key) + "[" + std::to_string(i) + "]";
      if (!a[i].is_object()) {
        problems_->push_back(path + " must be an object, got " + a[i].dump());
        continue;
      }
      OptionReader r(a[i], file_, path, problems_);
      items[i].visit(r);
      r.check_unknown();
    }
  }

  // Records a cross-field problem found by the struct's own validation.
  void problem(const std::string& key, const std::string& what) { problems_->push_back(where(key) + " " + what); }

  void check_unknown();
  void finish();  // throws Error if any problem was recorded

  const std::string& file() const { return file_; }

 private:
  OptionReader(const Json& j, std::string file, std::string path, std::shared_ptr<std::vector<std::string>> p);
  std::string where(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  template <class T>
  void check_value(const char* key, const T& value, const Check<T>& check) {
    std::string msg = check(value);
    if (!msg.empty()) problems_->push_back(where(key) + " " + msg + ", got " + Json(value).dump());
  }
  // The JSON value as T; false if it is not one. nlohmann's get<int>() casts a number unchecked (2.5 reads as 2,
  // 1e20 is undefined behaviour; found by tests/fuzz/fuzz_options), so an integer field accepts only an integral
  // value that fits it (3, 3.0 and 3e0 alike).
  template <class T>
  static bool get_value(const Json& v, T& out) {
    if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
      using L = std::numeric_limits<T>;
      if (v.is_number_unsigned()) {
        const auto x = v.get<uint64_t>();
        if (x > static_cast<uint64_t>(L::max())) return false;
        out = static_cast<T>(x);
        return true;
      }
      if (v.is_number_integer()) {
        const auto x = v.get<int64_t>();
        if (x < 0 && !L::is_signed) return false;
        if (x > 0 && static_cast<uint64_t>(x) > static_cast<uint64_t>(L::max())) return false;
        if (L::is_signed && x < static_cast<int64_t>(L::min())) return false;
        out = static_cast<T>(x);
        return true;
      }
      if (v.is_number_float()) {
        const double d = v.get<double>();
        // [min, 2^digits): both bounds are exact doubles for every integer type.
        if (!(std::floor(d) == d && d >= static_cast<double>(L::min()) && d < std::ldexp(1.0, L::digits)))
          return false;
        out = static_cast<T>(d);
        return true;
      }
      return false;
    } else {
      out = v.get<T>();
      return true;
    }
  }
  template <class T>
  static const char* type_name() {
    if constexpr (std::is_same_v<T, bool>) return "true/false";
    else if constexpr (std::is_integral_v<T>) return "an integer";
    else if constexpr (std::is_floating_point_v<T>) return "a number";
    else if constexpr (std::is_same_v<T, std::string>) return "a string";
    else return "an array";
  }

  const Json& j_;
  std::string file_, path_;
  std::vector<std::string> seen_;
  std::shared_ptr<std::vector<std::string>> problems_;
};

// Writes the resolved values back to JSON (the echo recorded in every artefact's provenance).
class OptionWriter {
 public:
  template <class T>
  void field(const char* key, const T& value, const char*, const char*, Check<T> = {}) {
    out[key] = value;
  }
  template <class S>
  void section(const char* key, S& sub, const char*) {
    OptionWriter w;
    sub.visit(w);
    out[key] = w.out;
  }
  template <class S>
  void list(const char* key, std::vector<S>& items, const char*) {
    Json a = Json::array();
    for (S& item : items) {
      OptionWriter w;
      item.visit(w);
      a.push_back(w.out);
    }
    out[key] = a;
  }
  void problem(const std::string&, const std::string&) {}
  Json out = Json::object();
};

// Lists fields as Markdown table rows (key, default, unit, meaning) for --help-config and the README.
class OptionDocWriter {
 public:
  explicit OptionDocWriter(std::string prefix = "") : prefix_(std::move(prefix)) {}
  template <class T>
  void field(const char* key, const T& value, const char* unit, const char* doc, Check<T> = {}) {
    rows += "| `" + prefix_ + key + "` | `" + Json(value).dump() + "` | " + unit + " | " + doc + " |\n";
  }
  template <class S>
  void section(const char* key, S& sub, const char*) {
    OptionDocWriter w(prefix_ + key + ".");
    sub.visit(w);
    rows += w.rows;
  }
  // A list: its default, then the fields of one item (`key[].field`) with an item's defaults.
  template <class S>
  void list(const char* key, std::vector<S>& items, const char* doc) {
    OptionWriter def;
    def.list(key, items, doc);
    rows += "| `" + prefix_ + key + "` | `" + def.out[key].dump() + "` | - | " + doc + " |\n";
    S item;
    OptionDocWriter w(prefix_ + key + "[].");
    item.visit(w);
    rows += w.rows;
  }
  void problem(const std::string&, const std::string&) {}
  std::string rows;

 private:
  std::string prefix_;
};

// Reads struct S from j (whose location is `file` and key path `path`), strictly. The struct's visit may call
// v.problem(...) for cross-field checks.
template <class S>
S read_options(const Json& j, const std::string& file, const std::string& path = "") {
  S s;
  if (!j.is_object()) throw Error(file + ": " + (path.empty() ? "the top level" : path) + " must be a JSON object");
  OptionReader r(j, file, path);
  s.visit(r);
  r.check_unknown();
  r.finish();
  return s;
}

// Runs the options' own checks (ranges and cross-field checks) on a struct filled in code rather than read from
// JSON, and throws every problem at once as read_options does, naming `where`. The visit reads a copy: a visit
// takes its struct by reference for reading, and the caller's stays as it is.
template <class S>
void check_options(const S& s, const std::string& where) {
  const Json none = Json::object();  // the reader keeps a reference: must outlive it
  OptionReader r(none, where, "");
  S copy = s;
  copy.visit(r);
  r.finish();
}

template <class S>
Json options_to_json(const S& s) {
  OptionWriter w;
  S copy = s;  // visit takes its struct by reference, for reading as for writing
  copy.visit(w);
  return w.out;
}

template <class S>
std::string options_doc(const S& s) {
  OptionDocWriter w;
  S copy = s;
  copy.visit(w);
  return "| key | default | unit | meaning |\n|---|---|---|---|\n" + w.rows;
}

}  // namespace floesim
