#include "kincal/io/csv.hpp"

#include "kincal/io/file.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace kincal {

NumberParse parse_number(const char* b, const char* e, double& v) {
  char buf[64];
  const size_t n = static_cast<size_t>(e - b);
  if (n == 0 || n >= sizeof buf) return NumberParse::NotNumber;
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
  // the common case, four times faster than strtod: a plain number that from_chars reads whole. Both are
  // correctly rounded, so the value is strtod's; anything else (a '+', blanks, hexadecimal, out of range)
  // goes to strtod as before.
  {
    const std::from_chars_result r = std::from_chars(b, e, v);
    if (r.ec == std::errc() && r.ptr == e) return std::isfinite(v) ? NumberParse::Ok : NumberParse::NotFinite;
  }
#endif
  std::memcpy(buf, b, n);
  buf[n] = 0;
  char* end = nullptr;
  v = std::strtod(buf, &end);
  if (end != buf + n) return NumberParse::NotNumber;
  if (!std::isfinite(v)) return NumberParse::NotFinite;
  return NumberParse::Ok;
}

namespace {

std::string missing_column(const std::string& source, const std::vector<std::string>& header, const std::string& name) {
  std::string cols;
  for (const auto& h : header) cols += (cols.empty() ? "" : ",") + h;
  return source + ":1: missing column '" + name + "' (header: " + cols + ")";
}

std::string number_error(const std::string& at, const std::string& column, const std::string& s, NumberParse r) {
  return at + ": column '" + column + "': '" + s + "' is not a " +
         (r == NumberParse::NotFinite ? "finite number" : "number");
}

int index_of(const std::vector<std::string>& header, const std::string& name) {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

}  // namespace

int CsvTable::find(const std::string& name) const { return index_of(header, name); }

int CsvTable::require(const std::string& name) const {
  const int c = find(name);
  if (c < 0) throw InputError(missing_column(source, header, name));
  return c;
}

double CsvTable::number(size_t row, int col) const {
  const std::string& s = cells[row][static_cast<size_t>(col)];
  double v;
  const NumberParse r = parse_number(s.data(), s.data() + s.size(), v);
  if (r != NumberParse::Ok) throw InputError(number_error(where(row), header[static_cast<size_t>(col)], s, r));
  return v;
}

// ---- CsvReader

CsvReader::CsvReader(const std::string& path, size_t chunk_bytes)
    : text_(std::make_unique<TextChunks>(path, chunk_bytes)), source_(path) {
  text_->more(pos_);
  if (text_->limit() >= 3 && std::memcmp(text_->data(), "\xEF\xBB\xBF", 3) == 0) pos_ = 3;
  if (!read_row()) throw InputError(source_ + ": empty file (no header row)");
}

CsvReader::CsvReader(std::string text, const std::string& source)
    : text_(std::make_unique<TextChunks>(std::move(text))), source_(source) {
  if (text_->limit() >= 3 && std::memcmp(text_->data(), "\xEF\xBB\xBF", 3) == 0) pos_ = 3;
  if (!read_row()) throw InputError(source_ + ": empty file (no header row)");
}

int CsvReader::find(const std::string& name) const { return index_of(header_, name); }

std::string CsvReader::missing(const std::string& name, int& col) const {
  col = find(name);
  return col < 0 ? missing_column(source_, header_, name) : std::string();
}

bool CsvReader::next() { return read_row(); }

double CsvReader::number(int col, std::string* error) const {
  const std::string& s = cell(col);
  double v;
  const NumberParse r = parse_number(s.data(), s.data() + s.size(), v);
  if (r == NumberParse::Ok) return v;
  std::string e = number_error(where(source_, row_line_), header_[static_cast<size_t>(col)], s, r);
  if (!error) throw InputError(e);
  *error = std::move(e);
  return std::numeric_limits<double>::quiet_NaN();
}

// RFC 4180 with the contract's leniencies: a UTF-8 byte order mark (as Excel writes it) is skipped; blank
// lines are skipped; blanks around a field are not part of it; a field in double quotes may hold commas,
// line breaks and quotes (written twice); a quote inside an unquoted field is a character like any other.
// Each row carries the line it starts on. The text comes in whole lines; a quoted field whose line breaks
// run past them reads more and parses its row again.
bool CsvReader::read_row() {
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  auto space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  for (;;) {
    if (pos_ >= text_->limit() && !text_->more(pos_)) return false;
    const char* text = text_->data();
    const size_t n = text_->limit();
    size_t i = pos_;
    int line = line_;
    const int first_line = line;
    size_t nf = 0;
    bool empty_row = true;  // nothing but blanks so far
    bool again = false;     // a quoted field runs past the lines read
    auto field = [&]() -> std::string& {
      if (nf == fields_.size()) fields_.emplace_back();
      return fields_[nf++];
    };
    while (true) {
      const size_t a = i;
      while (i < n && blank(text[i])) ++i;
      if (i < n && text[i] == '"') {
        const int open_line = line;
        std::string& f = field();
        f.clear();
        for (++i;; ++i) {
          if (i >= n) {
            if (!text_->at_end()) {
              again = true;
              break;
            }
            throw InputError(where(source_, open_line) + ": a quoted field is not closed (its '\"' opens here)");
          }
          if (text[i] == '"') {
            if (i + 1 < n && text[i + 1] == '"') {
              f += '"';
              ++i;
              continue;
            }
            ++i;
            break;
          }
          if (text[i] == '\n') ++line;
          f += text[i];
        }
        if (again) break;
        while (i < n && blank(text[i])) ++i;
        if (i < n && text[i] != ',' && text[i] != '\n')
          throw InputError(where(source_, line) + ": text after the closing '\"' of a quoted field");
        empty_row = false;
      } else {
        while (i < n && text[i] != ',' && text[i] != '\n') ++i;
        size_t b = a, e = i;
        while (b < e && space(text[b])) ++b;
        while (e > b && space(text[e - 1])) --e;
        field().assign(text + b, e - b);
        empty_row = empty_row && b == e;
      }
      if (i < n && text[i] == ',') {
        ++i;
        empty_row = false;
        continue;
      }
      break;  // the line's end or the text's
    }
    if (again) {
      text_->more(pos_);  // the row again, with more lines
      continue;
    }
    if (i < n) ++i, ++line;  // the '\n'
    pos_ = i;
    line_ = line;
    if (empty_row) continue;
    nfields_ = nf;
    row_line_ = first_line;
    if (!have_header_) {
      have_header_ = true;
      for (size_t k = 0; k < nf; ++k)
        if (fields_[k].empty()) throw InputError(where(source_, first_line) + ": empty column name in the header");
      header_.assign(fields_.begin(), fields_.begin() + static_cast<long>(nf));
      return true;
    }
    if (nf != header_.size())
      throw InputError(where(source_, first_line) + ": " + std::to_string(nf) + " fields, the header has " +
                       std::to_string(header_.size()));
    return true;
  }
}

CsvTable parse_csv(const std::string& text, const std::string& source) {
  CsvReader r(text, source);
  CsvTable t;
  t.source = source;
  t.header = r.header();
  while (r.next()) {
    t.cells.push_back(r.cells());
    t.line.push_back(r.line());
  }
  return t;
}

CsvTable read_csv(const std::string& path) { return parse_csv(read_text_file(path), path); }

}  // namespace kincal
