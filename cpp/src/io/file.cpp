#include "kincal/io/file.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace kincal {

std::string read_text_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path + ": cannot open the file (" + std::strerror(errno) + ")");
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_file_atomic(const std::string& path, const std::string& text) {
  AtomicFileWriter w(path, 0);
  w.write(text);
  w.commit();
}

bool is_csv_path(const std::string& path) {
  if (path.size() < 4) return false;
  std::string e = path.substr(path.size() - 4);
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e == ".csv";
}

bool is_regular_file(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string where(const std::string& source, int line) { return source + ":" + std::to_string(line); }

void fail_at(const char* source, int line, const std::string& cause) {
  throw InputError(std::string(source) + ":" + std::to_string(line) + ": " + cause);
}

// ---- TextChunks

TextChunks::TextChunks(const std::string& path, size_t chunk_bytes)
    : path_(path), chunk_(std::max<size_t>(chunk_bytes, 1)), eof_(false) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw InputError(path + ": cannot open the file (" + std::strerror(errno) + ")");
}

TextChunks::TextChunks(std::string text) : buf_(std::move(text)), limit_(buf_.size()) {}

TextChunks::~TextChunks() {
  if (file_) std::fclose(file_);
}

bool TextChunks::more(size_t& pos) {
  buf_.erase(0, pos);
  limit_ -= pos;
  pos = 0;
  const size_t before = limit_;
  // read until the text past limit_ holds a line's end, or the file ends
  while (!eof_) {
    const size_t old = buf_.size();
    // (the reads of a long line grow with it, so that a line of n bytes costs O(n))
    const size_t want = std::max(chunk_, old - limit_);
    buf_.resize(old + want);
    const size_t got = std::fread(&buf_[old], 1, want, file_);
    buf_.resize(old + got);
    if (got < want) {
      if (std::ferror(file_)) throw InputError(path_ + ": reading the file failed (" + std::strerror(errno) + ")");
      eof_ = true;
      std::fclose(file_);
      file_ = nullptr;
    }
    const size_t nl = buf_.find_last_of('\n');
    if (nl != std::string::npos && nl + 1 > limit_) {
      limit_ = nl + 1;
      break;
    }
  }
  if (eof_) limit_ = buf_.size();
  return limit_ > before;
}

// ---- AtomicFileWriter

AtomicFileWriter::AtomicFileWriter(const std::string& path, size_t buffer_bytes)
    : path_(path), tmp_(path + ".tmp" + std::to_string(::getpid())), cap_(buffer_bytes) {
  buf_.reserve(cap_);
  file_ = std::fopen(tmp_.c_str(), "wb");
  if (!file_) error_ = path_ + ": cannot write the output file (" + std::strerror(errno) + ")";
}

AtomicFileWriter::~AtomicFileWriter() {
  if (!done_) discard();
}

void AtomicFileWriter::discard() {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
    std::remove(tmp_.c_str());
  }
  done_ = true;
}

void AtomicFileWriter::flush() {
  if (file_ && !buf_.empty() && error_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), file_) != buf_.size())
    error_ = path_ + ": writing the output file failed";
  buf_.clear();
}

void AtomicFileWriter::write_through(const char* s, size_t n) {
  flush();
  if (n <= cap_) {
    buf_.append(s, n);
    return;
  }
  if (file_ && error_.empty() && std::fwrite(s, 1, n, file_) != n) error_ = path_ + ": writing the output file failed";
}

void AtomicFileWriter::commit() {
  flush();
  if (file_ && error_.empty() && std::fflush(file_) != 0) error_ = path_ + ": writing the output file failed";
  if (!error_.empty()) {
    discard();
    throw InputError(error_);
  }
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  done_ = true;
  if (!closed) {
    std::remove(tmp_.c_str());
    throw InputError(path_ + ": writing the output file failed");
  }
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) {
    const std::string cause = std::strerror(errno);
    std::remove(tmp_.c_str());
    throw InputError(path_ + ": cannot move the output file into place (" + cause + ")");
  }
}

}  // namespace kincal
