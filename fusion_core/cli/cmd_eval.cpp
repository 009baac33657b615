// fusion_cli eval: the accuracy tables of every area (attitude, and whatever other areas add).
#include <memory>

#include "commands.hpp"

namespace telltale::cli {

void register_eval(CLI::App& app) {
  auto* eval = app.add_subcommand(
      "eval", "Accuracy tables against simulator and recorded ground truth (all areas by default)");
  auto run_all = std::make_shared<std::vector<std::function<void()>>>();
  register_eval_attitude(*eval, *run_all);
  eval->callback([eval, run_all] {
    if (!eval->get_subcommands().empty()) return;  // an area was named: it ran itself
    for (const auto& run : *run_all) run();
  });
}

}  // namespace telltale::cli
