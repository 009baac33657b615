#pragma once
/// \file
/// A disk that really fills up, for the fault tests: a small tmpfs mounted in this test
/// process's own mount namespace (root only), invisible to everything else on the machine.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

namespace telltale::test {

/// A private mount namespace for this test process (root only), so tmpfs mounts with a size limit
/// or read-only ones stay invisible to everything else. False where that is not allowed.
inline bool private_mounts() {
  static const bool ok = [] {
    if (::geteuid() != 0 || ::unshare(CLONE_NEWNS) != 0) return false;
    return ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) == 0;
  }();
  return ok;
}

/// Fills the filesystem of `path` with one file until a write fails.
inline void fill_disk(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  std::vector<char> block(4096, 'x');
  while (::write(fd, block.data(), block.size()) > 0) {
  }
  ::close(fd);
}

/// A tmpfs at `dir` (`options`: its size and mode) in this process's private mount namespace,
/// unmounted at scope exit. `mounted` is false where that is not allowed: a fault test then
/// fails, never skips.
struct SmallTmpfs {
  explicit SmallTmpfs(const std::filesystem::path& dir,
                      const std::string& options = "size=1m,mode=0755")
      : path(dir) {
    std::filesystem::create_directories(dir);
    mounted = private_mounts() && ::mount("tmpfs", dir.c_str(), "tmpfs", 0, options.c_str()) == 0;
  }
  ~SmallTmpfs() {
    if (mounted) ::umount2(path.c_str(), MNT_DETACH);
  }
  SmallTmpfs(const SmallTmpfs&) = delete;
  SmallTmpfs& operator=(const SmallTmpfs&) = delete;
  std::filesystem::path path;
  bool mounted = false;
};

}  // namespace telltale::test
