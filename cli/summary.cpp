#include "summary.hpp"

#include <jelly/core/measures.hpp>

namespace jelly::cli {

void print_summary(std::FILE* out, const Scene& scene, const Simulator& sim,
                   const RunReport& report, const std::string& output_path,
                   const std::string& headline) {
  const Model& m = sim.model();
  const State& s = sim.state();
  const Vec3 com = center_of_mass(m, s);
  const double rate = report.wall_seconds > 0 ? report.steps / report.wall_seconds : 0;
  std::fprintf(out, "jelly run: %s\n",
               headline.empty() ? report.brief().c_str() : headline.c_str());
  std::fprintf(out, "  integrator      %s, dt = %g s\n", scene.integrator.name.c_str(),
               scene.integrator.dt);
  std::fprintf(out, "  steps           %ld (%.0f steps/s), %ld force evaluations\n", report.steps,
               rate, report.force_evaluations);
  std::fprintf(out, "  centre of mass  (%.6f, %.6f, %.6f) m\n", com.x(), com.y(), com.z());
  const Real kinetic = kinetic_energy(m, s);
  const Real elastic = elastic_energy(m, s);
  const Real gravity = gravitational_energy(m, s);
  std::fprintf(out,
               "  energy          kinetic %.6g, elastic %.6g, gravitational %.6g, total %.6g J\n",
               kinetic, elastic, gravity, kinetic + elastic + gravity);
  std::string stats;
  for (const auto& [name, value] : report.statistics) {
    char number[32];
    std::snprintf(number, sizeof number, "%.6g", value);
    stats += (stats.empty() ? "" : ", ") + name + " = " + number;
  }
  if (!stats.empty()) std::fprintf(out, "  statistics      %s\n", stats.c_str());
  for (const std::string& note : report.notes)
    std::fprintf(out, "  note            %s\n", note.c_str());
  if (!output_path.empty()) std::fprintf(out, "  output          %s\n", output_path.c_str());
}

}  // namespace jelly::cli
