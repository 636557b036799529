// kincal: CSV tables (a header row, then rows of string cells with their line numbers), read whole or
// row by row, and the one number parser every reader uses (whole field, finite). RFC 4180 fields:
// double-quoted ones may hold commas, line breaks and quotes written twice; a leading UTF-8 byte order
// mark (Excel's) is skipped. Errors are InputError "file:line: cause".
#pragma once

#include "kincal/core/types.hpp"
#include "kincal/io/file.hpp"

#include <memory>
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

/// A CSV text read row by row (a file in pieces of whole lines: kincal/io/file.hpp TextChunks), with the
/// rules and errors of parse_csv, in the same order: the header row is read by the constructor.
class CsvReader {
 public:
  /// The file at path, read chunk_bytes at a time.
  CsvReader(const std::string& path, size_t chunk_bytes);
  /// A text in memory, named source in errors.
  CsvReader(std::string text, const std::string& source);

  const std::string& source() const { return source_; }
  const std::vector<std::string>& header() const { return header_; }
  int find(const std::string& name) const;     ///< column index or -1
  /// The InputError of a missing column (CsvTable::require's), or empty when it is there (col: its index).
  std::string missing(const std::string& name, int& col) const;

  /// The next row (blank lines skipped); false at the end of the text.
  bool next();
  /// the current row's cells (as many as the header's columns) and the line it starts on
  const std::string& cell(int col) const { return fields_[static_cast<size_t>(col)]; }
  std::vector<std::string> cells() const { return {fields_.begin(), fields_.begin() + static_cast<long>(nfields_)}; }
  int line() const { return row_line_; }
  /// The current row's cell as a finite number; else the InputError CsvTable::number throws (in *error
  /// when error is given, the result then NaN).
  double number(int col, std::string* error = nullptr) const;

 private:
  bool read_row();  // the next non-blank row (the first: the header) into fields_; false at the end
  std::unique_ptr<TextChunks> text_;
  std::string source_;
  std::vector<std::string> header_;
  std::vector<std::string> fields_;  // the row's cells; nfields_ of them are the row's (the rest: capacity)
  size_t nfields_ = 0;
  size_t pos_ = 0;  // in text_
  int line_ = 1;    // the line at pos_
  int row_line_ = 0;
  bool have_header_ = false;
};

/// What parse_number found in a field.
enum class NumberParse {
  Ok,         ///< a finite number
  NotNumber,  ///< not (wholly) a number
  NotFinite   ///< a number, but NaN or infinite
};

/// Parses the whole field [b, e) as a finite number into v. No allocation.
NumberParse parse_number(const char* b, const char* e, double& v);

}  // namespace kincal
