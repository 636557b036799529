#include "kincal/io/csv.hpp"

#include "kincal/io/file.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace kincal {

namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

}  // namespace

NumberParse parse_number(const char* b, const char* e, double& v) {
  if (b == e) return NumberParse::NotNumber;
  char buf[64];
  const size_t n = static_cast<size_t>(e - b);
  if (n >= sizeof buf) return NumberParse::NotNumber;
  std::memcpy(buf, b, n);
  buf[n] = 0;
  char* end = nullptr;
  v = std::strtod(buf, &end);
  if (end != buf + n) return NumberParse::NotNumber;
  if (!std::isfinite(v)) return NumberParse::NotFinite;
  return NumberParse::Ok;
}

int CsvTable::find(const std::string& name) const {
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return static_cast<int>(i);
  return -1;
}

int CsvTable::require(const std::string& name) const {
  const int c = find(name);
  if (c < 0) {
    std::string cols;
    for (const auto& h : header) cols += (cols.empty() ? "" : ",") + h;
    throw InputError(source + ":1: missing column '" + name + "' (header: " + cols + ")");
  }
  return c;
}

double CsvTable::number(size_t row, int col) const {
  const std::string& s = cells[row][static_cast<size_t>(col)];
  double v;
  switch (parse_number(s.data(), s.data() + s.size(), v)) {
    case NumberParse::Ok: return v;
    case NumberParse::NotFinite:
      throw InputError(where(row) + ": column '" + header[col] + "': '" + s + "' is not a finite number");
    default: throw InputError(where(row) + ": column '" + header[col] + "': '" + s + "' is not a number");
  }
}

// RFC 4180 with the contract's leniencies: a UTF-8 byte order mark (as Excel writes it) is skipped; blank
// lines are skipped; blanks around a field are not part of it; a field in double quotes may hold commas,
// line breaks and quotes (written twice); a quote inside an unquoted field is a character like any other.
// Each row carries the line it starts on.
CsvTable parse_csv(const std::string& text, const std::string& source) {
  CsvTable t;
  t.source = source;
  const size_t n = text.size();
  size_t i = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  int line = 1;
  bool have_header = false;
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (i < n) {
    const int first_line = line;
    std::vector<std::string> fields;
    bool empty_row = true;  // nothing but blanks so far
    while (true) {
      const size_t a = i;
      while (i < n && blank(text[i])) ++i;
      if (i < n && text[i] == '"') {
        const int open_line = line;
        std::string f;
        for (++i;; ++i) {
          if (i >= n)
            throw InputError(where(source, open_line) + ": a quoted field is not closed (its '\"' opens here)");
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
        while (i < n && blank(text[i])) ++i;
        if (i < n && text[i] != ',' && text[i] != '\n')
          throw InputError(where(source, line) + ": text after the closing '\"' of a quoted field");
        fields.push_back(std::move(f));
        empty_row = false;
      } else {
        while (i < n && text[i] != ',' && text[i] != '\n') ++i;
        fields.push_back(trim(text.substr(a, i - a)));
        empty_row = empty_row && fields.back().empty();
      }
      if (i < n && text[i] == ',') {
        ++i;
        empty_row = false;
        continue;
      }
      break;  // the line's end or the text's
    }
    if (i < n) ++i, ++line;  // the '\n'
    if (empty_row) continue;
    if (!have_header) {
      for (const auto& f : fields)
        if (f.empty()) throw InputError(where(source, first_line) + ": empty column name in the header");
      t.header = std::move(fields);
      have_header = true;
      continue;
    }
    if (fields.size() != t.header.size())
      throw InputError(where(source, first_line) + ": " + std::to_string(fields.size()) + " fields, the header has " +
                       std::to_string(t.header.size()));
    t.cells.push_back(std::move(fields));
    t.line.push_back(first_line);
  }
  if (!have_header) throw InputError(source + ": empty file (no header row)");
  return t;
}

CsvTable read_csv(const std::string& path) { return parse_csv(read_text_file(path), path); }

}  // namespace kincal
