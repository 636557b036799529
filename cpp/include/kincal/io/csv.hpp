// kincal: CSV tables (a header row, then rows of string cells with their line numbers) and the one
// number parser every reader uses (whole field, finite). RFC 4180 fields: double-quoted ones may hold
// commas, line breaks and quotes written twice; a leading UTF-8 byte order mark (Excel's) is skipped.
// Errors are InputError "file:line: cause".
#pragma once

#include "kincal/core/types.hpp"

#include <string>
#include <vector>

namespace kincal {

/// A CSV file: header and string cells, with the line number of every row.
struct CsvTable {
  std::string source;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> cells;
  std::vector<int> line;
  int find(const std::string& name) const;      ///< column index or -1
  int require(const std::string& name) const;   ///< column index or InputError
  double number(size_t row, int col) const;     ///< finite number or InputError naming file:line
  std::string where(size_t row) const { return source + ":" + std::to_string(line[row]); }
};
CsvTable read_csv(const std::string& path);
CsvTable parse_csv(const std::string& text, const std::string& source);

/// What parse_number found in a field.
enum class NumberParse {
  Ok,         ///< a finite number
  NotNumber,  ///< not (wholly) a number
  NotFinite   ///< a number, but NaN or infinite
};

/// Parses the whole field [b, e) as a finite number into v. No allocation.
NumberParse parse_number(const char* b, const char* e, double& v);

}  // namespace kincal
