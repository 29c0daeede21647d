// gvio fleet's drive list (app/fleet/drive_list.hpp) and its child processes
// (app/fleet/child_process.hpp): parsing, relative paths, names, and the errors a list can hold.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fleet/child_process.hpp"
#include "fleet/drive_list.hpp"
#include "fleet/engines.hpp"
#include "odometry/error.hpp"
#include "support/fixtures.hpp"

namespace gvio::test {
namespace {
using testing::ElementsAre;
using testing::HasSubstr;
namespace fs = std::filesystem;

std::string errorOf(const std::string& text) {
  try {
    fleet::parseDriveList(text, "/lists/drives.txt");
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

TEST(DriveList, SplitsWordsWithQuotesAndComments) {
  EXPECT_THAT(fleet::splitWords("a  'b c'\t\"d'e\" # f g"), ElementsAre("a", "b c", "d'e"));
  EXPECT_THAT(fleet::splitWords("x#y z"), ElementsAre("x#y", "z"));
  EXPECT_THAT(fleet::splitWords("''"), ElementsAre(""));
  EXPECT_TRUE(fleet::splitWords("   # only a comment").empty());
  EXPECT_THROW(fleet::splitWords("a 'b"), InvalidInput);
}

TEST(DriveList, ResolvesPathsAgainstTheListsFolderAndNamesRuns) {
  const auto drives = fleet::parseDriveList(
      "# fleet\n"
      "\n"
      "kitti/drive_0027/\n"
      "/data/morning.bag --calib camchain.yaml /abs/imu.yaml --gnss-noise spp --seed 3\n"
      "'with space/x' --name evening --set vio.mode=stereo --gnss off\n",
      "/lists/drives.txt");
  ASSERT_EQ(drives.size(), 3U);
  EXPECT_EQ(drives[0].line, 3U);
  EXPECT_EQ(drives[0].dataset, fs::path("/lists/kitti/drive_0027/"));
  EXPECT_EQ(drives[0].name, "drive_0027");
  EXPECT_TRUE(drives[0].run_args.empty());
  EXPECT_EQ(drives[1].name, "morning");  // .bag dropped
  EXPECT_THAT(drives[1].run_args, ElementsAre("--calib", "/lists/camchain.yaml", "/abs/imu.yaml",
                                              "--gnss-noise", "spp", "--seed", "3"));
  EXPECT_EQ(drives[2].name, "evening");
  EXPECT_EQ(drives[2].dataset, fs::path("/lists/with space/x"));
  EXPECT_THAT(drives[2].run_args, ElementsAre("--set", "vio.mode=stereo", "--gnss", "off"));
}

TEST(DriveList, RejectsWhatTheFleetSetsAndAmbiguousNamesWithTheLine) {
  EXPECT_THAT(errorOf("a\nb --out x\n"), HasSubstr("drives.txt:2: --out is set by the fleet"));
  EXPECT_THAT(errorOf("a --dataset=b\n"), HasSubstr("drives.txt:1: --dataset is set"));
  EXPECT_THAT(errorOf("x/a\ny/a\n"), HasSubstr("drives.txt:2: a drive named 'a' is already"));
  EXPECT_THAT(errorOf("a --name\n"), HasSubstr("drives.txt:1: --name needs a value"));
  EXPECT_THAT(errorOf("a --name x/y\n"), HasSubstr("drives.txt:1: cannot name a run folder"));
  EXPECT_THAT(errorOf("--gnss off\n"), HasSubstr("drives.txt:1: expected a dataset first"));
  EXPECT_THAT(errorOf("a 'b\n"), HasSubstr("drives.txt:1: unterminated quote"));
  EXPECT_THAT(errorOf("# nothing\n\n"), HasSubstr("drives.txt: no drive in the list"));
  // The root has no name (and its parent is itself: a fuzzer found a hang there).
  EXPECT_THAT(errorOf("/\n"), HasSubstr("drives.txt:1: cannot name a run folder ''"));
  EXPECT_EQ(errorOf("x/a\ny/a --name b\n"), "");
}

TEST(DriveList, AMissingListIsOneLine) {
  try {
    fleet::readDriveList("/nonexistent/drives.txt");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/drives.txt: drive list not found"));
  }
}

TEST(ChildProcess, ReportsExitCodesSignalsAndTheLastErrorLine) {
  const TempDir dir("child_process");
  const fs::path log = dir.path() / "log.txt";
  const pid_t a = fleet::spawnLogged(
      {"/bin/sh", "-c",
       "echo '[info] working'; echo '[error] x.txt:3: bad' >&2; echo done; exit 3"},
      log);
  const auto ea = fleet::waitChild(a);
  ASSERT_TRUE(ea);
  EXPECT_EQ(ea->pid, a);
  EXPECT_EQ(ea->exit_code, 3);
  EXPECT_EQ(ea->signal, 0);
  EXPECT_GT(ea->peak_rss_mb, 0.0);
  EXPECT_EQ(fleet::lastErrorLine(log), "x.txt:3: bad");

  const pid_t b = fleet::spawnLogged({"/bin/sh", "-c", "kill -9 $$"}, dir.path() / "b.txt");
  const auto eb = fleet::waitChild(b);
  ASSERT_TRUE(eb);
  EXPECT_EQ(eb->signal, 9);
  EXPECT_EQ(eb->exit_code, 137);

  writeText(dir.path() / "c.txt", "== gvio fleet: drive x, attempt 1\nlast words\n\n");
  EXPECT_EQ(fleet::lastErrorLine(dir.path() / "c.txt"), "last words");
  EXPECT_EQ(fleet::lastErrorLine(dir.path() / "missing.txt"), "");
  EXPECT_THROW(fleet::spawnLogged({"/nonexistent/program"}, log), InvalidInput);
}

TEST(SlurmEngine, SubmitsOneThrottledArrayWithTheConfiguredResources) {
  fleet::FleetPlan plan;
  plan.out_dir = "/fleet/out";
  fleet::EngineRequest request;
  request.plan = &plan;
  request.drives = {0, 2, 5};
  request.jobs = 2;
  fleet::SlurmConfig slurm;
  slurm.partition = "batch";
  slurm.mem_mb = 3000;
  slurm.time_limit_min = 45;
  slurm.cpus_per_task = 4;
  const auto argv = fleet::sbatchArgv(request, slurm, "/fleet/out/slurm/attempt1.sh");
  EXPECT_THAT(argv,
              ElementsAre("sbatch", "--parsable", "--wait", "--array=0,2,5%2",
                          "--job-name=gvio-fleet", "--cpus-per-task=4", "--mem=3000M", "--time=45",
                          "--chdir=/fleet/out", "--output=/fleet/out/slurm/attempt1_task%a.out",
                          "--partition=batch", "/fleet/out/slurm/attempt1.sh"));
}

}  // namespace
}  // namespace gvio::test
