// jelly-bench: which integrator to use for which jelly, and why. Subcommands stability, accuracy,
// speed, seed, budget and merge; see docs/benchmarking.md.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <sstream>

#include <jelly/bench/accuracy.hpp>
#include <jelly/bench/budget.hpp>
#include <jelly/bench/output.hpp>
#include <jelly/bench/run_info.hpp>
#include <jelly/bench/seed_table.hpp>
#include <jelly/bench/shard.hpp>
#include <jelly/bench/speed.hpp>
#include <jelly/bench/stability.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/registry.hpp>

#ifndef JELLY_BENCH_SCENES_DIR
#define JELLY_BENCH_SCENES_DIR "scenes"
#endif

namespace {

using namespace jelly;
using namespace jelly::bench;

struct Common {
  std::string out = "out/bench";
  bool quick = false;
  std::string shard = "0/1";
  std::vector<std::string> integrators;
};

void add_common(CLI::App* app, Common& c) {
  app->add_option("--out", c.out, "output directory for CSV and HDF5")->capture_default_str();
  app->add_flag("--quick", c.quick,
                "small cubes, short horizons, few points (CI); options given explicitly are kept");
  app->add_option("--shard", c.shard, "run only work items k with k mod N == i")
      ->capture_default_str();
  app->add_option("--integrators", c.integrators, "comma-separated names (default: all registered)")
      ->delimiter(',');
}

// How often an option was given on the command line (0: its default stands).
std::size_t given(const CLI::App* command, const std::string& option) {
  return command->count(option);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"jelly-bench: stability, accuracy and cost of jelly's integrators"};
  app.require_subcommand(1);
  const std::vector<std::string> arguments(argv, argv + argc);

  Common common;
  StabilityOptions stability;
  std::string contact = "coulomb";
  bool kd_given = false, ratio_given = false;
  CLI::App* stability_cmd =
      app.add_subcommand("stability", "largest stable dt, measured and predicted");
  add_common(stability_cmd, common);
  stability_cmd->add_option("--ks", stability.ks, "spring stiffnesses (N/m)")
      ->delimiter(',')
      ->capture_default_str();
  stability_cmd
      ->add_option_function<std::vector<double>>(
          "--kd",
          [&](const std::vector<double>& v) {
            stability.kd = v;
            kd_given = true;
          },
          "damping per ks (N s/m); default kd = ratio * ks")
      ->delimiter(',');
  stability_cmd->add_option_function<double>(
      "--kd-ratio",
      [&](double r) {
        stability.kd_ratio = r;
        ratio_given = true;
      },
      "kd / ks (s), default the seed's 50/1400");
  stability_cmd->add_option("--scenes", stability.scenes, "slope, elevator")
      ->delimiter(',')
      ->capture_default_str();
  stability_cmd->add_option("--n", stability.n, "particles per cube edge")->capture_default_str();
  stability_cmd->add_option("--horizon", stability.horizon, "simulated time per run (s)")
      ->capture_default_str();
  stability_cmd->add_option("--contact", contact, "coulomb or seed")->capture_default_str();
  stability_cmd
      ->add_option("--energy-tolerance", stability.energy_tolerance,
                   "energy cap tolerance (docs/benchmarking.md); < 0: no energy check")
      ->capture_default_str();
  stability_cmd->add_option("--dt-max", stability.bracket.dt_max, "largest dt tried (s)")
      ->capture_default_str();
  stability_cmd
      ->add_option("--tolerance", stability.bracket.tolerance,
                   "relative width of the final bracket")
      ->capture_default_str();

  AccuracyOptions accuracy;
  CLI::App* accuracy_cmd = app.add_subcommand("accuracy", "work-precision, orders, energy drift");
  add_common(accuracy_cmd, common);
  accuracy_cmd->add_option("--n", accuracy.n, "particles per cube edge")->capture_default_str();
  accuracy_cmd->add_option("--t-end", accuracy.t_end, "final time (s)")->capture_default_str();
  accuracy_cmd->add_option("--dt", accuracy.dts, "time steps")
      ->delimiter(',')
      ->capture_default_str();
  accuracy_cmd->add_option("--reference-dt", accuracy.reference_dt, "0: smallest dt / 8")
      ->capture_default_str();
  accuracy_cmd->add_option("--drift-dt", accuracy.drift_dt, "time step of the drift runs (s)")
      ->capture_default_str();
  accuracy_cmd->add_option("--drift-t-end", accuracy.drift_t_end, "length of the drift runs (s)")
      ->capture_default_str();

