// The numeric CSV reader: what it accepts (blank lines, CRLF, quoted header names, spaces) and how it refuses a bad
// file (the message names the file, the line and the column).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "pipeline/csv.h"
#include "pipeline/error.h"

using namespace floesim;
namespace fs = std::filesystem;

namespace {

fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("floesim_csv_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

std::string error_of(const fs::path& p, const std::vector<std::string>& required = {}) {
  try {
    read_numeric_csv(p, required);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Csv, ReadsColumnsByNameWithBlankLinesCrlfAndQuotes) {
  const fs::path p = write("ok.csv", "\n\"time_s\", x_n\r\n0, 1.5\r\n\r\n0.5,-2e3\r\n");
  const NumericCsv t = read_numeric_csv(p, {"time_s"});
  ASSERT_EQ(t.header, (std::vector<std::string>{"time_s", "x_n"}));
  EXPECT_EQ(t.column("time_s"), (std::vector<double>{0.0, 0.5}));
  EXPECT_EQ(t.column("x_n"), (std::vector<double>{1.5, -2000.0}));
  EXPECT_FALSE(t.has("y_n"));
  EXPECT_THROW(t.column("y_n"), Error);
  fs::remove(p);
}

TEST(Csv, CellParsing) {
  double x = 0;
  EXPECT_TRUE(parse_finite_number("-1.25e-3", x));
  EXPECT_EQ(x, -1.25e-3);
  for (const char* bad : {"", "nan", "inf", "-inf", "1.5x", "1,5", " "}) EXPECT_FALSE(parse_finite_number(bad, x)) << bad;
  EXPECT_EQ(split_csv_line("a, b ,\"c\","), (std::vector<std::string>{"a", "b", "c", ""}));
  EXPECT_TRUE(is_blank_csv_line(" \t\r"));
  EXPECT_FALSE(is_blank_csv_line(" 0"));
}

TEST(Csv, ErrorsNameTheFileTheLineAndTheColumn) {
  const fs::path nan = write("nan.csv", "time_s,x_n\n0,1\n1,NaN\n");
  const std::string e1 = error_of(nan);
  EXPECT_NE(e1.find(nan.string()), std::string::npos) << e1;
  EXPECT_NE(e1.find("line 3"), std::string::npos) << e1;
  EXPECT_NE(e1.find("column x_n"), std::string::npos) << e1;
  const fs::path short_row = write("short.csv", "time_s,x_n\n0\n");
  EXPECT_NE(error_of(short_row).find("line 2: 1 cells, the header has 2"), std::string::npos) << error_of(short_row);
  const fs::path missing = write("missing.csv", "time_s\n0\n");
  EXPECT_NE(error_of(missing, {"time_s", "x_n"}).find("missing column x_n"), std::string::npos);
  const fs::path empty = write("empty.csv", "\n\n");
  EXPECT_NE(error_of(empty).find("empty file"), std::string::npos);
  EXPECT_NE(error_of("/nonexistent/x.csv").find("cannot open"), std::string::npos);
  for (const fs::path& p : {nan, short_row, missing, empty}) fs::remove(p);
}
