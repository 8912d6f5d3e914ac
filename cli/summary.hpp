#pragma once
// The summary `jelly run` prints at the end: status, steps, wall time, final centre of mass,
// energies and the integrator's statistics.
#include <cstdio>
#include <string>

#include <jelly/io/scene.hpp>
#include <jelly/solvers/run_report.hpp>
#include <jelly/solvers/simulator.hpp>

namespace jelly::cli {

// `headline` replaces the report's own first line (report.brief()) when not empty.
void print_summary(std::FILE* out, const Scene& scene, const Simulator& sim,
                   const RunReport& report, const std::string& output_path,
                   const std::string& headline = "");

}  // namespace jelly::cli