  SpeedOptions speed;
  CLI::App* speed_cmd = app.add_subcommand("speed", "cost per step against cube size");
  add_common(speed_cmd, common);
  speed_cmd->add_option("--sizes", speed.sizes, "cube sizes n")
      ->delimiter(',')
      ->capture_default_str();
  speed_cmd->add_option("--dt", speed.dt, "time step (s)")->capture_default_str();
  speed_cmd
      ->add_option(
          "--preconditioners", speed.preconditioners,
          "implicit_euler's cg_preconditioner values (jacobi, cholmod, multigrid, amg; direct: "
          "its CHOLMOD solver instead of CG; amg_v: amg with amg_cycle v), a row "
          "each, labelled implicit_euler[name] (default: its default only)")
      ->delimiter(',');
  speed_cmd
      ->add_option("--scenes", speed.scenes,
                   "scene files measured instead of the slope's cubes (their bodies, terrains and "
                   "integrator options; --sizes and --ks unused), rows labelled @file")
      ->delimiter(',');
  speed_cmd->add_option("--ks", speed.ks, "spring stiffness of every type (N/m)")
      ->capture_default_str();
  speed_cmd->add_option("--warmup-steps", speed.warmup_steps, "untimed steps before the timed ones")
      ->capture_default_str();
  speed_cmd->add_option("--steps", speed.steps, "timed steps per configuration")
      ->capture_default_str();
  speed_cmd
      ->add_option("--threads", speed.threads,
                   "thread counts, one row each (0 = the default: all cores or one thread, chosen "
                   "step by step)")
      ->delimiter(',')
      ->capture_default_str();
  speed_cmd->add_flag("--interleave", speed.interleave,
                      "run the rows in alternation (blocks of steps in turn: the slope's thread "
                      "counts, sizes and preconditioners, or one scene's): a change of the "
                      "machine's speed falls on all of them alike; the peak memory then covers "
                      "them together");
  speed_cmd
      ->add_option("--interleave-block", speed.interleave_block,
                   "steps of one row before the next one's, with --interleave")
      ->capture_default_str();

  SeedOptions seed;
  CLI::App* seed_cmd = app.add_subcommand("seed", "the seed report's stability claims");
  add_common(seed_cmd, common);
  seed_cmd->add_option("--n", seed.n, "particles per cube edge")->capture_default_str();
  seed_cmd->add_option("--horizon", seed.horizon, "simulated time per run (s)")
      ->capture_default_str();
  std::vector<std::string> seed_contacts{"seed_framework", "seed"};
  seed_cmd
      ->add_option("--contact", seed_contacts,
                   "placements of the report's contact rules: seed_framework (in every force "
                   "evaluation, as the course framework), seed (after each step)")
      ->delimiter(',')
      ->capture_default_str();

  BudgetOptions budget;
  CLI::App* budget_cmd =
      app.add_subcommand("budget", "which integrator for a 1/60 s frame budget (seed slope)");
  add_common(budget_cmd, common);
  budget_cmd->add_option("--sizes", budget.sizes, "cube sizes n")
      ->delimiter(',')
      ->capture_default_str();
  budget_cmd
      ->add_option("--cloth", budget.cloth_sizes,
                   "cloth sizes (nu = nv) of scenes/cloth_on_sphere.json, measured after the cubes")
      ->delimiter(',');
  budget.scenes_dir = JELLY_BENCH_SCENES_DIR;
  budget_cmd->add_option("--scenes-dir", budget.scenes_dir, "the folder of cloth_on_sphere.json")
      ->capture_default_str();
  budget_cmd->add_option("--setups", budget.labels, "only these setups (labels, comma-separated)")
      ->delimiter(',');
  budget_cmd->add_option("--horizon", budget.horizon, "simulated time measured (s)")
      ->capture_default_str();
  budget_cmd
      ->add_option("--search-horizon", budget.search_horizon,
                   "simulated time of each stability run of the searches (s)")
      ->capture_default_str();
  budget_cmd->add_option("--ks-ladder", budget.ks_ladder, "stiffnesses tried (kd proportional)")
      ->delimiter(',')
      ->capture_default_str();
  budget_cmd
      ->add_option("--ks-search-max-n", budget.ks_search_max_n,
                   "sizes above this skip the ks ladder")
      ->capture_default_str();
  budget_cmd
      ->add_option("--reference-steps", budget.reference_steps_per_frame,
                   "RK4 reference steps per frame")
      ->capture_default_str();

