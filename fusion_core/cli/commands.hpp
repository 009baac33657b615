#pragma once
/// \file
/// fusion_cli subcommands. Each lives in its own cmd_*.cpp and registers itself on the app;
/// main() maps io::CsvError and UsageError to exit status 2 with one line on stderr.

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace telltale::cli {

/// Bad input that is not a CSV error (an unknown filter name, an inconsistent option).
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The folder of real recordings the evaluations read (broad/, ipol_gait/, oxford_steps/, ...):
/// `flag` (--data) if given, else $TELLTALE_DATA, else ../shared/data relative to the working
/// directory. A user's clone has none of them: each evaluation says which table it skipped.
inline std::string real_data_dir(const std::string& flag) {
  if (!flag.empty()) return flag;
  if (const char* env = std::getenv("TELLTALE_DATA"); env && *env) return env;
  return "../shared/data";
}

void register_attitude(CLI::App& app);
void register_heading(CLI::App& app);
void register_steps(CLI::App& app);  // steps, pdr
void register_gait_sim(CLI::App& app);
void register_steps_eval(CLI::App& app);
void register_simulate(CLI::App& app);
void register_manoeuvre_eval(CLI::App& app);
/// `eval` is a group: each area (attitude, ...) adds a subcommand through register_eval_<area>
/// and pushes a runner with its default options; `fusion_cli eval` alone runs them all.
void register_eval(CLI::App& app);
void register_eval_attitude(CLI::App& eval, std::vector<std::function<void()>>& run_all);

}  // namespace telltale::cli
