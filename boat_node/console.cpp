#include "console.hpp"

#include <spawn.h>
#include <sys/wait.h>

#include <cmath>
#include <vector>

extern char** environ;

namespace telltale::boat {
namespace {
std::string bar(int lit, int count, bool reverse) {
  std::string s;
  for (int i = 0; i < count; ++i) {
    const int led = reverse ? count - 1 - i : i;  // the left bar lights from the centre outwards
    s += led < lit ? '#' : '.';
  }
  return s;
}
}  // namespace

std::string render_panel(const std::string& boat_id, double heel_deg, double pitch_deg,
                         const fusion::LedPanelState& leds, int leds_per_bar,
                         fusion::AlarmLevel level, bool colour) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%-10s heel %+6.1f [%s|%s]  pitch %+6.1f [up %s | down %s]  %-6s",
                boat_id.c_str(), heel_deg, bar(leds.left, leds_per_bar, true).c_str(),
                bar(leds.right, leds_per_bar, false).c_str(), pitch_deg,
                bar(leds.up, leds_per_bar, false).c_str(),
                bar(leds.down, leds_per_bar, false).c_str(), fusion::to_string(level));
  if (!colour) return buf;
  const char* on = level == fusion::AlarmLevel::kAlarm  ? "\033[1;41;97m"
                   : level == fusion::AlarmLevel::kWarn ? "\033[1;43;30m"
                                                        : "\033[1;32m";
  return std::string(on) + buf + "\033[0m";
}

WarningHook::~WarningHook() {
  while (waitpid(-1, nullptr, WNOHANG) > 0) {
  }
}

void WarningHook::on_level(const std::string& boat_id, fusion::AlarmLevel level, double value_deg,
                           std::chrono::steady_clock::time_point now) {
  while (waitpid(-1, nullptr, WNOHANG) > 0) {
  }
  const bool rose = level > last_;
  last_ = level;
  if (command_.empty() || !rose || level == fusion::AlarmLevel::kNormal) return;
  if (runs_ > 0 && now - last_run_ < min_interval_) return;
  last_run_ = now;
  std::vector<std::string> env_strings;
  for (char** e = environ; *e; ++e) env_strings.emplace_back(*e);
  env_strings.push_back("TELLTALE_BOAT=" + boat_id);
  env_strings.push_back(std::string("TELLTALE_LEVEL=") + fusion::to_string(level));
  char v[32];
  std::snprintf(v, sizeof v, "%.1f", value_deg);
  env_strings.push_back(std::string("TELLTALE_VALUE_DEG=") + v);
  std::vector<char*> envp;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::string sh = "/bin/sh", c = "-c", cmd = command_;
  char* argv[] = {sh.data(), c.data(), cmd.data(), nullptr};
  pid_t pid = 0;
  if (posix_spawn(&pid, "/bin/sh", nullptr, nullptr, argv, envp.data()) == 0) ++runs_;
}

}  // namespace telltale::boat
