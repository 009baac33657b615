#pragma once
/// \file
/// A real shore_server (and boat_nodes) on a private DDS domain and a free HTTP port, for tests
/// that speak to it over HTTP. Everything is stopped and removed at the end of the test.

#include <gtest/gtest.h>
#include <httplib.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "process.hpp"

namespace telltale::testing {

inline constexpr const char* kCoachToken = "integration-coach-token";

class ShoreFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = make_temp_dir();
    domain_ = unique_domain();
    start_shore();
  }
  void TearDown() override {
    boats_.clear();
    shore_.reset();
    std::filesystem::remove_all(dir_);
  }

  /// Extra shore flags (tokens, intervals) for start_shore().
  virtual std::vector<std::string> shore_flags() const { return {}; }

  void start_shore() {
    std::vector<std::string> argv = {bin_dir() + "/shore_server",
                                     "--domain",
                                     std::to_string(domain_),
                                     "--http-port",
                                     "0",
                                     "--db",
                                     db_path(),
                                     "--coach-token",
                                     kCoachToken};
    for (const auto& f : shore_flags()) argv.push_back(f);
    shore_ = std::make_unique<Process>(argv);
    const auto ready = shore_->wait_for_line("shore_server ready: ", std::chrono::seconds(20));
    ASSERT_TRUE(ready) << "shore did not start: " << shore_->output();
    std::smatch m;
    ASSERT_TRUE(std::regex_search(*ready, m, std::regex(R"(http://127\.0\.0\.1:(\d+)/)")));
    port_ = std::stoi(m[1]);
  }

  Process& start_boat(const std::string& id, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {bin_dir() + "/boat_node", "--domain", std::to_string(domain_),
                                     "--boat-id", id};
    // The session log in the test's own folder: never the working directory, where runs of
    // earlier test processes would be delivered as this boat's history.
    if (std::find(extra.begin(), extra.end(), "--log-dir") == extra.end())
      extra.insert(extra.end(), {"--log-dir", dir_ + "/log_" + id});
    for (auto& e : extra) argv.push_back(std::move(e));
    boats_.push_back(std::make_unique<Process>(argv));
    EXPECT_TRUE(boats_.back()->wait_for_line("boat_node ready: ", std::chrono::seconds(20)))
        << boats_.back()->output();
    return *boats_.back();
  }

  std::string db_path() const { return dir_ + "/shore.db"; }

  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_connection_timeout(2);
    c.set_read_timeout(10);
    return c;
  }
  static httplib::Headers bearer(const std::string& token = kCoachToken) {
    return {{"Authorization", "Bearer " + token}};
  }

  /// GET with the coach token; the parsed JSON body (null on failure).
  nlohmann::json get_json(const std::string& path) const {
    auto c = client();
    auto res = c.Get(path, bearer());
    if (!res || res->status != 200) return nullptr;
    return nlohmann::json::parse(res->body, nullptr, false);
  }

  std::map<std::string, nlohmann::json> boats_by_id() const {
    std::map<std::string, nlohmann::json> out;
    const auto boats = get_json("/api/v1/boats");
    if (!boats.is_array()) return out;
    for (const auto& b : boats) out[b["id"].get<std::string>()] = b;
    return out;
  }

  /// Waits until `pred()` holds, polling every 100 ms; false on timeout.
  template <class Pred>
  static bool eventually(Pred pred, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (pred()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return pred();
  }

  std::string dir_;
  int domain_ = 0;
  int port_ = 0;
  std::unique_ptr<Process> shore_;
  std::vector<std::unique_ptr<Process>> boats_;
};

}  // namespace telltale::testing
