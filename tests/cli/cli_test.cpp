// The jelly program as users run it: exit codes 0, 2 and 3, "error: ..." messages naming the
// JSON path, `jelly list`, and the HDF5 options of this build.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/components.hpp>
#include <jelly/geometry/body_shape.hpp>
#include <jelly/io/detail/field_reference.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/terrain_kinds.hpp>
#include <jelly/version.hpp>

#include "cli/cli_support.hpp"

namespace jelly {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;
using namespace cli_testing;

TEST(Cli, FieldsPrintsEveryFieldTableAsMarkdownOrJson) {
  const Result md = jelly("fields");
  ASSERT_EQ(md.code, 0) << md.err;
  EXPECT_EQ(md.err, "");
  for (const FieldTableDoc& table : scene_field_tables()) {
    EXPECT_THAT(md.out, HasSubstr(table.path.empty() ? std::string("## The top level")
                                                     : "## `" + table.path + "`"))
        << table.name;
    for (const FieldDoc& f : table.fields) {
      // The default: required, none (an optional key), blank (an object or list row: its own
      // table), or its JSON.
      const std::string fallback = f.required                               ? "required"
                                   : f.optional                             ? "none"
                                   : f.type == "object" || f.type == "list" ? ""
                                                                            : "`" + f.default_text;
      EXPECT_THAT(md.out, HasSubstr("| `" + f.name + "` | " + f.type + " | " + fallback))
          << table.name << "." << f.name;
    }
  }
  const Result json = jelly("fields --format json");
  ASSERT_EQ(json.code, 0) << json.err;
  EXPECT_EQ(json.out, field_tables_json(scene_field_tables()));
  const Result bad = jelly("fields --format xml");
  EXPECT_EQ(bad.code, 2);
  EXPECT_THAT(bad.err, HasSubstr("--format"));
}

TEST(Cli, ListNamesEveryIntegratorTerrainKindAndContactModel) {
  const Result r = jelly("list");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const std::string& name : integrator_names()) {
    EXPECT_THAT(r.out, HasSubstr("integrator " + name + " ")) << name;
  }
  for (const TerrainKindInfo& kind : terrain_kinds()) {
    EXPECT_THAT(r.out, HasSubstr("\nterrain    " + std::string(kind.name) + " "));
  }
  for (const BodyKindInfo& kind : body_kinds()) {
    EXPECT_THAT(r.out, HasSubstr("\nbody       " + std::string(kind.name) + " "));
  }
  for (const EnumName<ContactModel>& model : contact_models()) {
    EXPECT_THAT(r.out, HasSubstr("\ncontact    " + std::string(model.name) + " "));
  }
}

// `jelly list` shows the components of this build first (the program and this test link the
// same ones), and a component's integrators only when it is there.
TEST(Cli, ListShowsTheComponentsOfThisBuild) {
  const Result r = jelly("list");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, StartsWith("component  core "));
  for (const char* name : {"io", "meshes", "arkode", "fit"}) {
    const bool built = std::string(name) == "io" ||
                       (std::string(name) == "meshes" && JELLY_WITH_MESHES) ||
                       (std::string(name) == "arkode" && JELLY_WITH_ARKODE) ||
                       (std::string(name) == "fit" && JELLY_WITH_FIT);
    EXPECT_EQ(has_component(name), built) << name;
    EXPECT_EQ(r.out.find("\ncomponent  " + std::string(name) + " ") != std::string::npos, built)
        << name;
  }
  // The program links the viewer layer (at least its exports): it names the component viewer.
  EXPECT_NE(r.out.find("\ncomponent  viewer "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("\nintegrator arkode_dirk ") != std::string::npos,
            static_cast<bool>(JELLY_WITH_ARKODE));
  EXPECT_EQ(r.out.find("\nintegrator arkode_erk ") != std::string::npos,
            static_cast<bool>(JELLY_WITH_ARKODE));
}

TEST(Cli, AShortGoodRunExitsZeroWithASummary) {
  const Result r = jelly("run " + kSmallSlope + " --duration 0.05 --integrator midpoint");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // stderr is not a terminal: no progress bar
  EXPECT_THAT(r.out, StartsWith("jelly run: completed at t = 0.05 s after 50 steps"));
  EXPECT_THAT(r.out, HasSubstr("integrator      midpoint, dt = 0.001 s"));
  EXPECT_THAT(r.out, HasSubstr("centre of mass  ("));
  EXPECT_THAT(r.out, HasSubstr("energy          kinetic "));
  // The integrator's counters and each body's crush measures (volume ratio, inverted cells).
  EXPECT_THAT(
      r.out,
      HasSubstr("statistics      inverted_cells.jelly = 0, steps = 50, volume_ratio.jelly = 1"));
}

