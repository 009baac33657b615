// fusion_cli manoeuvre-eval: the manoeuvre detector against the race simulator's ground truth.
#include <cstdio>

#include "commands.hpp"
#include "telltale/fusion/sim/manoeuvre_eval.hpp"

namespace telltale::cli {

void register_manoeuvre_eval(CLI::App& app) {
  struct Opts {
    std::uint64_t seed = 1;
    int seeds = 10;
    double minutes = 40.0;
    double min_turn_deg = 60.0;
    bool verbose = false;
    bool no_heel = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "manoeuvre-eval",
      "tacks, gybes, bear-aways, 720s detected on the simulated race (10 seeds) vs its truth");
  cmd->add_option("--seed", o->seed, "first seed")->capture_default_str();
  cmd->add_option("--seeds", o->seeds, "number of seeds")->capture_default_str();
  cmd->add_option("--minutes", o->minutes, "minutes of racing per seed")->capture_default_str();
  cmd->add_option("--min-turn-deg", o->min_turn_deg,
                  "detection threshold (mean course over the 10 s before a turn vs after it)")
      ->capture_default_str();
  cmd->add_flag("--no-heel", o->no_heel, "the course alone, as from a GNSS-only log");
  cmd->add_flag("--verbose", o->verbose,
                "list every miss, false detection, turn error > 5 deg and distance lost error > 2 m");
  cmd->callback([o] {
    fusion::ManoeuvreOptions opt;
    opt.min_turn_deg = o->min_turn_deg;
    const auto e = fusion::sim::evaluate_manoeuvres(o->seed, o->seeds, o->minutes, opt, 10.0, !o->no_heel);
    std::printf("kind       truth  detected  matched  recall  precision\n");
    const auto row = [](const char* n, const fusion::sim::KindScore& s) {
      std::printf("%-9s %6d %9d %8d  %6.3f  %9.3f\n", n, s.truth, s.detected, s.matched,
                  s.recall(), s.precision());
    };
    row("tack", e.tack);
    row("gybe", e.gybe);
    row("bear_away", e.bear_away);
    row("round_up", e.round_up);
    row("penalty", e.penalty);
    std::printf("mark roundings (not scored): %d\n", e.roundings);
    std::printf("turn angle error, matched tacks and gybes: mean %.2f deg, max %.2f deg\n",
                e.turn_err_mean_deg, e.turn_err_max_deg);
    std::printf("t0 error: mean %.2f s\n", e.t0_err_mean_s);
    std::printf("distance lost error, matched tacks and gybes: mean %.2f m, max %.2f m\n",
                e.lost_err_mean_m, e.lost_err_max_m);
    std::printf("wind direction error vs the simulated mean wind: mean %.2f deg, max %.2f deg\n",
                e.wind_err_mean_deg, e.wind_err_max_deg);
    if (o->verbose)
      for (const auto& m : e.misses) std::printf("  %s\n", m.c_str());
  });
}

}  // namespace telltale::cli
