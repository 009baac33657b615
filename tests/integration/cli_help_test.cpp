// Every long-running binary's --help groups its flags under headings a boat technician or coach
// understands: each flag once, under its heading; only --help and --config stay in CLI11's
// general "Options". The tables below are the grouping; a flag added without a heading, or moved,
// shows up here as a diff.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "process.hpp"

namespace {

using telltale::testing::bin_dir;

struct Heading {
  std::string name;                ///< as printed, without the colon
  std::vector<std::string> flags;  ///< long names, in the order printed
};

struct HelpCase {
  const char* binary;
  std::vector<Heading> headings;
};

/// `binary --help`'s stdout and exit status.
std::pair<int, std::string> help_of(const std::string& binary) {
  const std::string line =
      "env -u TELLTALE_DOMAIN timeout -s KILL 20 \"" + binary + "\" --help 2>/dev/null </dev/null";
  std::string out;
  FILE* pipe = popen(line.c_str(), "r");
  if (pipe == nullptr) return {-1, out};
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}

/// CLI11's help as headings and the long flags under each. A heading is an unindented line
/// ending in ':'; an option is a line starting "  -" whose first word holds its names
/// ("-h,--help"); descriptions are indented further (they may name other flags: not counted).
std::vector<Heading> parse_help(const std::string& text) {
  std::vector<Heading> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    if (!l.empty() && l.front() != ' ' && l.back() == ':') {
      out.push_back({l.substr(0, l.size() - 1), {}});
    } else if (l.rfind("  -", 0) == 0) {
      if (out.empty()) out.push_back({"(no heading)", {}});
      std::istringstream names(l.substr(2, l.find(' ', 2) - 2));
      for (std::string name; std::getline(names, name, ',');)
        if (name.rfind("--", 0) == 0) out.back().flags.push_back(name);
    }
  }
  return out;
}

std::string describe(const std::vector<Heading>& headings) {
  std::string s;
  for (const auto& h : headings) {
    s += h.name + ":";
    for (const auto& f : h.flags) s += " " + f;
    s += "\n";
  }
  return s;
}

class CliHelp : public ::testing::TestWithParam<HelpCase> {};

TEST_P(CliHelp, GroupsEveryFlagOnceUnderItsHeading) {
  const HelpCase& c = GetParam();
  const std::string binary = bin_dir() + "/" + c.binary;
  const auto [code, text] = help_of(binary);
  SCOPED_TRACE(std::string(c.binary) + " --help\n" + text);
  ASSERT_EQ(code, 0);
  const std::vector<Heading> printed = parse_help(text);
  std::map<std::string, int> times;
  for (const auto& h : printed)
    for (const auto& f : h.flags) ++times[f];
  for (const auto& [flag, n] : times) EXPECT_EQ(n, 1) << flag << " printed " << n << " times";
  EXPECT_EQ(describe(printed), describe(c.headings));
}

// Every binary the build makes: fleet_load only with TELLTALE_BUILD_BENCHMARKS (the sanitized
// build leaves the benchmarks out), so its case exists only where it is built, never skipped.
std::vector<HelpCase> cases() {
  std::vector<HelpCase> all = {
      HelpCase{
          "boat_node",
          {{"Options", {"--help", "--config"}},
           {"Identity", {"--boat-id", "--group"}},
           {"Sensors",
            {"--source", "--imu-rate-hz", "--seed", "--gyro-range-dps", "--acc-range-g",
             "--replay-fast", "--replay-loop"}},
           {"GNSS and heading", {"--gnss", "--heading", "--variation-deg"}},
           {"Mounting",
            {"--axis-remap", "--mount-file", "--sensor-offset", "--calibration-file",
             "--calibrate-s"}},
           {"Session log", {"--log-dir", "--log-max-mb", "--deliver-earlier-days"}},
           {"Alarms and LED panel",
            {"--console", "--warn-command", "--led-step-deg", "--leds-per-bar",
             "--default-max-heel-deg"}},
           {"DDS", {"--domain", "--rate-hz", "--dds-profiles", "--dds-participant", "--dds-peer"}},
           {"Security", {"--security-dir"}},
           {"Fault injection", {"--fault-drop-link"}}}},
      HelpCase{
          "wearable_node",
          {{"Options", {"--help", "--config"}},
           {"Identity", {"--athlete-id"}},
           {"Sensor", {"--source", "--mount", "--seed", "--replay-fast"}},
           {"Step length", {"--height-m", "--step-scale"}},
           {"DDS", {"--domain", "--rate-hz", "--dds-profiles", "--dds-participant", "--dds-peer"}},
           {"Security", {"--security-dir"}}}},
      HelpCase{
          "shore_server",
          {{"Options", {"--help", "--config"}},
           {"Dashboard and HTTP",
            {"--http-port", "--bind", "--web-dir", "--max-import-mb", "--rest-threads",
             "--keep-alive-s"}},
           {"Security", {"--coach-token", "--analyst-token", "--athlete-token", "--security-dir"}},
           {"Recording", {"--db", "--session-gap-s", "--retention-days", "--commit-ms"}},
           {"Live fleet",
            {"--stale-ms", "--forget-after-s", "--max-streams", "--stream-interval-ms"}},
           {"DDS", {"--domain", "--dds-profiles", "--dds-participant", "--dds-peer"}}}},
      HelpCase{"telltale_import",
               {{"Positionals", {}},
                {"Options", {"--help", "--config"}},
                {"Shore", {"--shore", "--token", "--timeout-s"}},
                {"Files", {"--boat", "--format", "--tz", "--date"}},
                {"Corrections", {"--heel-offset", "--pitch-offset", "--declination"}}}},
  };
#ifdef TELLTALE_HAS_FLEET_LOAD
  all.push_back(
        HelpCase{"fleet_load",
                 {{"Options", {"--help"}},
                  {"Shore", {"--shore-url", "--token", "--shore-pid"}},
                  {"Load", {"--boats", "--rate-hz", "--fix-hz", "--seconds", "--sse-clients"}},
                  {"DDS", {"--domain", "--dds-profiles"}}}});
#endif
  return all;
}

INSTANTIATE_TEST_SUITE_P(
    Binaries, CliHelp, ::testing::ValuesIn(cases()),
    [](const ::testing::TestParamInfo<HelpCase>& p) { return std::string(p.param.binary); });

}  // namespace
