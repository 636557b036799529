// kincal: the controller-PC corrector: pose lines in (CSV x,y,z,a,b,c with a header, or G-code with
// modal X Y Z A B C words), joint lines out, one at a time, compensated as compensate_poses does
// the whole program, without allocating per line.
#pragma once

#include "kincal/compensation/program.hpp"
#include "kincal/model/coverage.hpp"

#include <array>
#include <string>
#include <vector>

namespace kincal {

/// The controller-PC corrector: one pose line in, one joint line out, no allocation per line.
class StreamCompensator {
 public:
  StreamCompensator(Robot robot, ProgramOptions opt);
  /// Processes one input line (without its newline); writes the output line (without newline) to
  /// out and returns its length. Throws InputError "stdin:N: cause" on bad input.
  size_t process(const char* line, size_t len, char* out, size_t cap);
  /// A warning about the last line processed (a branch change; a joint leaving the angles its periodic
  /// effects were fitted on, once each time it leaves them), or empty.
  const std::string& warning() const { return warning_; }

 private:
  Robot robot_;
  ProgramOptions opt_;
  int line_no_ = 0;
  ProgramCursor cursor_;
  std::string warning_;
  std::vector<Extrapolation> periodic_;  ///< joints whose periodic effects have a fitted range
  std::array<bool, 6> outside_{};        ///< each one's last pose was outside its range
  // CSV state
  bool csv_header_seen_ = false;
  int csv_cols_[6] = {0, 1, 2, 3, 4, 5};
  int csv_temperature_col_ = -1;
  // G-code modal state
  Pose6 modal_;
  bool modal_set_[6] = {false, false, false, false, false, false};
  Vec6 solve(const Pose6& p, double temperature_c);
  size_t csv_header(const char* s, size_t n, char* out, size_t cap);
  size_t csv_line(const char* s, size_t n, char* out, size_t cap);
  size_t gcode_line(const char* s, size_t n, char* out, size_t cap);
};

}  // namespace kincal