  std::vector<std::string> merge_inputs;
  std::string merge_out = "out/bench";
  CLI::App* merge_cmd = app.add_subcommand("merge", "merge the CSV files of shards");
  merge_cmd->add_option("inputs", merge_inputs, "directories or CSV files")->required();
  merge_cmd->add_option("--out", merge_out, "output directory")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::cerr << "error: " << e.what() << "\nRun 'jelly-bench --help' for usage.\n";
    return 2;
  }
  try {
    const Metadata metadata = run_metadata(arguments);
    if (merge_cmd->parsed()) {
      // Everything read from the CSV files is input: what is wrong with it is bad input.
      MergedRun run;
      std::vector<Table> tables, summaries;
      try {
        run = merge_csv(merge_inputs);
        for (const auto& [name, table] : run.tables) tables.push_back(table);
        // Summaries are recomputed from the merged rows (and replace any read back).
        summaries = summary_tables(run.command, tables);
      } catch (const InputError&) {
        throw;
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::exception& e) {
        throw InputError(std::string("merge: ") + e.what());
      }
      for (const Table& summary : summaries) {
        tables.erase(std::remove_if(tables.begin(), tables.end(),
                                    [&](const Table& t) { return t.name() == summary.name(); }),
                     tables.end());
      }
      for (Table& t : summaries) tables.push_back(std::move(t));
      Metadata merged = run.metadata;
      merged["merge_command_line"] = metadata.at("command_line");
      write_outputs(run.command, tables, merged, merge_out, Shard{}, std::cout);
      return 0;
    }
    const Shard shard = Shard::parse(common.shard);
    std::string command;
    std::vector<Table> tables;
    if (stability_cmd->parsed()) {
      command = "stability";
      require(!(kd_given && ratio_given), "--kd", "given with --kd-ratio", "one of the two");
      stability.contact = contact_model_from_name(contact, "--contact");
      if (common.quick) {  // smaller defaults; an option given explicitly is kept
        if (given(stability_cmd, "--n") == 0) stability.n = 4;
        if (given(stability_cmd, "--horizon") == 0) stability.horizon = 1;
        if (given(stability_cmd, "--ks") == 0) stability.ks = {1400, 5600};
        if (given(stability_cmd, "--tolerance") == 0) stability.bracket.tolerance = 0.1;
      }
      stability.integrators = common.integrators;
      stability.shard = shard;
      stability.progress = &std::cerr;
      tables = {run_stability(stability)};
    } else if (accuracy_cmd->parsed()) {
      command = "accuracy";
      if (common.quick) {
        if (given(accuracy_cmd, "--n") == 0) accuracy.n = 3;
        if (given(accuracy_cmd, "--t-end") == 0) accuracy.t_end = 0.2;
        if (given(accuracy_cmd, "--dt") == 0) accuracy.dts = {1e-3, 5e-4, 2.5e-4};
        if (given(accuracy_cmd, "--drift-t-end") == 0) accuracy.drift_t_end = 1;
      }
      accuracy.integrators = common.integrators;
      accuracy.shard = shard;
      tables = run_accuracy(accuracy);
    } else if (speed_cmd->parsed()) {
      command = "speed";
      if (common.quick) {
        if (given(speed_cmd, "--sizes") == 0) speed.sizes = {3, 5};
        if (given(speed_cmd, "--steps") == 0) speed.steps = 20;
        speed.warmup_steps = std::min(speed.warmup_steps, 5);
      }
      speed.integrators = common.integrators;
      speed.shard = shard;
      tables = run_speed(speed);
    } else if (budget_cmd->parsed()) {
      command = "budget";
      if (common.quick) {
        if (budget_cmd->count("--sizes") == 0) budget.sizes = {4};
        budget.horizon = 0.5;
        budget.search_horizon = 0.5;
        budget.lowered = true;
        if (budget_cmd->count("--ks-ladder") == 0) budget.ks_ladder = {1400, 22400};
        budget.steps_ladder = {1, 2, 4, 8, 16};
        budget.sample_every = 3;
      }
      if (!common.integrators.empty()) {
        for (const BudgetSetup& s : default_budget_setups())
          if (std::find(common.integrators.begin(), common.integrators.end(), s.integrator) !=
              common.integrators.end())
            budget.setups.push_back(s);
        require(!budget.setups.empty(), "--integrators", "(none with a budget setup)",
                "integrators among the budget setups");
      }
      budget.shard = shard;
      budget.progress = &std::cerr;
      tables = {run_budget(budget)};
    } else if (seed_cmd->parsed()) {
      command = "seed";
      if (common.quick) {
        if (given(seed_cmd, "--n") == 0) seed.n = 4;
        if (given(seed_cmd, "--horizon") == 0) seed.horizon = 0.5;
      }
      seed.integrators = common.integrators;
      seed.contacts.clear();
      for (const std::string& c : seed_contacts)
        seed.contacts.push_back(contact_model_from_name(c, "--contact"));
      seed.shard = shard;
      seed.progress = &std::cerr;
      tables = {run_seed(seed)};
    }
    if (shard.count == 1) {
      for (Table& t : summary_tables(command, tables)) tables.push_back(std::move(t));
    } else {
      std::cout << "shard " << shard.text()
                << ": summaries are computed by `jelly-bench merge` over all shards\n";
    }
    write_outputs(command, tables, metadata, common.out, shard, std::cout);
  } catch (const InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
