// kincal: whole files: reading one into memory or in pieces of whole lines, writing one atomically
// (never a partial file, also when it is written piece by piece), the CSV extension, and the
// InputError "file:line: cause" every reader raises.
#pragma once

#include "kincal/core/types.hpp"

#include <cstddef>
#include <cstdio>
#include <string>

namespace kincal {

/// The whole file as text; InputError "path: cannot open the file (cause)" when it cannot be read.
std::string read_text_file(const std::string& path);

/// Write text to path atomically (a temporary file beside it, renamed when complete).
void write_file_atomic(const std::string& path, const std::string& text);

/// Whether the path ends in .csv (any case).
bool is_csv_path(const std::string& path);

/// Whether path names a regular file (one that can be read twice; not a pipe or a terminal).
bool is_regular_file(const std::string& path);

/// "source:line", the place an error names.
std::string where(const std::string& source, int line);

/// Throws InputError "source:line: cause".
[[noreturn]] void fail_at(const char* source, int line, const std::string& cause);

/// How many bytes a program file is read in at a time, and its output written (kincal/compensation/program.hpp).
constexpr size_t kProgramChunkBytes = size_t{1} << 20;

/// A text read in pieces of whole lines: text()[0, limit()) holds whole lines (each with its '\n'; the
/// file's last line also without one once the file is read to its end), about chunk_bytes at a time; the
/// text before the reader's position is dropped at the next more(). A file of any length thus needs
/// memory for a chunk and its longest line only.
class TextChunks {
 public:
  /// A file, read chunk_bytes at a time (at least 1); InputError "path: cannot open the file (cause)".
  TextChunks(const std::string& path, size_t chunk_bytes);
  /// A text already in memory: all of it at once.
  explicit TextChunks(std::string text);
  ~TextChunks();
  TextChunks(const TextChunks&) = delete;
  TextChunks& operator=(const TextChunks&) = delete;

  const char* data() const { return buf_.data(); }
  /// the end of the whole lines read
  size_t limit() const { return limit_; }
  /// true when text()[0, limit()) runs to the end of the file
  bool at_end() const { return eof_ && limit_ == buf_.size(); }
  /// Drops [0, pos) (pos becomes 0) and reads at least one more whole line; false when there is none.
  bool more(size_t& pos);

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string buf_;
  size_t limit_ = 0;
  size_t chunk_ = 0;
  bool eof_ = true;
};

/// A file written piece by piece into a temporary file beside it ("path.tmpPID"), renamed to path by
/// commit(); destroyed without commit() (an error), the temporary file is removed and path is not
/// touched (and when the process is stopped by a signal: remove_unfinished_files_on_signals). Writes are
/// buffered (buffer_bytes). A file that cannot be created or written is reported by commit(), with the
/// messages of write_file_atomic, so that an error of the content comes first.
class AtomicFileWriter {
 public:
  AtomicFileWriter(const std::string& path, size_t buffer_bytes = kProgramChunkBytes);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  void write(const char* s, size_t n) {
    if (n <= cap_ - buf_.size()) {
      buf_.append(s, n);
      return;
    }
    write_through(s, n);
  }
  void write(const std::string& s) { write(s.data(), s.size()); }
  /// Flushes, closes and renames the file into place; InputError when anything failed.
  void commit();
  const std::string& path() const { return path_; }

 private:
  void flush();
  void write_through(const char* s, size_t n);
  void discard();
  std::string path_, tmp_;
  std::FILE* file_ = nullptr;
  std::string buf_;
  size_t cap_;
  std::string error_;  ///< the first failure (reported by commit)
  bool done_ = false;
  int slot_ = -1;  ///< where the signal handler finds the temporary file
};

/// For command-line programs: SIGINT, SIGTERM and SIGHUP remove the temporary files of the
/// AtomicFileWriters still open, then stop the process as the signal would have. (A program file of
/// millions of poses takes a minute: an interrupted run leaves neither the output nor a temporary file.)
void remove_unfinished_files_on_signals();

}  // namespace kincal
