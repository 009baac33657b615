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

namespace telltale::testing {

class FusionCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("telltale_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
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

 private:
  std::filesystem::path dir_;
};

}  // namespace telltale::testing
