// kincal: whole files: reading one into memory, writing one atomically (never a partial file), the
// CSV extension, and the InputError "file:line: cause" every reader raises.
#pragma once

#include "kincal/core/types.hpp"

#include <string>

namespace kincal {

/// The whole file as text; InputError "path: cannot open the file (cause)" when it cannot be read.
std::string read_text_file(const std::string& path);

/// Write text to path atomically (a temporary file beside it, renamed when complete).
void write_file_atomic(const std::string& path, const std::string& text);

/// Whether the path ends in .csv (any case).
bool is_csv_path(const std::string& path);

/// "source:line", the place an error names.
std::string where(const std::string& source, int line);

/// Throws InputError "source:line: cause".
[[noreturn]] void fail_at(const char* source, int line, const std::string& cause);

}  // namespace kincal
