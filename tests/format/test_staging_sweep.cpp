// Stale staging files (issue 20): a SIGKILLed writer runs no destructor and leaves its
// TARGET.tmp-PID@HOST-XXXXXX files; the next writer of TARGET removes those whose process is
// gone, and never a live writer's.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <set>

#include "format/atomic_output.h"
#include "page_file_test_util.h"

namespace vt {
namespace {

using namespace vt::testing;
namespace fs = std::filesystem;

std::set<std::string> names_in(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

void set_age(const std::string& path, int64_t age_seconds) {
  const timespec t[2] = {{time(nullptr) - age_seconds, 0}, {time(nullptr) - age_seconds, 0}};
  ASSERT_EQ(::utimensat(AT_FDCWD, path.c_str(), t, 0), 0);
}

void touch(const std::string& path, int64_t age_seconds) {
  write_bytes(path, {'x'});
  set_age(path, age_seconds);
}

// A child that stages TARGET's file and its page writer's file inside it, reports the paths
// through `out`, then waits on `hold` (a live writer) until the parent closes or kills it.
pid_t start_writer(const std::string& target, int out, const int hold[2]) {
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  ::close(hold[1]);  // else the read below never sees the parent close its end
  auto outer = create_staging_file(target);
  auto inner = outer.ok() ? create_staging_file(outer->path) : outer;
  const char ok = inner.ok() ? 1 : 0;
  (void)!::write(out, &ok, 1);
  char c;
  (void)!::read(hold[0], &c, 1);
  ::_exit(0);  // no cleanup, as after a SIGKILL
}

TEST(StagingSweep, KilledWritersFilesGoLiveWritersStay) {
  const std::string target = temp_path("scene.vtpf");
  const std::string dir = fs::path(target).parent_path().string();
  int out[2], hold[2];
  ASSERT_EQ(::pipe(out), 0);
  ASSERT_EQ(::pipe(hold), 0);
  const pid_t child = start_writer(target, out[1], hold);
  ASSERT_GT(child, 0);
  char ok = 0;
  ASSERT_EQ(::read(out[0], &ok, 1), 1);
  ASSERT_EQ(ok, 1);
  const std::set<std::string> staged = names_in(dir);
  ASSERT_EQ(staged.size(), 2u);
  const std::string prefix = "scene.vtpf.tmp-" + std::to_string(child) + "@";
  for (const std::string& n : staged) EXPECT_EQ(n.rfind(prefix, 0), 0u) << n;

  // The writer is alive: its files stay, however often others sweep.
  EXPECT_EQ(sweep_stale_staging(target), 0);
  auto mine = create_staging_file(target);
  ASSERT_TRUE(mine.ok()) << mine.status().message();
  ::close(mine->fd);
  EXPECT_EQ(names_in(dir).size(), 3u);

  ::kill(child, SIGKILL);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);
  // Gone: both of its files are swept, this process's own staging file is not.
  EXPECT_EQ(sweep_stale_staging(target), 2);
  EXPECT_EQ(names_in(dir), std::set<std::string>{fs::path(mine->path).filename().string()});
  for (int fd : {out[0], out[1], hold[0], hold[1]}) ::close(fd);
}

TEST(StagingSweep, OutputSetSweepsWhatAKillLeft) {
  const std::string target = temp_path("pair.vtpf");
  const std::string dir = fs::path(target).parent_path().string();
  write_bytes(target, {'o', 'l', 'd'});
  int out[2], hold[2];
  ASSERT_EQ(::pipe(out), 0);
  ASSERT_EQ(::pipe(hold), 0);
  const pid_t child = start_writer(target, out[1], hold);
  char ok = 0;
  ASSERT_EQ(::read(out[0], &ok, 1), 1);
  ::close(hold[1]);  // the child returns from read and exits without removing anything
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);
  EXPECT_EQ(names_in(dir).size(), 3u);
  {
    OutputSet set;
    auto t = set.stage(target);
    ASSERT_TRUE(t.ok());
    write_bytes(*t, {'n', 'e', 'w'});
    ASSERT_TRUE(set.commit().ok());
  }
  EXPECT_EQ(names_in(dir), std::set<std::string>{"pair.vtpf"});
  EXPECT_EQ(read_bytes(target), std::vector<uint8_t>({'n', 'e', 'w'}));
  for (int fd : {out[0], out[1], hold[0]}) ::close(fd);
}

TEST(StagingSweep, UnknownOwnersOnlyByAgeOthersNever) {
  const std::string target = temp_path("t.vtpf");
  const std::string dir = fs::path(target).parent_path().string();
  const int64_t old = kStaleStagingSeconds + 60, fresh = 60;
  // No PID in the name (writers before it was) or another host's: by age only.
  touch(dir + "/t.vtpf.tmp-AbC123", old);
  touch(dir + "/t.vtpf.tmp-Zz9900", fresh);
  touch(dir + "/t.vtpf.tmp-42@other-host-QwErTy", old);
  touch(dir + "/t.vtpf.tmp-43@other-host-QwErTy", fresh);
  touch(dir + "/t.vtpf.old-AbC123.tmp-DeF456", old);
  // This PID with a file written before the process started: the PID was reused.
  char host[256] = {};
  ASSERT_EQ(::gethostname(host, sizeof host - 1), 0);
  std::string tag(host);
  tag = tag.substr(0, std::min(tag.find('.'), size_t(32)));
  touch(dir + "/t.vtpf.tmp-" + std::to_string(::getpid()) + "@" + tag + "-ReUsed", 3600);
  touch(dir + "/t.vtpf.tmp-" + std::to_string(::getpid()) + "@" + tag + "-MyOwn1", 0);
  // Not the pattern, or not this target's: never, whatever the age.
  for (const char* n :
       {"t.vtpf.tmp-AbC12", "t.vtpf.tmp-AbC1234", "t.vtpf.tmpAbC123", "t.vtpf.tmp-AbC123.bak",
        "t.vtpf.tmp-0@x-AbC123", "u.vtpf.tmp-AbC123", "t.vtpf.tmp-12@ho.st-AbC123", "t.vtpf"})
    touch(dir + "/" + n, old);
  ASSERT_EQ(::mkdir((dir + "/t.vtpf.tmp-DiR000").c_str(), 0700), 0);
  set_age(dir + "/t.vtpf.tmp-DiR000", old);

  EXPECT_EQ(sweep_stale_staging(target), 4);
  const std::set<std::string> kept = names_in(dir);
  for (const char* gone :
       {"t.vtpf.tmp-AbC123", "t.vtpf.tmp-42@other-host-QwErTy", "t.vtpf.old-AbC123.tmp-DeF456"})
    EXPECT_EQ(kept.count(gone), 0u) << gone;
  EXPECT_EQ(kept.count("t.vtpf.tmp-" + std::to_string(::getpid()) + "@" + tag + "-ReUsed"), 0u);
  EXPECT_EQ(kept.size(), 12u);
  EXPECT_EQ(kept.count("t.vtpf.tmp-" + std::to_string(::getpid()) + "@" + tag + "-MyOwn1"), 1u);
  EXPECT_EQ(kept.count("t.vtpf.tmp-DiR000"), 1u);
}

TEST(StagingSweep, CleanSweepsEveryTargetInTheFolder) {
  const std::string dir = fs::path(temp_path("x")).parent_path().string();
  const int64_t old = kStaleStagingSeconds + 60;
  touch(dir + "/a.vtpf.tmp-AbC123", old);
  touch(dir + "/b.png.tmp-42@other-host-QwErTy", old);
  touch(dir + "/c.tmp-abcdef.glb.tmp-XyZ789", old);  // a target whose name holds ".tmp-"
  touch(dir + "/d.vtpf.tmp-Zz9900", 60);             // fresh: maybe a live writer elsewhere
  touch(dir + "/e.vtpf", old);
  auto removed = sweep_stale_staging_in(dir);
  ASSERT_TRUE(removed.ok()) << removed.status().message();
  std::set<std::string> gone;
  for (const std::string& p : *removed) gone.insert(fs::path(p).filename().string());
  EXPECT_EQ(gone, (std::set<std::string>{"a.vtpf.tmp-AbC123", "b.png.tmp-42@other-host-QwErTy",
                                         "c.tmp-abcdef.glb.tmp-XyZ789"}));
  EXPECT_EQ(names_in(dir), (std::set<std::string>{"d.vtpf.tmp-Zz9900", "e.vtpf"}));
  EXPECT_EQ(sweep_stale_staging_in(dir + "/missing").status().code(), ErrorCode::kNotFound);
}

TEST(AtomicWriter, AFailedWriteKeepsThePreviousFileAndLeavesNothing) {
  const std::string target = temp_path("out.png");
  const std::string dir = fs::path(target).parent_path().string();
  write_bytes(target, {'o', 'l', 'd'});
  // The writer fails half-way (a full disk): the old file stays whole, no temporary stays.
  Status s = write_output(target, [](const std::string& temp) -> Status {
    write_bytes(temp, {'h', 'a'});
    return Error(ErrorCode::kIo, "disk full");
  });
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  EXPECT_EQ(read_bytes(target), std::vector<uint8_t>({'o', 'l', 'd'}));
  EXPECT_EQ(names_in(dir), std::set<std::string>{"out.png"});
  ASSERT_TRUE(write_output_bytes(target, "new bytes").ok());
  EXPECT_EQ(read_bytes(target).size(), 9u);
  EXPECT_EQ(names_in(dir), std::set<std::string>{"out.png"});
  // A folder that does not exist: an i/o error naming the path, nothing created.
  s = write_output_bytes(dir + "/no/such/folder/x.json", "{}");
  EXPECT_EQ(s.code(), ErrorCode::kIo);
  EXPECT_NE(s.message().find("no/such/folder/x.json"), std::string::npos) << s.message();
  // A directory at the path is never replaced.
  EXPECT_EQ(write_output_bytes(dir, "{}").code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace vt
