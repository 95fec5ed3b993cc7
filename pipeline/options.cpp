#include "pipeline/options.h"

#include <algorithm>
#include <fstream>
#include <sstream>

namespace floesim {

Check<double> positive() {
  return [](const double& x) { return x > 0 && std::isfinite(x) ? "" : std::string("must be > 0"); };
}
Check<double> non_negative() {
  return [](const double& x) { return x >= 0 && std::isfinite(x) ? "" : std::string("must be >= 0"); };
}
Check<std::vector<double>> plane_point() {
  return [](const std::vector<double>& p) {
    if (p.size() != 2) return std::string("must be [x, y] (2 numbers)");
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) return std::string("must be finite numbers");
    return std::string();
  };
}
Check<double> in_range(double lo, double hi) {
  return [lo, hi](const double& x) {
    return x >= lo && x <= hi ? std::string()
                              : "must be in [" + Json(lo).dump() + ", " + Json(hi).dump() + "]";
  };
}
Check<int> positive_int() {
  return [](const int& x) { return x > 0 ? "" : std::string("must be > 0"); };
}
Check<int> int_in_range(int lo, int hi) {
  return [lo, hi](const int& x) {
    return x >= lo && x <= hi ? std::string() : "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  };
}
Check<std::string> one_of(std::vector<std::string> choices) {
  return [choices](const std::string& s) {
    if (std::find(choices.begin(), choices.end(), s) != choices.end()) return std::string();
    std::string m = "must be one of";
    for (auto& c : choices) m += " \"" + c + "\"";
    return m;
  };
}

Json load_json_file(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open (does the file exist and is it readable?)");
  try {
    return Json::parse(in, nullptr, true, /*ignore_comments=*/true);
  } catch (const Json::exception& e) {
    // Not only parse_error: a number beyond a double ("1e999") is out_of_range.406 (found by tests/fuzz/fuzz_floes;
    // it escaped as an "internal error" instead of this message).
    throw Error(file.string() + ": not valid JSON: " + e.what());
  }
}

OptionReader::OptionReader(const Json& j, std::string file, std::string path)
    : OptionReader(j, std::move(file), std::move(path), std::make_shared<std::vector<std::string>>()) {}

OptionReader::OptionReader(const Json& j, std::string file, std::string path,
                           std::shared_ptr<std::vector<std::string>> p)
    : j_(j), file_(std::move(file)), path_(std::move(path)), problems_(std::move(p)) {}

namespace {

// Levenshtein distance between two keys (insertions, deletions and substitutions of one character each).
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string closest_key(const std::string& key, const std::vector<std::string>& known) {
  std::string best;
  size_t best_d = std::max<size_t>(2, key.size() / 3) + 1;  // a typo: at most a third of the key (2 for short ones)
  for (const std::string& k : known)
    if (const size_t d = edit_distance(key, k); d < best_d) best = k, best_d = d;
  return best;
}

void OptionReader::check_unknown() {
  if (!j_.is_object()) return;
  for (auto it = j_.begin(); it != j_.end(); ++it) {
    if (std::find(seen_.begin(), seen_.end(), it.key()) != seen_.end()) continue;
    std::string known;
    for (auto& s : seen_) known += (known.empty() ? "" : ", ") + s;
    const std::string guess = closest_key(it.key(), seen_);
    problems_->push_back(where(it.key()) + " is not a known key" +
                         (guess.empty() ? std::string(" (a typo?); known") : "; did you mean " + guess + "? Known") +
                         " keys here: " + known);
  }
}

void OptionReader::finish() {
  if (problems_->empty()) return;
  std::ostringstream os;
  os << file_ << ": " << problems_->size() << " problem" << (problems_->size() > 1 ? "s" : "") << " in the options:";
  for (auto& p : *problems_) os << "\n  - " << p;
  throw Error(os.str());
}

}  // namespace floesim
