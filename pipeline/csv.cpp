#include "pipeline/csv.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "pipeline/error.h"

namespace floesim {

namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '"'; };
  while (a < b && blank(s[a])) ++a;
  while (b > a && blank(s[b - 1])) --b;
  return s.substr(a, b - a);
}

}  // namespace

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream is(line);
  while (std::getline(is, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && trim(line).back() == ',') cells.push_back("");
  return cells;
}

bool is_blank_csv_line(const std::string& line) { return trim(line).empty(); }

bool parse_finite_number(const std::string& cell, double& x) {
  if (cell.empty()) return false;
  char* end = nullptr;
  x = std::strtod(cell.c_str(), &end);
  return end == cell.c_str() + cell.size() && std::isfinite(x);
}

bool NumericCsv::has(const std::string& name) const {
  for (const std::string& h : header)
    if (h == name) return true;
  return false;
}

const std::vector<double>& NumericCsv::column(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return columns[i];
  throw Error(file.string() + ": no column " + name + " in the header");
}

NumericCsv read_numeric_csv(const std::filesystem::path& file, const std::vector<std::string>& required) {
  std::ifstream in(file);
  FLOESIM_REQUIRE(in, file.string(), ": cannot open the CSV file");
  NumericCsv t;
  t.file = file;
  std::string line;
  size_t lineno = 0;
  while (t.header.empty() && std::getline(in, line)) {
    ++lineno;
    if (!is_blank_csv_line(line)) t.header = split_csv_line(line);
  }
  FLOESIM_REQUIRE(!t.header.empty(), file.string(), ": empty file (expected a header row)");
  for (const std::string& r : required)
    FLOESIM_REQUIRE(t.has(r), file.string(), ": line ", lineno, " (header): missing column ", r);
  t.columns.resize(t.header.size());
  while (std::getline(in, line)) {
    ++lineno;
    if (is_blank_csv_line(line)) continue;
    const std::vector<std::string> cells = split_csv_line(line);
    FLOESIM_REQUIRE(cells.size() == t.header.size(), file.string(), ": line ", lineno, ": ", cells.size(),
                    " cells, the header has ", t.header.size());
    for (size_t c = 0; c < cells.size(); ++c) {
      double x = 0;
      FLOESIM_REQUIRE(parse_finite_number(cells[c], x), file.string(), ": line ", lineno, ", column ", t.header[c],
                      ": '", cells[c], "' is not a finite number");
      t.columns[c].push_back(x);
    }
  }
  return t;
}

}  // namespace floesim
