#include "render/render_options.h"

#include <cctype>

namespace floesim::render {

Check<std::string> hex_colour() {
  return [](const std::string& s) {
    bool ok = s.size() == 7 && s[0] == '#';
    for (size_t i = 1; ok && i < s.size(); ++i) ok = std::isxdigit(static_cast<unsigned char>(s[i])) != 0;
    return ok ? std::string() : std::string("must be a colour \"#rrggbb\"");
  };
}

void parse_hex_colour(const std::string& s, float rgb[3]) {
  for (int i = 0; i < 3; ++i) rgb[i] = static_cast<float>(std::stoi(s.substr(1 + 2 * i, 2), nullptr, 16)) / 255.f;
}

}  // namespace floesim::render
