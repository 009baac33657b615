// Every binary, started with missing, invalid or conflicting options, says what is wrong in one
// clear line on stderr and exits non-zero by itself: never std::terminate, never a core dump.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "process.hpp"

namespace {

using telltale::testing::bin_dir;
using telltale::testing::unique_domain;

struct Outcome {
  bool exited = false;  ///< ended by exit(), not by a signal
  int code = -1;        ///< exit status, or the signal
  std::string err;      ///< everything on stderr (stdout is discarded)
};

/// Runs `cmd` through the shell with `env` prepended; a binary that would start anyway is cut
/// after 20 s by timeout(1) and reported as exit status 124.
Outcome run(const std::string& env, const std::string& cmd) {
  const std::string line = "cd \"" + testing::TempDir() + "\" && env -u TELLTALE_DOMAIN " + env +
                           " timeout -s KILL 20 " + cmd + " 2>&1 1>/dev/null </dev/null";
  Outcome o;
  FILE* pipe = popen(line.c_str(), "r");
  if (pipe == nullptr) return o;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) o.err.append(buf, n);
  const int status = pclose(pipe);
  o.exited = WIFEXITED(status);
  o.code = o.exited ? WEXITSTATUS(status) : WTERMSIG(status);
  return o;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) out.push_back(l);
  return out;
}

struct Case {
  const char* name;
  std::string env;
  std::string args;      ///< binary name first
  const char* expected;  ///< a fragment of the error line
};

class CliErrors : public ::testing::TestWithParam<Case> {};

TEST_P(CliErrors, OneClearLineAndANonZeroExit) {
  const Case& c = GetParam();
  const Outcome o = run(c.env, bin_dir() + "/" + c.args);
  SCOPED_TRACE(c.args + "\n--- stderr ---\n" + o.err);
  // The shell reports a child killed by a signal (abort: 134, timeout's KILL: 137) as 128 + n.
  ASSERT_TRUE(o.exited);
  EXPECT_NE(o.code, 0);
  EXPECT_LT(o.code, 124) << "killed or timed out, not a clean exit";
  EXPECT_EQ(o.err.find("terminate"), std::string::npos);
  const auto l = lines(o.err);
  ASSERT_FALSE(l.empty());
  // One line that says what is wrong; CLI11 adds its standard "Run with --help" hint.
  EXPECT_LE(l.size(), 2U);
  EXPECT_NE(l.front().find(c.expected), std::string::npos) << l.front();
}

std::string domain_env() { return "TELLTALE_DOMAIN=" + std::to_string(unique_domain()); }

INSTANTIATE_TEST_SUITE_P(
    Binaries, CliErrors,
    ::testing::Values(
        // Refused before the default database is looked for (that folder cannot exist): a bad
        // setting never creates or migrates a user's database on its way to the error.
        Case{"shore_domain_not_a_number", "TELLTALE_DOMAIN=abc XDG_DATA_HOME=/dev/null/telltale",
             "shore_server --http-port 0", "TELLTALE_DOMAIN"},
        Case{"shore_domain_out_of_range", "", "shore_server --domain 500 --http-port 0", "0..232"},
        Case{"shore_db_in_missing_folder", domain_env(),
             "shore_server --http-port 0 --db /nonexistent-telltale-dir/x.db", "x.db"},
        Case{"shore_unknown_flag", "", "shore_server --no-such-flag", "no-such-flag"},
        Case{"shore_stream_interval_out_of_range", "", "shore_server --stream-interval-ms 1",
             "stream-interval-ms"},
        Case{"shore_bad_athlete_token", domain_env(),
             "shore_server --http-port 0 --athlete-token nocolon", "athlete-token"},
        Case{"boat_without_id", "", "boat_node", "boat-id"},
        Case{"boat_domain_out_of_range", "", "boat_node --boat-id b1 --domain 999", "0..232"},
        Case{"boat_domain_not_a_number", "TELLTALE_DOMAIN=7x", "boat_node --boat-id b1",
             "TELLTALE_DOMAIN"},
        Case{"boat_unknown_source", domain_env(), "boat_node --boat-id b1 --source bogus", "bogus"},
        Case{"boat_sensor_offset_not_finite", domain_env(),
             "boat_node --boat-id b1 --sensor-offset nan,0,0", "finite"},
        Case{"wearable_without_id", "", "wearable_node", "athlete-id"},
        Case{"wearable_domain_out_of_range", "", "wearable_node --athlete-id a1 --domain 233",
             "0..232"},
        Case{"fusion_cli_missing_file", "",
             "fusion_cli attitude --in /nonexistent-telltale.csv --out /dev/null",
             "nonexistent-telltale.csv"},
        Case{"fusion_cli_acc_range_not_positive", "",
             "fusion_cli attitude --in /nonexistent-telltale.csv --out /dev/null --acc-range-g 0",
             "acc-range-g"}),
    [](const ::testing::TestParamInfo<Case>& p) { return std::string(p.param.name); });

}  // namespace
