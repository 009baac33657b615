#pragma once
/// \file
/// A test that runs `fusion_cli` as analysts and scripts run it: a fresh temporary folder per
/// test, stdout and stderr to files in it.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "temp_dir_test.hpp"

namespace telltale::testing {

class FusionCliTest : public test::TempDirTest {
 protected:
  FusionCliTest() : TempDirTest("telltale_cli_") {}
  [[nodiscard]] std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// Exit status of `fusion_cli args` (-1 if it did not exit), stdout in out.txt, stderr in
  /// err.txt.
  int run(const std::string& args) const {
    const std::string cmd = std::string(TELLTALE_FUSION_CLI) + " " + args + " >" + path("out.txt") +
                            " 2>" + path("err.txt");
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  }
  [[nodiscard]] std::string read(const std::string& name) const {
    std::ifstream in(path(name));
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
  }
};

}  // namespace telltale::testing
