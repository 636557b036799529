// kincal: the text of KRL data (private to the KRL reader): aggregates {X 1,Y 2,..,S 6,T 50,E1 ..}, the
// declarations of data lists, the top-level parts of a statement. krl_text.cpp; used by krl_reader.cpp.
#pragma once

#include "kincal/io/controllers.hpp"
#include "kincal/io/native.hpp"

#include <array>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <utility>
#include <vector>

namespace kincal::krl {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// DECL [GLOBAL] TYPE NAME[=value]; TOOL_DATA[n] / BASE_DATA[n] = value; NAME[.field] = value; C_PTP .. C_SPL
extern const std::regex kDecl, kElement, kAssign, kApprox;

std::string code_of(const std::string& line);  ///< the line without its ';' comment
std::string trim(const std::string& s);
bool is_pos(const std::string& type);   ///< E6POS, POS, FRAME
bool is_axis(const std::string& type);  ///< E6AXIS, AXIS
std::string file_name(const std::string& path);
bool same_file(const std::string& a, const std::string& b);

/// The fields of an aggregate "{X 1,Y 2,S 'B110',...}" by upper-case key, values trimmed.
std::map<std::string, std::string> fields_of(const std::string& agg);
/// A field's number, else InputError "at: KEY 'val' is not a number".
double number(const std::string& key, const std::string& val, const std::string& at);
/// S and T: a number or a KRL bit / hex literal 'B110', 'H1F'.
int bits(const std::string& key, const std::string& val, const std::string& at);

/// A position aggregate read: its pose, the first of X..C it lacks, whether it is joints, its S/T, E1..E6.
struct Aggregate {
  Pose6 pose;
  std::string missing;  // the first of X..C it does not give
  bool joints = false;  // A1..A6
  std::optional<ControllerTarget> taught;
  std::array<double, 6> external{{kNaN, kNaN, kNaN, kNaN, kNaN, kNaN}};
};
Aggregate read_aggregate(const std::string& agg, const std::string& at);

/// The spans of the top-level comma-separated parts of code[from, to), trimmed.
std::vector<std::pair<size_t, size_t>> top_args(const std::string& code, size_t from, size_t to);
/// Where the word WITH stands in code from `from` on, outside brackets and strings; npos when nowhere.
size_t with_at(const std::string& code, size_t from);
/// Whether s has a ':' outside brackets (the geometric operator).
bool top_colon(const std::string& s);

}  // namespace kincal::krl
