#pragma once
/// \file
/// A fresh, empty folder for each test, removed after it: named after the test and this
/// process, because ctest runs a file's tests as parallel processes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace telltale::test {

class TempDirTest : public ::testing::Test {
 protected:
  /// `prefix`: what the folder's name begins with (which suite made it, when one is left).
  explicit TempDirTest(std::string prefix = "telltale_") : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace telltale::test
