#include "pipeline/load_series.h"

#include <cmath>

#include "pipeline/error.h"
#include "pipeline/options.h"

namespace floesim {

std::vector<double> surge_ice_resistance_kN(const Results& r, const std::string& source) {
  const std::vector<double>& t = r.get("time_s");
  const std::vector<double>& load = r.get("ice_load");
  FLOESIM_REQUIRE(load.size() == 6 * t.size(), source, ": series ice_load does not have 6 columns per step");
  std::vector<double> res(t.size());
  for (size_t i = 0; i < t.size(); ++i) res[i] = -load[6 * i] / 1000.0;
  for (size_t i = 0; i < t.size(); ++i)
    FLOESIM_REQUIRE(std::isfinite(res[i]) && std::isfinite(t[i]), source, ": ice_load or time_s is not finite at step ",
                    i, " (t = ", t[i], " s); the simulation blew up");
  return res;
}

std::string recorded_contact_model(const Results& r, const std::string& source) {
  const Json& attrs = r.attributes;
  if (!attrs.contains("contact_model")) return "rigid";
  FLOESIM_REQUIRE(attrs["contact_model"].is_string(), source, ": attribute contact_model must be a string");
  const std::string m = attrs["contact_model"].get<std::string>();
  FLOESIM_REQUIRE(m == "rigid" || m == "compliant" || m == "mixed", source, ": attribute contact_model is \"", m,
                  "\"; expected rigid, compliant or mixed");
  return m;
}

double auto_moving_average_window_s(const Results& r, const std::string& source) {
  return recorded_contact_model(r, source) == "rigid" ? 20.0 : 0.5;
}

double recorded_steady_start_s(const Results& r, const std::string& source) {
  if (!r.attributes.contains("steady_start_s")) return 0;
  FLOESIM_REQUIRE(r.attributes["steady_start_s"].is_number(), source, ": attribute steady_start_s must be a number");
  return r.attributes["steady_start_s"].get<double>();
}

}  // namespace floesim
