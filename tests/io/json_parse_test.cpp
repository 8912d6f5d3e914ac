// JSON read from users (scene files, --set values, the scene stored in a recording): nesting is
// bounded, a key repeated in one object, a number beyond a double and a file that is not a
// regular file are InputErrors naming the place; none crashes or hangs.
#include <jelly/io/detail/json_parse.hpp>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

const std::string kMinimal = R"({"integrator": {"name": "rk4"}, "duration": 1})";

// The InputError message of parsing `text` with `overrides`, or "" when it parses.
std::string error_naming_file(const std::string& text,
                              const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(text, overrides, "scene.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string nested(int depth) { return std::string(depth, '[') + std::string(depth, ']'); }

TEST(JsonParse, DeepNestingIsRefusedNotAStackOverflow) {
  // 100,000 levels overflowed the stack when printed or copied.
  const std::string deep =
      R"({"description": )" + nested(100000) + R"(, "integrator": {"name": "rk4"}, "duration": 1})";
  EXPECT_THAT(error_naming_file(deep),
              StartsWith("scene.json is not valid JSON: it nests arrays and objects deeper than "
                         "64 levels at description[0][0]"));
  // The limit itself: 64 levels parse (and fail validation as a wrong type), 65 do not.
  EXPECT_THAT(error_naming_file(R"({"description": )" + nested(63) + "}"),
              StartsWith("description = [[[["));
  EXPECT_THAT(error_naming_file(R"({"description": )" + nested(64) + "}"),
              HasSubstr("deeper than 64"));
}

TEST(JsonParse, DeepSetValuesAndAppliedOverridesAreRefused) {
  // Messages quote a long assignment cut short.
  EXPECT_EQ(error_naming_file(kMinimal, {"description=" + nested(100000)}),
            "--set 'description=" + std::string(65, '[') +
                "...' is not valid JSON: it nests arrays and objects deeper than 32 levels at "
                "[0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0][0]... (a scene needs 4)");
  EXPECT_THROW(apply_override(nested(100000), "a=1"), InputError);
  // A value (32 levels) and a path (32 steps) of half the limit each: the edited scene, written
  // out by apply_override, reads back.
  const std::string edited = apply_override(kMinimal, "description.a.b=" + nested(32));
  EXPECT_NO_THROW(detail::parse_json(edited, "edited"));
  // A path of 60,000 keys created objects 60,000 deep (a crash when printed).
  std::string long_path;
  for (int i = 0; i < 60000; ++i) long_path += "a.";
  EXPECT_THAT(error_naming_file(kMinimal, {long_path + "a=1"}),
              HasSubstr("' has more than 32 steps"));
  // Unbalanced brackets are refused as soon as they are too deep, before the end of the text.
  EXPECT_THAT(error_naming_file(kMinimal, {"description=" + std::string(100000, '[')}),
              HasSubstr("deeper than 32 levels"));
  // Text that is not JSON is a string value, which validation then checks.
  EXPECT_EQ(error_naming_file(kMinimal, {"description=[[[", "duration=[["}),
            "duration = \"[[\" is invalid: a number");
}

TEST(JsonParse, RepeatedKeysNameTheObject) {
  EXPECT_EQ(error_naming_file(R"({"integrator": {"name": "rk4"}, "duration": 1, "duration": 2})"),
            "scene.json is not valid JSON: the key \"duration\" appears twice in the top-level "
            "object (only one value could count: remove the other)");
  EXPECT_THAT(error_naming_file(R"({"terrains": [{"kind": "plane"}, {"kind": "plane", "contact":
                            {"friction": 1, "friction": 0}}],
                          "integrator": {"name": "rk4"}, "duration": 1})"),
              HasSubstr("the key \"friction\" appears twice in terrains[1].contact "));
  // The same key in two different objects is fine.
  EXPECT_EQ(error_naming_file(R"({"springs": {"shear": {"ks": 1}, "bending": {"ks": 1}},
                         "integrator": {"name": "rk4"}, "duration": 1})"),
            "");
  EXPECT_THAT(error_naming_file(kMinimal, {R"(springs={"shear": {"ks": 1, "ks": 2}})"}),
              HasSubstr("the key \"ks\" appears twice in shear"));
}

TEST(JsonParse, NumbersBeyondADoubleAreInputErrors) {
  EXPECT_EQ(error_naming_file(R"({"integrator": {"name": "rk4"}, "duration": 1e999})"),
            "scene.json is not valid JSON: number overflow parsing '1e999' at duration (numbers "
            "must be within a double's range, about +-1.8e308)");
  EXPECT_THAT(error_naming_file(kMinimal, {"springs.shear.ks=-1e400"}),
              StartsWith("--set 'springs.shear.ks=-1e400' is not valid JSON: number overflow"));
  // An integer too long for 64 bits is read as a double, and a tiny number underflows to 0.
  EXPECT_THAT(error_naming_file(kMinimal, {"cube.n=100000000000000000000000"}),
              StartsWith("cube.n = "));
  EXPECT_EQ(error_naming_file(kMinimal, {"springs.shear.kd=1e-400"}), "");
}

TEST(JsonParse, SetValuesThatAreNotUtf8AreRefused) {
  EXPECT_EQ(error_naming_file(kMinimal, {"description=\xff\xfe"}),
            "--set 'description=\xff\xfe': the value is not valid UTF-8 text");
  // A path with such bytes became an object key, and the unknown-key message dumped it: an
  // uncaught JSON exception (jelly_set_fuzzer under make test-sanitize).
  EXPECT_EQ(error_naming_file(kMinimal, {"cube.\xff\xff.origin=[1,2,3]"}),
            "--set 'cube.\xff\xff.origin=[1,2,3]': the path is not valid UTF-8 text");
}

// Messages show JSON that is not valid UTF-8 (from a damaged file) with U+FFFD, not an exception.
TEST(JsonParse, MessagesShowInvalidUtf8AsReplacementCharacters) {
  Json object = Json::object();
  object["\xff"] = 1;
  EXPECT_EQ(json_text(object), "{\"\xEF\xBF\xBD\":1}");
}

// The message of loading the scene file at `path`, or "" when it loads.
std::string load_error(const std::string& path) {
  try {
    load_scene(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(JsonParse, OnlyRegularFilesOfSaneSizeAreRead) {
  // A device would be read forever, a pipe would block: refused before opening.
  EXPECT_EQ(load_error("/dev/zero"),
            "cannot read the scene file '/dev/zero': it is a character device, not a file");
  const std::string dir = ::testing::TempDir() + "jelly_json_XXXXXX";
  std::string made = dir;
  ASSERT_NE(mkdtemp(made.data()), nullptr);
  EXPECT_EQ(load_error(made), "cannot read the scene file '" + made + "': it is a directory");
  const std::string fifo = made + "/fifo.json";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(load_error(fifo),
            "cannot read the scene file '" + fifo + "': it is a pipe, not a file");
  const std::string huge = made + "/huge.json";
  { std::ofstream(huge) << kMinimal; }
  ASSERT_EQ(truncate(huge.c_str(), detail::kMaxJsonFileBytes + 1), 0);  // sparse
  EXPECT_THAT(load_error(huge), HasSubstr("bytes, more than a JSON file can"));
  EXPECT_THAT(load_error(made + "/missing.json"), HasSubstr("No such file or directory"));
  std::remove(fifo.c_str());
  std::remove(huge.c_str());
  rmdir(made.c_str());
}

}  // namespace
}  // namespace jelly
