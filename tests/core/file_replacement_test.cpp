// FileReplacement: every output file is written beside its path and renamed once complete; an
// uncommitted temporary is removed; the file it replaces keeps its permission bits and is locked
// against a second replacement while the first is under way.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <jelly/core/detail/file_replacement.hpp>
#include <jelly/core/errors.hpp>

#include "support/temp_dir.hpp"

namespace jelly {
namespace {

using detail::FileReplacement;
using ::testing::HasSubstr;
using testing::TempDir;

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(FileReplacement, TemporaryNamesKeepTheExtensionWhenAsked) {
  const std::string tag = ".partial-" + std::to_string(static_cast<long>(getpid()));
  EXPECT_EQ(FileReplacement::temporary_name("a/out.h5", FileReplacement::Name::kAfterName),
            "a/out.h5" + tag);
  EXPECT_EQ(FileReplacement::temporary_name("a/out.mp4", FileReplacement::Name::kBeforeExtension),
            "a/out" + tag + ".mp4");
  EXPECT_EQ(FileReplacement::temporary_name("a.d/out", FileReplacement::Name::kBeforeExtension),
            "a.d/out" + tag);
  EXPECT_EQ(FileReplacement::temporary_name(".hidden", FileReplacement::Name::kBeforeExtension),
            ".hidden" + tag);
  EXPECT_EQ(
      FileReplacement::temporary_name("f/%04d.png", FileReplacement::Name::kBeforeExtension, 2),
      "f/%04d" + tag + "-2.png");
}

TEST(FileReplacement, CommitReplacesAndAnUncommittedTemporaryIsRemoved) {
  TempDir dir;
  const std::string path = dir.file("out.txt");
  std::ofstream(path) << "old";
  ASSERT_EQ(chmod(path.c_str(), 0640), 0);
  {
    FileReplacement r(path);
    r.write("abandoned");
    EXPECT_TRUE(std::filesystem::exists(r.temporary()));
  }
  EXPECT_EQ(contents(path), "old");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
  FileReplacement r(path);
  r.write("new");
  EXPECT_EQ(contents(path), "old");
  r.commit();
  EXPECT_TRUE(r.committed());
  EXPECT_EQ(contents(path), "new");
  struct stat info {};
  ASSERT_EQ(stat(path.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0640u);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 1);
}

TEST(FileReplacement, ATakenTemporaryNameIsNeverReused) {
  TempDir dir;
  const std::string path = dir.file("out.txt");
  const std::string taken =
      FileReplacement::temporary_name(path, FileReplacement::Name::kAfterName);
  std::ofstream(taken) << "someone else's";
  detail::replace_file(path, "new");
  EXPECT_EQ(contents(path), "new");
  EXPECT_EQ(contents(taken), "someone else's");
}

TEST(FileReplacement, ASecondReplacementWaitsForTheFirst) {
  TempDir dir;
  const std::string path = dir.file("out.txt");
  std::ofstream(path) << "old";
  auto first = std::make_unique<FileReplacement>(path);
  try {
    FileReplacement second(path);
    ADD_FAILURE() << "a second replacement of a file being replaced was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("'" + path + "' is being written by another run"));
  }
  first->write("first");
  first->commit();
  FileReplacement third(path);  // the first has finished
  third.write("third");
  third.commit();
  EXPECT_EQ(contents(path), "third");
}

TEST(FileReplacement, AMissingFolderIsBadInput) {
  TempDir dir;
  EXPECT_THROW(FileReplacement(dir.file("no/such/folder.txt")), InputError);
}

}  // namespace
}  // namespace jelly
