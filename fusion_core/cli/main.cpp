// fusion_cli: the fusion core offline, for analysts and tests (SPEC section 6).
#include <cstdio>
#include <exception>

#include "commands.hpp"
#include "csv.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "Telltale fusion core, offline: attitude, heading, steps, PDR, simulation, evaluation"};
  app.require_subcommand(1);
  telltale::cli::register_attitude(app);
  telltale::cli::register_heading(app);
  telltale::cli::register_steps(app);
  telltale::cli::register_gait_sim(app);
  telltale::cli::register_steps_eval(app);
  telltale::cli::register_simulate(app);
  telltale::cli::register_eval(app);
  telltale::cli::register_manoeuvre_eval(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const telltale::io::CsvError& e) {
    std::fprintf(stderr, "fusion_cli: %s\n", e.what());
    return 2;
  } catch (const telltale::cli::UsageError& e) {
    std::fprintf(stderr, "fusion_cli: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fusion_cli: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
