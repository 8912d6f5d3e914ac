#include <jelly/bench/seed_table.hpp>

#include <algorithm>
#include <cmath>
#include <set>

#include <jelly/bench/scenes.hpp>
#include <jelly/bench/stability_region.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::bench {

namespace {

struct Configuration {
  const char* name;
  Real ks, kd, dt;
};
// The report's runs: its default (dt 0.001), the two larger steps, and the stiffer material.
constexpr Configuration kConfigurations[] = {
    {"seed_dt_0.001", 1400, 50, 0.001},
    {"seed_dt_0.0027", 1400, 50, 0.0027},
    {"seed_dt_1/60", 1400, 50, 1.0 / 60},
    {"ks2400_kd120_dt_0.001", 2400, 120, 0.001},
};
const char* const kScenes[] = {"slope", "elevator"};
const std::set<std::string> kReportMethods{"explicit_euler", "midpoint", "rk4", "symplectic_euler"};

}  // namespace

void SeedOptions::validate() const {
  require(n >= 2 && n <= 40, "--n", n, "an integer in [2, 40]");
  require(std::isfinite(horizon) && horizon > 0, "--horizon", horizon, "a time > 0 s");
  require(!contacts.empty(), "--contact", "(none)", "seed, seed_framework or both");
  for (ContactModel c : contacts)
    require(is_seed_model(c), "--contact", contact_model_name(c), "seed or seed_framework");
}

Table run_seed(const SeedOptions& o) {
  o.validate();
  const std::vector<std::string> integrators =
      o.integrators.empty() ? integrator_names() : o.integrators;
  for (const std::string& name : integrators) make_integrator(name);
  Table table("seed",
              "the report's runs with its contact rules: stable over the horizon, or the time "
              "and reason of divergence",
              {"item", "contact:s", "configuration:s", "scene:s", "integrator:s", "n", "ks", "kd",
               "dt", "horizon", "status:s", "diverged_at", "reason:s"});
  long item = 0;
  for (const ContactModel contact : o.contacts) {
    const std::string contact_name(contact_model_name(contact));
    for (const Configuration& c : kConfigurations) {
      for (const char* scene : kScenes) {
        for (const std::string& integrator : integrators) {
          const long this_item = item++;
          if (!o.shard.owns(this_item)) continue;
          std::vector<Cell> row{static_cast<double>(this_item),
                                contact_name,
                                std::string(c.name),
                                std::string(scene),
                                integrator,
                                static_cast<double>(o.n),
                                c.ks,
                                c.kd,
                                c.dt,
                                o.horizon};
          if (is_adaptive_integrator(integrator)) {
            row.insert(row.end(), {std::string("skipped_adaptive"), NAN,
                                   std::string("adaptive: no fixed dt")});
            table.add_row(row);
            continue;
          }
          if (contact == ContactModel::kSeedFramework &&
              !integrator_supports_in_evaluation_contact(integrator)) {
            row.insert(row.end(), {std::string("skipped_unsupported"), NAN,
                                   std::string("seed_framework needs an explicit integrator")});
            table.add_row(row);
            continue;
          }
          SceneSpec spec;
          spec.name = scene;
          spec.n = o.n;
          spec.ks = c.ks;
          spec.kd = c.kd;
          spec.contact = contact;
          Simulator sim =
              make_scene_simulator(spec, integrator, c.dt, o.horizon, o.energy_tolerance);
          const RunReport report = sim.run_until(o.horizon);
          row.insert(row.end(), {std::string(run_status_name(report.status)),
                                 report.ok() ? NAN : report.t, report.reason});
          table.add_row(row);
          if (o.progress) {
            *o.progress << "seed item " << this_item << ": " << contact_name << " " << c.name << " "
                        << scene << " " << integrator << ": " << report.brief() << std::endl;
          }
        }
      }
    }
  }
  return table;
}

Table seed_claims(const Table& seed) {
  Table claims("seed_claims",
               "the report's claims against our runs (survivors among the report's four methods: "
               "explicit_euler, midpoint, rk4, symplectic_euler)",
               {"claim:s", "contact:s", "scene:s", "configuration:s", "expected:s", "survivors:s",
                "other_survivors:s", "verdict:s"});
  // The contact models of the table, in order of appearance.
  std::vector<std::string> contacts;
  for (int r = 0; r < seed.rows(); ++r) {
    const std::string& c = seed.text(r, "contact");
    if (std::find(contacts.begin(), contacts.end(), c) == contacts.end()) contacts.push_back(c);
  }
  struct Claim {
    const char* text;
    const char* configuration;
    bool only_rk4;  // true: survivors == {rk4}; false: rk4 does not survive
  };
  const Claim list[] = {
      {"ks 2400 / kd 120: only RK4 survives", "ks2400_kd120_dt_0.001", true},
      {"dt 0.0027: only RK4 survives", "seed_dt_0.0027", true},
      {"larger dt (1/60): even RK4 fails", "seed_dt_1/60", false},
  };
  for (const std::string& contact : contacts) {
    for (const Claim& claim : list) {
      for (const char* scene : kScenes) {
        std::set<std::string> seen, survivors;
        std::string others;
        for (int r = 0; r < seed.rows(); ++r) {
          if (seed.text(r, "contact") != contact ||
              seed.text(r, "configuration") != claim.configuration ||
              seed.text(r, "scene") != scene)
            continue;
          const std::string& name = seed.text(r, "integrator");
          const std::string& status = seed.text(r, "status");
          const bool stable = status == "completed" || status == "completed_with_warnings";
          if (kReportMethods.count(name)) {
            seen.insert(name);
            if (stable) survivors.insert(name);
          } else if (stable) {
            others += (others.empty() ? "" : " ") + name;
          }
        }
        std::string list_text;
        for (const std::string& s : survivors) list_text += (list_text.empty() ? "" : " ") + s;
        std::string verdict;
        if (claim.only_rk4) {
          if (seen.size() < kReportMethods.size()) {
            verdict = "incomplete";
          } else {
            verdict = survivors == std::set<std::string>{"rk4"} ? "confirmed" : "refuted";
          }
        } else {
          verdict = !seen.count("rk4") ? "incomplete"
                                       : (survivors.count("rk4") ? "refuted" : "confirmed");
        }
        claims.add_row({std::string(claim.text), contact, std::string(scene),
                        std::string(claim.configuration),
                        std::string(claim.only_rk4 ? "rk4 only" : "rk4 unstable"),
                        list_text.empty() ? std::string("(none)") : list_text,
                        others.empty() ? std::string("(none)") : others, verdict});
      }
    }
  }
  return claims;
}

}  // namespace jelly::bench
