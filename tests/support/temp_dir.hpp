// Per-test scratch space and the repository's test data: a unique temporary folder (mkdtemp) per
// use.
#pragma once

#include <stdlib.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace ftstack::test {

/// A fresh folder under $TMPDIR (or /tmp), unique per process and per instance, removed with its
/// content on destruction unless FTSTACK_KEEP_TEMP is set. Tests never share file names.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "ftstack") {
    const char* env = std::getenv("TMPDIR");
    std::string templ =
        std::string(env != nullptr && *env != '\0' ? env : "/tmp") + "/" + prefix + "_XXXXXX";
    if (::mkdtemp(templ.data()) == nullptr) throw std::runtime_error("mkdtemp " + templ);
    path_ = templ;
  }
  ~TempDir() {
    std::error_code ec;
    if (std::getenv("FTSTACK_KEEP_TEMP") == nullptr) std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  /// The path of `name` inside the folder.
  [[nodiscard]] std::string operator/(const std::string& name) const {
    return (path_ / name).string();
  }

 private:
  std::filesystem::path path_;
};

/// A folder of this test process's own, with a trailing '/', removed at exit: what
/// ::testing::TempDir() (one folder shared by every process) would be if it were private.
inline const std::string& ProcessTempDir() {
  static const TempDir dir("ftstack_proc");
  static const std::string path = dir.path().string() + "/";
  return path;
}

/// A file of the repository's test data (tests/data/, sources in tests/data/README.md).
inline std::string TestDataPath(const std::string& rel) {
  return std::string(FTSTACK_SOURCE_DIR) + "/tests/data/" + rel;
}

}  // namespace ftstack::test