// Implicit Euler at a game's time step with contact inside its solve: it completes, and the
// summary reports the contact statistics; a bad contact option names its path.
TEST(Cli, ImplicitEulerResolvesContactInItsSolve) {
  Result r = jelly("run '" + scene("drop_coulomb.json") +
                   "' --set cube.n=3 --duration 1 --integrator implicit_euler --dt 0.0333333");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("integrator      implicit_euler, dt = 0.0333333 s"));
  EXPECT_THAT(r.out, HasSubstr("contact_extra_solves = "));
  EXPECT_THAT(r.out, HasSubstr("contact_not_converged = 0,"));

  r = jelly("run '" + scene("drop_coulomb.json") +
            "' --integrator implicit_euler --set integrator.options.contact=penalty");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "error: integrator.options.contact = \"penalty\" is invalid: one of \"implicit\", "
            "\"after_step\"\n");
}

TEST(Cli, ADivergentRunExitsThree) {
  const Result r = jelly("run " + kSmallSlope + " --integrator explicit_euler --dt 0.05 --quiet");
  EXPECT_EQ(r.code, 3) << r.out << r.err;
  EXPECT_THAT(r.out, StartsWith("jelly run: diverged at t = "));
  // The seed contact at dt = 0.05 s is warned about first (docs/contact.md).
  EXPECT_THAT(r.err, StartsWith("warning: terrains[0]: the seed contact rules act within"));
  EXPECT_THAT(r.err, HasSubstr("\nerror: the run stopped early: diverged at t = "));
}

// A seed-model terrain at a step that crosses its epsilon zone is warned about at the start,
// naming the coulomb model; at the report's dt = 1 ms it is not.
TEST(Cli, SeedContactAtLargeStepsWarns) {
  Result r = jelly("run '" + scene("seed_slope.json") + "' --dt 0.0166667 --duration 0.02 --quiet");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.err, StartsWith("warning: terrains[0]: the seed contact rules act within epsilon"));
  EXPECT_THAT(r.err, HasSubstr("terrains[0].contact.model = \"coulomb\""));
  r = jelly("run '" + scene("seed_slope.json") + "' --duration 0.02 --quiet");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
}

// Bad bodies exit 2 naming the field, the value and what is allowed (issue 12's bad input): a
// pin by a group the mesh does not have lists the groups it has; a spacing that would make
// more particles than max_particles (default 2 million); two bodies of one name.
TEST(Cli, BadBodiesExitTwoNamingTheField) {
  Result r = jelly("run '" + scene("gummy_bear.json") +
                   "' --set 'bodies[0].pins=[{\"group\": \"tail\"}]'");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "error: bodies[0].pins[0].group = \"tail\" is invalid: a group of the body: one of "
            "arm_left, arm_right, belly, ear_left, ear_right, head, leg_left, leg_right, snout\n");
  r = jelly("run '" + scene("gummy_bear.json") + "' --set bodies[0].spacing=0.004");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("is invalid: at most max_particles = 2000000"));
  r = jelly("run '" + scene("gummy_bear.json") + "' --set bodies[0].spacing=1");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: bodies[0].spacing = 1 is invalid: a spacing that leaves "
                                "at least 8 lattice points"));
  r = jelly("run '" + scene("two_jellies.json") + "' --set bodies[1].name=soft");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "error: bodies[1].name = \"soft\" is invalid: a name no other body has (bodies[0] has "
            "it)\n");
}

