// Every C++ test process writes its files in a directory of its own: ctest runs each test as a process,
// two at a time, and two test trees (a clone's CI beside a working copy) may run at once, so fixed names
// in one shared /tmp raced (a KRL test read another's $config.dat half-written). Before main: TEST_TMPDIR
// (what ::testing::TempDir() returns) set to <temp>/kincal-test-<pid>/, removed at exit; a TEST_TMPDIR
// already set is kept.
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include <unistd.h>

namespace {

struct ProcessTempDir {
  std::filesystem::path dir;
  ProcessTempDir() {
    if (std::getenv("TEST_TMPDIR")) return;
    std::error_code ec;
    dir = std::filesystem::temp_directory_path(ec) / ("kincal-test-" + std::to_string(getpid()));
    std::filesystem::create_directories(dir, ec);
    if (ec) {
      dir.clear();
      return;
    }
    setenv("TEST_TMPDIR", (dir.string() + "/").c_str(), 1);
  }
  ~ProcessTempDir() {
    std::error_code ec;
    if (!dir.empty()) std::filesystem::remove_all(dir, ec);
  }
};

const ProcessTempDir g_temp_dir;

}  // namespace
