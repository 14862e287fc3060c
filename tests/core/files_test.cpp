#include "tega/core/files.h"

#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

size_t entries_in(const fs::path& dir) {
  return static_cast<size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

TEST(Files, AtomicWriteReplacesContentAndLeavesNoTemporary) {
  tega::test::TempDir tmp;
  const auto file = tmp / "a/b/out.txt";
  tega::write_text_atomic(file, "first");
  tega::write_text_atomic(file, "second");
  EXPECT_EQ(tega::read_text_file(file), "second");
  EXPECT_EQ(entries_in(file.parent_path()), 1u);
}

TEST(Files, FailedWriteKeepsTheOldFile) {
  tega::test::TempDir tmp;
  const auto file = tmp / "out.txt";
  tega::write_text_atomic(file, "good");
  EXPECT_THROW(tega::write_file_atomic(file,
                                       [](const fs::path& temp) {
                                         tega::test::write_text(temp, "partial");
                                         throw std::runtime_error("crash mid-write");
                                       }),
               std::runtime_error);
  EXPECT_EQ(tega::read_text_file(file), "good");
  EXPECT_EQ(entries_in(tmp.path()), 1u);
}

TEST(Files, StagedDirectoryAppearsOnlyOnCommit) {
  tega::test::TempDir tmp;
  const auto out = tmp / "capture";
  {
    tega::StagedDirectory staged(out, false);
    tega::write_text_atomic(staged.path() / "x.txt", "x");
    EXPECT_FALSE(fs::exists(out));
    staged.commit();
  }
  EXPECT_EQ(tega::read_text_file(out / "x.txt"), "x");
  {
    tega::StagedDirectory abandoned(tmp / "other", false);
    tega::write_text_atomic(abandoned.path() / "y.txt", "y");
  }
  EXPECT_FALSE(fs::exists(tmp / "other"));
  EXPECT_EQ(entries_in(tmp.path()), 1u);  // no staging leftovers
}

TEST(Files, StagedDirectoryRefusesOrReplacesExisting) {
  tega::test::TempDir tmp;
  const auto out = tmp / "capture";
  fs::create_directories(out);
  tega::test::write_text(out / "old.txt", "old");
  try {
    tega::StagedDirectory refused(out, false);
    FAIL() << "expected an error";
  } catch (const tega::Error& e) {
    EXPECT_NE(std::string(e.what()).find("already exists"), std::string::npos);
  }
  tega::StagedDirectory replacing(out, true);
  tega::write_text_atomic(replacing.path() / "new.txt", "new");
  EXPECT_TRUE(fs::exists(out / "old.txt"));  // untouched until commit
  replacing.commit();
  EXPECT_FALSE(fs::exists(out / "old.txt"));
  EXPECT_TRUE(fs::exists(out / "new.txt"));
  EXPECT_EQ(entries_in(tmp.path()), 1u);
}

TEST(Files, ResumableStagedDirectoryKeepsWhatARunWithTheSameKeyWrote) {
  tega::test::TempDir tmp;
  const auto out = tmp / "dataset";
  {
    tega::StagedDirectory interrupted(out, false, "key 1");
    EXPECT_EQ(interrupted.path(), tmp / "dataset.partial");
    tega::write_text_atomic(interrupted.path() / "images/a.png", "a");
    tega::test::write_text(interrupted.path() / "images/b.png.tmp-1-2-3", "half written");
  }  // not committed: kept for the next run
  {
    tega::StagedDirectory resumed(out, false, "key 1");
    EXPECT_EQ(tega::read_text_file(resumed.path() / "images/a.png"), "a");
    EXPECT_FALSE(fs::exists(resumed.path() / "images/b.png.tmp-1-2-3"));
  }
  {
    tega::StagedDirectory changed(out, false, "key 2");
    EXPECT_FALSE(fs::exists(changed.path() / "images/a.png"));
    tega::write_text_atomic(changed.path() / "c.png", "c");
    changed.commit();
  }
  EXPECT_EQ(tega::read_text_file(out / "c.png"), "c");
  EXPECT_EQ(entries_in(out), 1u);  // no resume key in the output
  EXPECT_EQ(entries_in(tmp.path()), 1u);
  EXPECT_THROW(tega::StagedDirectory(out, false, "key 2"), tega::Error);
}

TEST(Files, RemoveTreeRemovesNestedDirectoriesAndToleratesMissingPaths) {
  tega::test::TempDir tmp;
  tega::write_text_atomic(tmp / "tree/a/b/c.txt", "c");
  tega::write_text_atomic(tmp / "tree/d.txt", "d");
  std::filesystem::create_symlink(tmp.path(), tmp / "tree/link-to-parent");  // must not be followed
  tega::remove_tree(tmp / "tree");
  EXPECT_FALSE(fs::exists(tmp / "tree"));
  EXPECT_TRUE(fs::exists(tmp.path()));
  EXPECT_NO_THROW(tega::remove_tree(tmp / "never-existed"));
}

TEST(Files, ReadingAMissingFileNamesIt) {
  try {
    tega::read_text_file("/no/such/file.json");
    FAIL();
  } catch (const tega::Error& e) {
    EXPECT_STREQ(e.what(), "/no/such/file.json: does not exist");
  }
}

}  // namespace