TEST(Cli, BadScenesExitTwoNamingTheJsonPath) {
  const std::string bad_range = write_scene(R"({
    "terrains": [{"kind": "plane", "contact": {"restitution": 1.5}}],
    "integrator": {"name": "rk4"}, "duration": 1})");
  Result r = jelly("run '" + bad_range + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: terrains[0].contact.restitution = 1.5 is invalid: a number in [0, 1]\n");
  EXPECT_EQ(r.out, "");

  const std::string unknown_key = write_scene(R"({
    "springs": {"shear": {"ks": 10, "kb": 1}}, "integrator": {"name": "rk4"}, "duration": 1})");
  r = jelly("run '" + unknown_key + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "error: springs.shear.kb = 1 is invalid: unknown key; allowed here: \"ks\", \"kd\"\n");

  const std::string missing = write_scene(R"({"integrator": {"name": "rk4"}})");
  r = jelly("run '" + missing + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: duration is missing: it is required\n");

  const std::string not_json = write_scene("{\"duration\": ");
  r = jelly("run '" + not_json + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: " + not_json + " is not valid JSON: parse error"));

  r = jelly("run '" + scene("no_such_scene.json") + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: cannot read the scene file '"));
}

TEST(Cli, BadOptionsExitTwoNamingTheJsonPath) {
  Result r = jelly("run " + kSmallSlope + " --dt abc");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: integrator.dt = \"abc\" is invalid: a number\n");

  r = jelly("run " + kSmallSlope + " --dt -1");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: integrator.dt = -1 is invalid: a finite time step > 0 s\n");

  r = jelly("run " + kSmallSlope + " --duration 0");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: duration = 0 is invalid: a finite duration > 0 s\n");

  r = jelly("run " + kSmallSlope + " --integrator rk5");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: integrator.name = \"rk5\" is invalid: one of "));

  r = jelly("run " + kSmallSlope + " --set terrains[0].contact.friction=-2");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: terrains[0].contact.friction = -2 is invalid: a finite number >= 0\n");

  r = jelly("run " + kSmallSlope + " --set terrains.1.kind=plane");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "error: --set 'terrains.1.kind=plane': terrains[1] does not exist (terrains has 1 "
            "element)\n");

  r = jelly("run " + kSmallSlope + " --set cube.n");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: --set 'cube.n': expected path=value"));
}

// Obstacles: a bad radius exits 2 naming the field; a good one runs.
TEST(Cli, ObstacleKindsRunAndNameTheirBadFields) {
  const std::string path = write_scene(R"({
    "cube": {"n": 3, "edge_length": 1, "origin": [-0.5, 1.2, -0.5]},
    "terrains": [{"kind": "plane"}, {"kind": "sphere", "center": [0, 0.5, 0], "radius": 0.5},
                 {"kind": "box", "center": [2, 0, 0], "size": [1, 1, 1],
                  "motion": {"kind": "oscillation", "amplitude": [0, 0.2, 0], "frequency": 1}},
                 {"kind": "capsule", "center": [-2, 0, 0], "radius": 0.2, "height": 1},
                 {"kind": "cylinder", "center": [0, 0, 2], "radius": 0.2, "height": 1,
                  "angular_velocity_degrees": [0, 90, 0]}],
    "integrator": {"name": "rk4", "dt": 0.001},
    "duration": 0.3})");
  Result r = jelly("run '" + path + "' --quiet");
  EXPECT_EQ(r.code, 0) << r.err;
  r = jelly("run '" + path + "' --set terrains[1].radius=-1");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "error: terrains[1].radius = -1 is invalid: a finite radius > 0 (m)\n");
  r = jelly("run '" + path + "' --set terrains[2].size=[1,0,1]");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: terrains[2].size = "));
}

TEST(Cli, OverlappingBodiesExitTwoNamingBoth) {
  const Result r = jelly("run '" + scene("jelly_stack.json") +
                         "' --set bodies[1].origin=[-0.5,0.8,-0.5] --duration 0.01");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: bodies \"bottom\" and \"middle\" overlap at the start: "));
}

TEST(Cli, CommandLineParseErrorsExitTwo) {
  Result r = jelly("run " + kSmallSlope + " --bogus");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: The following argument was not expected: --bogus\n"));

  r = jelly("run");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: scene is required\n"));

  r = jelly("");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: A subcommand is required\n"));

  r = jelly("fly");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: "));

  r = jelly("run " + kSmallSlope + " --dt");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: --dt: 1 required H missing"));
  EXPECT_THAT(r.err, HasSubstr("'jelly run --help'"));

  // The usage named is the command's own (render's errors sent readers to `jelly run --help`;
  // seen while fuzzing render's command line, issue 44).
  r = jelly("render missing.h5");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("Run 'jelly --help' or 'jelly render --help' for usage."));
  r = jelly("export --pc2");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("'jelly export --help'"));
}

// CLI11's NonNegativeNumber answered --threads -1 with the range of a double (310 digits).
TEST(Cli, AThreadCountOutOfRangeExitsTwoNamingWhatIsAllowed) {
  for (const std::string value : {"-1", "1.5", "99999999999", "x"}) {
    const Result r = jelly("run " + kSmallSlope + " --threads " + value);
    EXPECT_EQ(r.code, 2) << value;
    EXPECT_EQ(
        r.err.substr(0, r.err.find('\n')),
        "error: --threads: " + value + " is invalid: an integer from 0 (all cores) to 2147483647")
        << value;
  }
  EXPECT_EQ(jelly("run " + kSmallSlope + " --threads 1 --duration 0.01 -q").code, 0);
}

