// Output files are replaced atomically through exclusive temporaries, and a killed run's
// temporaries are recognised by their dead PID and removed (io/atomic_write.hpp).
#include <sys/wait.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/atomic_write.hpp"
#include "io/input_error.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
namespace fs = std::filesystem;

// A PID that has just ended (a child reaped at once), so no process holds it for now.
long deadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return static_cast<long>(child);
}

TEST(AtomicWrite, ReplacesTheFileAndLeavesNoTemporary) {
  const TempDir dir("atomic_replace");
  const fs::path file = dir.path() / "out.txt";
  writeText(file, "old\n");
  io::writeTextAtomic(file, "new\n");
  EXPECT_EQ(readText(file), "new\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(AtomicWrite, AFailingWriterKeepsTheEarlierFile) {
  const TempDir dir("atomic_fail");
  const fs::path file = dir.path() / "out.txt";
  writeText(file, "earlier\n");
  EXPECT_THROW(io::writeFileAtomic(file,
                                   [](std::ostream& out) {
                                     out << "half";
                                     throw std::runtime_error("writer failed");
                                   }),
               std::runtime_error);
  EXPECT_EQ(readText(file), "earlier\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(AtomicWrite, TemporariesAreNewHiddenSiblingsNamedForTheirProcess) {
  const TempDir dir("atomic_names");
  const fs::path file = dir.path() / "map.ply";
  const fs::path a = io::createTemporarySibling(file, ".ply");
  const fs::path b = io::createTemporarySibling(file, ".ply");
  EXPECT_NE(a, b);
  EXPECT_EQ(a.parent_path(), dir.path());
  EXPECT_EQ(a.extension(), ".ply");
  EXPECT_THAT(a.filename().string(),
              ::testing::StartsWith(".map.ply.gvio-tmp-" + std::to_string(::getpid()) + "-"));
  EXPECT_TRUE(fs::is_regular_file(a));
  EXPECT_EQ(fs::file_size(a), 0u);
  EXPECT_TRUE(io::isTemporaryName(a));
  EXPECT_FALSE(io::isTemporaryName(file));
  EXPECT_FALSE(io::isTemporaryName(dir.path() / ".map.ply.gvio-tmp-x-1"));
  EXPECT_THROW(io::createTemporarySibling(dir.path() / "missing" / "f.txt"), io::InputError);
}

TEST(AtomicWrite, StaleTemporariesOfDeadProcessesAreRemovedOthersKept) {
  const TempDir dir("atomic_stale");
  const fs::path dead = dir.path() / (".map.pcd.gvio-tmp-" + std::to_string(deadPid()) + "-7");
  const fs::path alive =
      dir.path() / (".map.pcd.gvio-tmp-" + std::to_string(static_cast<long>(::getppid())) + "-7");
  const fs::path own = io::createTemporarySibling(dir.path() / "map.bt");
  const fs::path user = dir.path() / "notes.gvio-tmp-1-1";  // not hidden: not ours
  for (const auto& f : {dead, alive, user}) writeText(f, "x");
  const std::vector<fs::path> removed = io::removeStaleTemporaries(dir.path());
  ASSERT_EQ(removed.size(), 1u);
  EXPECT_EQ(removed.front(), dead);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(own));
  EXPECT_TRUE(fs::exists(user));
}

}  // namespace
}  // namespace gvio::test
