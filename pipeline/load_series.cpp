#include "pipeline/load_series.h"

#include <cmath>

#include "pipeline/error.h"
#include "pipeline/options.h"
#include "pipeline/signal.h"

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

FilteredLoad auto_filtered_surge_ice_resistance_kN(const Results& r, const std::string& source) {
  const std::vector<double> total = surge_ice_resistance_kN(r, source);
  const std::vector<double>& t = r.get("time_s");
  // The rigid part as recorded (series ice_load_rigid beside ice_load_compliant); a file whose split is absent or
  // empty (all zero while the load is not) is of the one law its contact_model attribute names.
  std::vector<double> rigid(total.size(), 0.0);
  bool split = false;
  for (const char* name : {"ice_load_rigid", "ice_load_compliant"}) {
    if (!r.series.count(name)) continue;
    const std::vector<double>& load = r.get(name);
    FLOESIM_REQUIRE(load.size() == 6 * t.size(), source, ": series ", name, " does not have 6 columns per step");
    for (size_t i = 0; i < t.size(); ++i) {
      FLOESIM_REQUIRE(std::isfinite(load[6 * i]), source, ": ", name, " is not finite at step ", i);
      split = split || load[6 * i] != 0;
      if (std::string(name) == "ice_load_rigid") rigid[i] = -load[6 * i] / 1000.0;
    }
  }
  if (!split && recorded_contact_model(r, source) == "rigid") rigid = total;
  bool any_rigid = false, any_compliant = false;
  std::vector<double> compliant(total.size());
  for (size_t i = 0; i < total.size(); ++i) {
    compliant[i] = total[i] - rigid[i];
    any_rigid = any_rigid || rigid[i] != 0;
    any_compliant = any_compliant || compliant[i] != 0;
  }
  if (!split) any_rigid = recorded_contact_model(r, source) == "rigid";
  const double dt = t.size() >= 2 ? (t.back() - t.front()) / static_cast<double>(t.size() - 1) : 1.0;
  FilteredLoad f;
  if (any_rigid && !any_compliant) {
    f.window_s = 20.0;
    f.kN = moving_average_centred(total, window_samples(20.0, dt));
    f.text = "20 s centred moving average (rigid contacts)";
  } else if (!any_rigid) {
    f.window_s = 0.5;
    f.kN = moving_average_centred(total, window_samples(0.5, dt));
    f.text = "0.5 s centred moving average (compliant contacts)";
  } else {
    f.window_s = 20.0;
    const std::vector<double> a = moving_average_centred(rigid, window_samples(20.0, dt));
    const std::vector<double> b = moving_average_centred(compliant, window_samples(0.5, dt));
    f.kN.resize(total.size());
    for (size_t i = 0; i < total.size(); ++i) f.kN[i] = a[i] + b[i];
    f.text = "rigid part over 20 s + compliant part over 0.5 s (centred moving averages, summed)";
  }
  return f;
}

double recorded_steady_start_s(const Results& r, const std::string& source) {
  if (!r.attributes.contains("steady_start_s")) return 0;
  FLOESIM_REQUIRE(r.attributes["steady_start_s"].is_number(), source, ": attribute steady_start_s must be a number");
  return r.attributes["steady_start_s"].get<double>();
}

}  // namespace floesim