// Runs `jelly ARGS` on a pseudo-terminal (util-linux `script`), stdout and stderr together.
Result jelly_on_a_terminal(const std::string& args) {
  const std::string out = temp_path(".tty");
  const std::string command = "script -qec \"'" + std::string(JELLY_CLI) + "' " + args +
                              "\" /dev/null >'" + out + "' 2>&1 </dev/null";
  const int status = std::system(command.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out);
  std::remove(out.c_str());
  return r;
}

TEST(Cli, ProgressBarOnATerminalOnlyAndNotWithQuiet) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no `script`";
  Result r = jelly_on_a_terminal("run " + kSmallSlope + " --duration 0.2");
  ASSERT_EQ(r.code, 0) << r.out;
  // The final redraw of the bar, then the summary.
  EXPECT_THAT(r.out, HasSubstr("\r[########################] 100%  t = 0.200 / 0.200 s  "));
  EXPECT_THAT(r.out, HasSubstr(" steps/s  ETA 0:00"));
  EXPECT_THAT(r.out, HasSubstr("jelly run: completed at t = 0.2 s after 200 steps"));

  r = jelly_on_a_terminal("run " + kSmallSlope + " --duration 0.2 --quiet");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_THAT(r.out, Not(HasSubstr("steps/s  ETA")));
  EXPECT_THAT(r.out, HasSubstr("jelly run: completed at t = 0.2 s after 200 steps"));
}

