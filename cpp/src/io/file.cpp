#include "kincal/io/file.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <csignal>
#include <fstream>
#include <signal.h>
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

namespace {

// The temporary files being written, for the signal handler: a slot is 0 free, 1 taken, 2 holding a path.
constexpr int kSlots = 16;
std::atomic<int> g_slot_state[kSlots];
char g_slot_path[kSlots][4096];

int claim_slot(const std::string& tmp) {
  if (tmp.size() >= sizeof g_slot_path[0]) return -1;
  for (int k = 0; k < kSlots; ++k) {
    int expected = 0;
    if (!g_slot_state[k].compare_exchange_strong(expected, 1)) continue;
    std::memcpy(g_slot_path[k], tmp.c_str(), tmp.size() + 1);
    g_slot_state[k].store(2);
    return k;
  }
  return -1;  // (more files open at once than slots: those are not removed on a signal)
}

void release_slot(int k) {
  if (k >= 0) g_slot_state[k].store(0);
}

extern "C" void remove_unfinished_files(int sig) {
  for (int k = 0; k < kSlots; ++k)
    if (g_slot_state[k].load() == 2) ::unlink(g_slot_path[k]);
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  ::sigaction(sig, &dfl, nullptr);
  ::raise(sig);
}

}  // namespace

void remove_unfinished_files_on_signals() {
  struct sigaction sa {};
  sa.sa_handler = remove_unfinished_files;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // a signal the user had ignored (nohup, a background job's SIGINT) stays ignored
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &sa, nullptr);
  }
}

AtomicFileWriter::AtomicFileWriter(const std::string& path, size_t buffer_bytes)
    : path_(path), tmp_(path + ".tmp" + std::to_string(::getpid())), cap_(buffer_bytes) {
  buf_.reserve(cap_);
  slot_ = claim_slot(tmp_);
  file_ = std::fopen(tmp_.c_str(), "wb");
  if (!file_) error_ = path_ + ": cannot write the output file (" + std::strerror(errno) + ")";
}

AtomicFileWriter::~AtomicFileWriter() {
  if (!done_) discard();
  release_slot(slot_);
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
  const bool moved = std::rename(tmp_.c_str(), path_.c_str()) == 0;
  const std::string cause = moved ? std::string() : std::strerror(errno);
  if (!moved) std::remove(tmp_.c_str());
  release_slot(slot_);
  slot_ = -1;
  if (!moved) throw InputError(path_ + ": cannot move the output file into place (" + cause + ")");
}

}  // namespace kincal
