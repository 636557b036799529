// kincal: the words of one G-code line: scanning the pose words (X Y Z A B C) or the joint words
// (A1= .. AN=), cutting them out of the line, and putting joint words in their place. Allocation-free
// (the program readers and the streaming corrector share them); errors are InputError "file:line: cause".
#pragma once

#include "kincal/core/types.hpp"

#include <cstddef>

namespace kincal {

/// The pose word letters in axis order: X Y Z A B C.
constexpr const char* kPoseLetters = "XYZABC";

/// Which words scan_gcode looks for.
enum class GcodeWords {
  Pose,  ///< X Y Z A B C
  Joint  ///< A1= .. AN= (N the robot's joints)
};

/// One word found on a line: its axis (pose: 0..5 for X Y Z A B C; joint: 0..N-1), where it stands
/// on the line [begin, end) and its number.
struct GcodeWord {
  int axis;
  size_t begin, end;
  double value;
};

/// Scans the line s[0..n) for the words of the given kind (dof: the joints, for joint words), at most
/// cap of them into words; returns how many. Comments (';' to the end, '(...)') and quoted strings
/// are skipped. A broken word throws InputError "source:line: cause".
int scan_gcode(const char* s, size_t n, GcodeWords kind, int dof, GcodeWord* words, int cap, const char* source,
               int line);

/// A line with its words cut out: its length, and where the first word was (where joint words go).
struct CutLine {
  size_t size = 0;
  size_t insert_at = 0;
};

/// Copies the line s[0..n) into buf (capacity cap) with the words cut out, each with one following
/// blank. InputError "source:line: line too long" when it does not fit.
CutLine cut_words(const char* s, size_t n, const GcodeWord* words, int count, char* buf, size_t cap,
                  const char* source, int line);

/// A joint G-code line: the cut line cut[0..n) with the joint words of q_deg at insert_at, into out
/// (capacity cap); returns its length.
size_t emit_gcode_line(const char* cut, size_t n, size_t insert_at, const Vec6& q_deg, char* out, size_t cap);

}  // namespace kincal
