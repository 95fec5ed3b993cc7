// CSV of numbers, the one home of its parsing: the measured ship data (identify), the identified loads (plot,
// report). A header row names the columns; every further non-blank row holds one finite number per column.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace floesim {

// The cells of one CSV line, each trimmed of spaces, tabs, a carriage return and enclosing double quotes (no
// quoted commas: numeric files have none). A trailing comma gives a last empty cell.
std::vector<std::string> split_csv_line(const std::string& line);

// Nothing but spaces, tabs, a carriage return (and quotes) on the line.
bool is_blank_csv_line(const std::string& line);

// Parses a whole cell as a finite number (strtod, nothing left over); false for "", "nan", "inf", "1.5x".
bool parse_finite_number(const std::string& cell, double& x);

struct NumericCsv {
  std::filesystem::path file;
  std::vector<std::string> header;
  std::vector<std::vector<double>> columns;  // per header column, per data row
  bool has(const std::string& name) const;
  // The column named `name`; Error naming the file and the column if absent.
  const std::vector<double>& column(const std::string& name) const;
};

// Reads a numeric CSV: the header (first non-blank line), then rows of finite numbers with as many cells as the
// header. Errors name the file, the line and the column. `required` columns must be in the header.
NumericCsv read_numeric_csv(const std::filesystem::path& file, const std::vector<std::string>& required = {});

}  // namespace floesim
