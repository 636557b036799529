// kincal: the text of RAPID modules (private to the RAPID reader): statements that run to their ';' over
// several lines, with where each piece of their text stands; the values of robtargets and frames.
// rapid_text.cpp; used by rapid_reader.cpp.
#pragma once

#include "kincal/io/native.hpp"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace kincal::rapid {

// One statement: its code (comments cut, the lines joined by one blank) and where each piece stands.
struct Stmt {
  std::string text;
  struct Piece { size_t at; int line; size_t col; };
  std::vector<Piece> pieces;
  bool ended = false;  // by ';' or as a block line (MODULE, PROC, IF .. THEN, ...)
  int line() const { return pieces.front().line; }
  std::pair<int, size_t> pos(size_t o) const {  // the (line, column) of text offset o
    auto it = std::upper_bound(pieces.begin(), pieces.end(), o, [](size_t v, const Piece& p) { return v < p.at; });
    --it;
    return {it->line, it->col + (o - it->at)};
  }
};

std::string trim(const std::string& s);
/// A line that is a statement without ';': MODULE, routine heads and ends, IF .. THEN, labels, ...
bool block_line(const std::string& text);
/// The statements of a module's lines, in order.
std::vector<Stmt> statements(const std::vector<std::string>& lines);
/// The n numbers of a bracketed list "[a,b,..]", else InputError "at: what ...".
std::vector<double> numbers(const std::string& part, size_t n, const std::string& at, const char* what);
/// The top-level parts of a bracketed value.
std::vector<std::string> parts_of(const std::string& v);
/// A frame [[x,y,z],[q1,q2,q3,q4]].
Eigen::Isometry3d frame_of(const std::string& part, const std::string& at, const char* what);
/// A robtarget value [[x,y,z],[q1..q4],[cf1,cf4,cf6,cfx],[e1..e6]] into t (pose, taught, external).
void parse_robtarget(const std::string& v, const std::string& at, NativeTarget& t);

}  // namespace kincal::rapid
