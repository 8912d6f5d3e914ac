// jelly-bench as users run it: bad arguments and bad CSV input exit 2 with "error: ...", and
// --quick only changes the defaults of options that were not given.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
namespace fs = std::filesystem;

struct Result {
  int code = -1;
  std::string out, err;
};

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class BenchCli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "jelly-bench-cli-XXXXXX").string();
    dir_ = mkdtemp(pattern.data());
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result bench(const std::string& args) {
    const fs::path out = dir_ / "stdout", err = dir_ / "stderr";
    const std::string command = std::string("'") + JELLY_BENCH + "' " + args + " >'" +
                                out.string() + "' 2>'" + err.string() + "' </dev/null";
    const int status = std::system(command.c_str());
    Result r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
  }

  fs::path dir_;
};

TEST_F(BenchCli, CommandLineErrorsExitTwoWithError) {
  // CLI11's own exit codes (105, 106, 109, ...) are not the project's.
  for (const std::string args : {"", "stability --bogus", "fly", "speed --steps abc", "merge"}) {
    const Result r = bench(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_THAT(r.err, StartsWith("error: ")) << args;
  }
  const Result help = bench("--help");
  EXPECT_EQ(help.code, 0);
  EXPECT_THAT(help.out, HasSubstr("stability"));
}

TEST_F(BenchCli, GarbageCsvExitsTwoWithError) {
  const fs::path garbage = dir_ / "garbage.csv";
  std::ofstream(garbage) << "not,a,jelly-bench\ntable\n";
  Result r = bench("merge '" + garbage.string() + "' --out '" + (dir_ / "out").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: " + garbage.string() + ":1: not a jelly-bench table"));

  const fs::path bad_number = dir_ / "bad_number.csv";
  std::ofstream(bad_number) << "# command: speed\n# table: speed\n# types: n\nsteps\nmany\n";
  r = bench("merge '" + bad_number.string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr(":5: 'many' is not a number"));

  r = bench("merge '" + (dir_ / "missing").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, StartsWith("error: merge: no file or directory "));
}

TEST_F(BenchCli, QuickKeepsOptionsGivenExplicitly) {
  const Result r = bench("speed --quick --sizes 3 --steps 7 --threads 1 --integrators rk4 --out '" +
                         (dir_ / "out").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = read_file(dir_ / "out" / "speed.csv");
  // The row of the one configuration: item 0, rk4, n = 3, 1 thread, ..., steps = 7 (not
  // --quick's 20).
  EXPECT_THAT(csv, HasSubstr("\n0,rk4,3,1,27,185,0.001,7,completed,"));
}

// --interleave runs the thread counts in alternation: the same rows, every one completed with
// its steps (blocks of 3 steps: 20 warm-up and 11 timed steps end on a short block), and the
// same trajectories as without it (the contact count is a function of the state). Its rows say
// that their peak memory is not per configuration. (At n = 5 both rows' loops run on one thread:
// this checks the alternation, docs/threads.md the bits.)
TEST_F(BenchCli, InterleavedThreadCountsGiveTheSameRows) {
  const std::string common = "speed --sizes 5 --steps 11 --threads 1,2 --integrators rk4 ";
  Result r = bench(common + "--out '" + (dir_ / "plain").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  r = bench(common + "--interleave --interleave-block 3 --out '" + (dir_ / "alt").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string plain = read_file(dir_ / "plain" / "speed.csv");
  const std::string alt = read_file(dir_ / "alt" / "speed.csv");
  for (const std::string row : {"\n0,rk4,5,1,125,", "\n1,rk4,5,2,125,"}) {
    const auto in_plain = plain.find(row), in_alt = alt.find(row);
    ASSERT_NE(in_plain, std::string::npos) << row;
    ASSERT_NE(in_alt, std::string::npos) << row;
    // particles, springs, dt, steps, status and contacts agree.
    const auto fields = [](const std::string& csv, std::size_t at) {
      std::string line = csv.substr(at + 1, csv.find('\n', at + 1) - at - 1);
      std::size_t pos = 0;
      for (int comma = 0; comma < 10; ++comma) pos = line.find(',', pos) + 1;
      return line.substr(0, pos);
    };
    EXPECT_EQ(fields(alt, in_alt), fields(plain, in_plain));
    EXPECT_THAT(fields(alt, in_alt), HasSubstr(",11,completed,"));
    const std::string alt_row = alt.substr(in_alt + 1, alt.find('\n', in_alt + 1) - in_alt - 1);
    EXPECT_EQ(alt_row.substr(alt_row.rfind(',')), ",0") << alt_row;  // memory_per_configuration
  }
  r = bench(common + "--interleave --interleave-block 0 --out '" + (dir_ / "bad").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.err, HasSubstr("--interleave-block = 0 is invalid"));
}

// --interleave with several sizes of the slope (which it alternates since 2026-11-29): every
// size's row completes with its steps and is marked as sharing its peak memory. (The order of
// the steps is not visible in the output; this checks that the runs of two sizes kept together
// each finish.)
TEST_F(BenchCli, InterleavedSizesRunTogether) {
  const Result r = bench(
      "speed --sizes 4,5 --steps 4 --warmup-steps 1 --threads 1 --integrators "
      "rk4 --interleave --interleave-block 1 --out '" +
      (dir_ / "sizes").string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = read_file(dir_ / "sizes" / "speed.csv");
  for (const std::string row : {"\n0,rk4,4,1,64,", "\n1,rk4,5,1,125,"}) {
    const auto at = csv.find(row);
    ASSERT_NE(at, std::string::npos) << row;
    const std::string line = csv.substr(at + 1, csv.find('\n', at + 1) - at - 1);
    EXPECT_THAT(line, HasSubstr(",4,completed,")) << line;
    EXPECT_EQ(line.substr(line.rfind(',')), ",0") << line;  // memory_per_configuration
  }
}

// The `cores` of a table's metadata are the ones the run could use (its CPU affinity: taskset,
// a Slurm task's allocation), which its default thread count follows; `hardware_cores` the
// machine's.
TEST_F(BenchCli, CoresAreTheProcessAffinity) {
  if (std::system("command -v taskset >/dev/null 2>&1") != 0) GTEST_SKIP() << "no taskset";
  const fs::path out = dir_ / "out";
  const std::string command = std::string("taskset -c 0 '") + JELLY_BENCH +
                              "' budget --quick --setups 'xpbd s1' --out '" + out.string() +
                              "' >/dev/null 2>&1 </dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  const std::string csv = read_file(out / "budget.csv");
  EXPECT_THAT(csv, HasSubstr("\n# cores: 1\n"));
  EXPECT_THAT(csv, HasSubstr("\n# hardware_cores: " +
                             std::to_string(std::thread::hardware_concurrency()) + "\n"));
}

// budget --cloth: the cloth of scenes/cloth_on_sphere.json is measured after the cubes, a row
// per setup marked scene "cloth" with its n x n particles and no ks ladder; the CSV records the
// load average at the start and the end. A bad size or scene folder is bad input.
TEST_F(BenchCli, BudgetMeasuresTheClothAfterTheCubes) {
  const fs::path out = dir_ / "cloth";
  const Result r =
      bench("budget --quick --cloth 6 --setups rk4,implicit_euler --out '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string csv = read_file(out / "budget.csv");
  EXPECT_THAT(csv, HasSubstr("\n# load_average_start: "));
  EXPECT_THAT(csv, HasSubstr("\n# load_average_end: "));
  EXPECT_THAT(csv, HasSubstr("\nitem,scene,n,particles,springs,setup,"));
  // Items 0 and 1: the n = 4 cube; 2 and 3: the 6 x 6 cloth (36 particles), both completed.
  EXPECT_THAT(csv, HasSubstr("\n0,cube,4,64,"));
  EXPECT_THAT(csv, HasSubstr("\n2,cloth,6,36,"));
  EXPECT_THAT(csv, HasSubstr("\n3,cloth,6,36,"));
  std::istringstream lines(csv);
  std::string line;
  int cloth_rows = 0;
  while (std::getline(lines, line)) {
    if (line.find(",cloth,") == std::string::npos) continue;
    ++cloth_rows;
    EXPECT_THAT(line, HasSubstr(",completed,")) << line;
    EXPECT_THAT(line, HasSubstr(",nan,")) << "no ks ladder for the cloth: " << line;
  }
  EXPECT_EQ(cloth_rows, 2);

  for (const std::string args :
       {"budget --quick --cloth 1", "budget --quick --cloth 6 --scenes-dir /nonexistent"}) {
    const Result bad = bench(args + " --out '" + (dir_ / "bad").string() + "'");
    EXPECT_EQ(bad.code, 2) << args << ": " << bad.err;
    EXPECT_THAT(bad.err, StartsWith("error: ")) << args;
  }
  EXPECT_THAT(bench("budget --quick --cloth 1").err, HasSubstr("--cloth"));
}

}  // namespace
