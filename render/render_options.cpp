#include "render/render_options.h"

#include <cctype>
#include <cmath>

namespace floesim::render {

Check<std::string> hex_colour() {
  return [](const std::string& s) {
    bool ok = s.size() == 7 && s[0] == '#';
    for (size_t i = 1; ok && i < s.size(); ++i) ok = std::isxdigit(static_cast<unsigned char>(s[i])) != 0;
    return ok ? std::string() : std::string("must be a colour \"#rrggbb\"");
  };
}

Check<std::vector<std::string>> two_views() {
  return [](const std::vector<std::string>& v) {
    bool ok = v.size() == 2;
    for (const std::string& s : v) ok = ok && (s == "chase" || s == "top" || s == "side");
    return ok ? std::string() : std::string("must be two views, each \"chase\", \"top\" or \"side\"");
  };
}

// The plot's check too (declared in render_options.h): the checks of the render stages' options need no rendering
// code (tests/fuzz/fuzz_options reads every options struct without linking the renderer).
Check<Json> auto_or_number(bool strictly_positive) {
  return [strictly_positive](const Json& j) {
    if (j.is_string() && j.get<std::string>() == "auto") return std::string();
    if (j.is_number() && std::isfinite(j.get<double>()) &&
        (strictly_positive ? j.get<double>() > 0 : j.get<double>() >= 0))
      return std::string();
    return std::string("must be \"auto\" or a number ") + (strictly_positive ? "> 0" : ">= 0");
  };
}

void parse_hex_colour(const std::string& s, float rgb[3]) {
  for (int i = 0; i < 3; ++i) rgb[i] = static_cast<float>(std::stoi(s.substr(1 + 2 * i, 2), nullptr, 16)) / 255.f;
}

}  // namespace floesim::render
