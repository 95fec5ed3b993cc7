// The CSV readers, one harness per reader (FUZZ_CSV_READER selects it at compile time): the thrust series
// (sim/engine/model.h read_thrust_series), the measured ship data (sim/analysis/identify.h read_measured_csv) and the generic
// numeric CSV (pipeline/csv.h read_numeric_csv).
#include "fuzz_util.h"
#include "pipeline/csv.h"
#include "sim/analysis/identify.h"
#include "sim/engine/model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const auto file = floesim::fuzz::temp_file(".csv");
  floesim::fuzz::write_input(file, data, size);
  floesim::fuzz::expect_ok_or_error([&] {
#if FUZZ_CSV_READER == 1
    std::vector<double> t, f;
    floesim::sim::read_thrust_series(file.string(), t, f);
    if (t.size() != f.size()) std::abort();
#elif FUZZ_CSV_READER == 2
    (void)floesim::sim::read_measured_csv(file);
#else
    const floesim::NumericCsv csv = floesim::read_numeric_csv(file);
    for (const auto& col : csv.columns)
      if (col.size() != (csv.columns.empty() ? 0 : csv.columns[0].size())) std::abort();
#endif
  });
  return 0;
}
