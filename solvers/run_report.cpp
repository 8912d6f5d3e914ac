#include <jelly/solvers/run_report.hpp>

#include <cmath>
#include <cstdio>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/solvers/detail/run_fields.hpp>

namespace jelly {

std::string_view run_status_name(RunStatus status) {
  switch (status) {
    case RunStatus::kCompleted:
      return "completed";
    case RunStatus::kCompletedWithWarnings:
      return "completed_with_warnings";
    case RunStatus::kDiverged:
      return "diverged";
    case RunStatus::kSolverFailed:
      return "solver_failed";
  }
  return "unknown";
}

std::string RunReport::brief() const {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%s at t = %.6g s after %ld steps, %.3f s wall",
                std::string(run_status_name(status)).c_str(), t, steps, wall_seconds);
  std::string out = buffer;
  if (!reason.empty()) out += ": " + reason;
  return out;
}

const FieldTable<CrushLimits>& crush_fields() {
  using C = CrushLimits;
  static const FieldTable<C> table{
      "CrushLimits",
      "crush",
      "When a run that reaches its end ends completed_with_warnings naming a crushed body "
      "(docs/output.md)",
      {
          number_field<&C::min_volume_ratio>(
              "min_volume_ratio", "", range_closed(0, 1), "a number in [0, 1] (0: never by volume)",
              "A body's volume below this fraction of its rest volume; 0 = never by volume"),
          number_field<&C::max_inverted_fraction>(
              "max_inverted_fraction", "", range_closed(0, 1),
              "a number in [0, 1] (1: never by inverted cells)",
              "More than this fraction of a body's cells (tetrahedra) inverted; 1 = never"),
      },
  };
  return table;
}

void CrushLimits::validate() const { validate_fields(crush_fields(), *this, "crush."); }

void report_crushed_bodies(const Model& model, const VecX& x, const CrushLimits& limits,
                           RunReport& report) {
  for (const Body& body : model.bodies) {
    const BodyVolume v = body_volume(model, body, x);
    if (!v.has_volume()) {
      report.notes.push_back("body \"" + body.name + "\" (" + body.kind +
                             ") has no volume: not checked for crushing");
      continue;
    }
    const bool cells = !body.volume.cells.empty();
    const std::string what = cells ? "cells" : "tetrahedra";
    report.statistics["volume_ratio." + body.name] = v.ratio();
    report.statistics[(cells ? "inverted_cells." : "inverted_tets.") + body.name] =
        static_cast<double>(v.inverted);
    const bool small = v.ratio() < limits.min_volume_ratio;
    const bool inverted = v.inverted_fraction() > limits.max_inverted_fraction;
    if (!report.ok() || !(small || inverted)) continue;
    char figures[160];
    std::snprintf(figures, sizeof figures, "volume %.3g of its rest volume, %ld of %ld %s inverted",
                  v.ratio(), v.inverted, v.elements, what.c_str());
    char limit[160];
    std::snprintf(limit, sizeof limit, "crush limits: volume ratio >= %g, at most %g %% inverted",
                  limits.min_volume_ratio, 100 * limits.max_inverted_fraction);
    report.status = RunStatus::kCompletedWithWarnings;
    if (!report.reason.empty()) report.reason += "; ";
    report.reason += "body \"" + body.name + "\" is crushed: " + figures + " (" + limit + ")";
  }
}

}  // namespace jelly
