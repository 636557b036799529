#include "kincal/io/csv.hpp"

#include "kincal/io/file.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

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

CsvTable parse_csv(const std::string& text, const std::string& source) {
  CsvTable t;
  t.source = source;
  std::istringstream in(text);
  std::string raw;
  int line = 0;
  bool have_header = false;
  while (std::getline(in, raw)) {
    ++line;
    const std::string s = trim(raw);
    if (s.empty()) continue;
    std::vector<std::string> fields;
    size_t pos = 0;
    while (true) {
      const size_t c = s.find(',', pos);
      fields.push_back(trim(s.substr(pos, c == std::string::npos ? std::string::npos : c - pos)));
      if (c == std::string::npos) break;
      pos = c + 1;
    }
    if (!have_header) {
      for (const auto& f : fields)
        if (f.empty()) throw InputError(where(source, line) + ": empty column name in the header");
      t.header = fields;
      have_header = true;
      continue;
    }
    if (fields.size() != t.header.size())
      throw InputError(where(source, line) + ": " + std::to_string(fields.size()) + " fields, the header has " +
                       std::to_string(t.header.size()));
    t.cells.push_back(std::move(fields));
    t.line.push_back(line);
  }
  if (!have_header) throw InputError(source + ": empty file (no header row)");
  return t;
}

CsvTable read_csv(const std::string& path) { return parse_csv(read_text_file(path), path); }

}  // namespace kincal