TEST(Cli, HelpExitsZero) {
  const Result r = jelly("run --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_THAT(r.out, HasSubstr("--set PATH=VALUE"));
  EXPECT_THAT(r.out, HasSubstr("Exit codes: 0 ok, 2 bad input"));
}

TEST(Cli, RunWritesAFileThatInfoDescribes) {
  const std::string file = temp_path(".h5");
  Result r = jelly("run " + kSmallSlope + " --duration 0.1 -o '" + file + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  r = jelly("info '" + file + "'");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out, "");
}

// jelly xdmf writes the sidecar a run writes (for a killed run, or an older recording), and
// replaces an existing one only with --overwrite.
TEST(Cli, XdmfWritesTheSidecarOfARecording) {
  const std::string file = temp_path(".h5");
  const std::string sidecar = file.substr(0, file.size() - 3) + ".xdmf";
  Result r = jelly("run " + kSmallSlope + " --duration 0.1 -q -o '" + file + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string written = read_file(sidecar);
  ASSERT_THAT(written, HasSubstr("<Xdmf"));
  r = jelly("info '" + file + "'");
  EXPECT_THAT(r.out, HasSubstr("sidecar:       " + sidecar + " (open it in ParaView)"));
  ASSERT_EQ(std::remove(sidecar.c_str()), 0);
  r = jelly("info '" + file + "'");
  EXPECT_THAT(r.out, HasSubstr("sidecar:       none (`jelly xdmf " + file + "` writes it"));
  r = jelly("xdmf '" + file + "'");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("wrote " + sidecar));
  EXPECT_EQ(read_file(sidecar), written);
  r = jelly("xdmf '" + file + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("'" + sidecar + "' exists: pass --overwrite"));
  r = jelly("xdmf '" + file + "' --overwrite --no-strain");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(read_file(sidecar), Not(HasSubstr("strain")));
  r = jelly("xdmf '" + sidecar + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("give the recording (.h5)"));
  r = jelly("xdmf '" + temp_path(".h5") + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("no such file"));
}

TEST(Cli, ADivergentRunKeepsItsFile) {
  const std::string file = temp_path(".h5");
  Result r =
      jelly("run " + kSmallSlope + " --integrator explicit_euler --dt 0.05 -q -o '" + file + "'");
  EXPECT_EQ(r.code, 3) << r.err;
  r = jelly("info '" + file + "'");
  EXPECT_EQ(r.code, 0) << r.err;
}

// A 3x3x3 jelly dropped 0.3 m onto the floor (coulomb contact) with ks = 1000 and kd = 20 for
// every spring type, recorded every 10 ms for 0.5 s.
const std::string kFitScene =
    "'" + scene("drop_coulomb.json") +
    "' --set cube.n=3 --set cube.origin=[-1,0.3,-1] --set springs.structural.ks=1000 "
    "--set springs.shear.ks=1000 --set springs.bending.ks=1000 --set springs.bending.kd=20 "
    "--set output_interval=0.01 --set integrator.name=rk4 -q";

// jelly fit recovers the coefficients of a recording from other starting values, and writes
// a scene with them that loads.
TEST(Cli, FitRecoversTheCoefficientsOfARecording) {
  const std::string file = temp_path(".h5");
  Result r = jelly("run " + kFitScene + " --duration 0.5 -o '" + file + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string fitted = temp_path(".json");
  r = jelly("fit '" + file + "' --initial ks=1400 --initial kd=30 --write-scene '" + fitted + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const Scene s = load_scene(fitted);
  for (const SpringCoefficients& c : s.cube().springs) {
    EXPECT_NEAR(c.ks, 1000, 10);  // within 1 %
    EXPECT_NEAR(c.kd, 20, 0.2);
  }
  EXPECT_THAT(r.out, HasSubstr("ks = "));
  EXPECT_THAT(r.out, HasSubstr("(start 1400"));
  EXPECT_THAT(r.out, HasSubstr("covariance: ok"));

  // --no-covariance: the same estimates, without the covariance's replays.
  r = jelly("fit '" + file + "' --initial ks=1400 --initial kd=30 --no-covariance");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("covariance: failed: not requested"));
  EXPECT_THAT(r.out, HasSubstr("ks = "));
}

// A projective_dynamics recording (a pinned cloth, no terrain): the fit takes PD's own adjoint
// and its report names it.
TEST(Cli, FitNamesTheProjectiveDynamicsAdjoint) {
  const std::string file = temp_path(".h5");
  Result r = jelly("run '" + scene("hanging_cloth.json") +
                   "' --set integrator.name=projective_dynamics --duration 0.3 -o '" + file + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  r = jelly("fit '" + file + "' --no-covariance");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("derivatives: adjoint (exact gradients of projective_dynamics"));
}

// An implicit_euler recording: jelly fit takes the adjoint path by default, says so, and
// recovers the coefficients; --gradients numeric takes the other path and says why.
TEST(Cli, FitTakesTheAdjointPathForImplicitEuler) {
  const std::string file = temp_path(".h5");
  Result r = jelly("run " + kFitScene +
                   " --set integrator.name=implicit_euler --set integrator.dt=0.005 --duration 0.5"
                   " -o '" +
                   file + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string fitted = temp_path(".json");
  r = jelly("fit '" + file + "' --initial ks=1400 --initial kd=30 --no-covariance --write-scene '" +
            fitted + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("derivatives: adjoint (exact gradients of implicit_euler"));
  const Scene s = load_scene(fitted);
  for (const SpringCoefficients& c : s.cube().springs) {
    EXPECT_NEAR(c.ks, 1000, 10) << r.out;  // within 1 %
    EXPECT_NEAR(c.kd, 20, 0.2) << r.out;
  }
  r = jelly("fit '" + file +
            "' --initial ks=1400 --initial kd=30 --no-covariance --gradients "
            "numeric --max-iterations 1");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("derivatives: numeric (central differences of replays, "
                               "Levenberg-Marquardt): asked for (gradients = numeric)"));
}

TEST(Cli, FitErrorsExitTwo) {
  Result r = jelly("fit /nonexistent/run.h5");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: "));
  const std::string file = temp_path(".h5");
  ASSERT_EQ(jelly("run " + kFitScene + " --duration 0.5 -o '" + file + "'").code, 0);
  r = jelly("fit '" + file + "' --free ks,foo");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: free = ks,foo is invalid"));
  r = jelly("fit '" + file + "' --initial kq=3");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: --initial = kq=3 is invalid"));
  r = jelly("fit '" + file + "' --gradients exact");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: --gradients = exact is invalid: one of auto, adjoint, "
                                "numeric"));
  // The recording's integrator (kFitScene's) has no adjoint: --gradients adjoint says so.
  r = jelly("fit '" + file + "' --gradients adjoint --max-iterations 1");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: gradients = adjoint is invalid: a fit the adjoint "
                                "supports: the recording's integrator is"));
  const std::string short_file = temp_path(".h5");
  ASSERT_EQ(jelly("run " + kFitScene + " --duration 0.001 -o '" + short_file + "'").code, 0);
  r = jelly("fit '" + short_file + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: recording.frames = 1 is invalid: at least 3 frames"));
}

}  // namespace
}  // namespace jelly
