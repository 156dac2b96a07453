// OutputTarget and signal cleanup: what an output may replace, and that nothing else is ever
// touched. Every case runs in a sandbox folder of its own; the root, home and current folders
// are stand-ins inside it.
#include "evfs/io/output_target.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "evfs/core/error.h"
#include "evfs/runtime/signal_cleanup.h"
#include "evfs/tests/io/io_test_util.h"
#include "evfs/tests/test_data.h"

namespace evfs {
namespace {

namespace fs = std::filesystem;

// A sandbox with stand-ins for the folders evfs must never replace.
struct Sandbox {
  explicit Sandbox(const std::string& name) : root(test::ScratchDir("output_" + name)) {
    for (const char* folder : {"root", "home", "cwd", "data"})
      fs::create_directories(root / folder);
    test::WriteFile((root / "data/events.txt").string(), "0.1 1 1 1\n");
  }

  OutputOptions Options(const fs::path& out, const char* command = "reconstruct") const {
    OutputOptions options;
    options.path = out.string();
    options.command = command;
    options.inputs = {(root / "data").string()};
    options.protected_folders = {{(root / "root").string(), "the file-system root"},
                                 {(root / "home").string(), "the home folder"},
                                 {(root / "cwd").string(), "the current folder"}};
    return options;
  }

  // Names in `folder` other than `keep`: leftovers of staging or aside folders.
  std::vector<std::string> Others(const fs::path& folder, const std::string& keep) const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(folder)) {
      if (entry.path().filename() != keep) names.push_back(entry.path().filename().string());
    }
    return names;
  }

  fs::path root;
};

void WriteIn(const std::string& folder, const std::string& name, const std::string& text) {
  fs::create_directories(folder);
  test::WriteFile((fs::path(folder) / name).string(), text);
}

// Runs `write` on a new output at `out` and commits it.
void MakeOutput(const OutputOptions& options, const std::string& file) {
  OutputTarget target(options);
  WriteIn(target.staging(), file, file);
  target.Commit();
}

TEST(OutputTargetTest, NewFolderAppearsWholeWithItsMarker) {
  const Sandbox sandbox("new");
  const fs::path out = sandbox.root / "made/on/demand/out";
  {
    OutputTarget target(sandbox.Options(out.string() + "/"));  // a trailing slash is the same
    EXPECT_EQ(target.path(), out.string());
    EXPECT_TRUE(fs::is_directory(target.staging()));
    EXPECT_EQ(fs::path(target.staging()).parent_path(), out.parent_path());
    EXPECT_FALSE(fs::exists(out)) << "visible before it is complete";
    WriteIn(target.staging(), "result.txt", "new");
    target.Commit();
  }
  EXPECT_EQ(test::ReadFile((out / "result.txt").string()), "new");
  EXPECT_EQ(test::ReadFile((out / kOutputMarkerFile).string()),
            "evfs reconstruct\nfile result.txt\n");
  EXPECT_TRUE(sandbox.Others(out.parent_path(), "out").empty());
}

TEST(OutputTargetTest, OverwriteRefusesWhatTheMarkerDoesNotList) {
  const Sandbox sandbox("foreign");
  const fs::path out = sandbox.root / "out";
  {
    OutputTarget target(sandbox.Options(out));
    WriteIn(target.staging() + "/frames", "000000.png", "frame");
    target.Commit();
  }
  EXPECT_EQ(test::ReadFile((out / kOutputMarkerFile).string()),
            "evfs reconstruct\nfile frames/000000.png\nfolder frames\n");
  OutputOptions overwrite = sandbox.Options(out);
  overwrite.overwrite = true;
  WriteIn((out / "frames").string(), "mine.png", "mine");
  WriteIn((out / "my").string(), "y", "mine");
  try {
    OutputTarget target(overwrite);
    ADD_FAILURE() << "replaced an output holding the user's files";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("did not write: frames/mine.png, my/"),
              std::string::npos)
        << error.what();
  }
  EXPECT_EQ(test::ReadFile((out / "my/y").string()), "mine");
  // A file where evfs wrote a folder is foreign too.
  fs::remove_all(out / "my");
  fs::remove(out / "frames/mine.png");
  fs::rename(out / "frames", sandbox.root / "frames");
  test::WriteFile((out / "frames").string(), "a file now");
  EXPECT_THROW(OutputTarget target(overwrite), InvalidArgumentError);
  fs::remove(out / "frames");
  MakeOutput(overwrite, "new.txt");
  EXPECT_EQ(test::ReadFile((out / "new.txt").string()), "new.txt");
  EXPECT_TRUE(sandbox.Others(sandbox.root, "out").size() == 5u) << "a staging folder was left";
}

TEST(OutputTargetTest, AMarkerThatIsALinkOrNotAFileIsNamed) {
  const Sandbox sandbox("marker_link");
  const fs::path out = sandbox.root / "out";
  fs::create_directories(out);
  test::WriteFile((sandbox.root / "marker").string(), "evfs reconstruct\n");
  fs::create_symlink(sandbox.root / "marker", out / kOutputMarkerFile);
  OutputOptions overwrite = sandbox.Options(out);
  overwrite.overwrite = true;
  try {
    OutputTarget target(overwrite);
    ADD_FAILURE() << "a linked marker was taken as evfs's";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("is a symbolic link"), std::string::npos)
        << error.what();
  }
}

// A process id that no process has now: a child that has exited and been reaped.
pid_t DeadProcessId() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  int status = 0;
  waitpid(child, &status, 0);
  return child;
}

TEST(OutputTargetTest, LeftoversOfADeadRunAreRemovedOnlyWhenTheyAreEvfss) {
  const Sandbox sandbox("leftovers");
  const fs::path out = sandbox.root / "out";
  MakeOutput(sandbox.Options(out), "old.txt");
  const std::string dead = std::to_string(DeadProcessId());
  const std::string alive = std::to_string(getppid());
  // Removed: an empty staging folder, a staging folder marked unfinished, and an earlier output
  // moved aside that holds only what its marker lists.
  fs::create_directories(sandbox.root / (".out.evfs-tmp-" + dead + "-0"));
  WriteIn((sandbox.root / (".out.evfs-tmp-" + dead + "-1")).string(), kOutputMarkerFile,
          "evfs reconstruct\nunfinished\n");
  WriteIn((sandbox.root / (".out.evfs-tmp-" + dead + "-1/frames")).string(), "0.png", "x");
  fs::copy(out, sandbox.root / (".out.evfs-old-" + dead + "-0"), fs::copy_options::recursive);
  // Kept: one of a running process, one without a marker, one holding a file of the user's, and
  // names that only look alike.
  const std::vector<std::string> kept = {
      ".out.evfs-tmp-" + alive + "-0", ".out.evfs-tmp-" + dead + "-2",
      ".out.evfs-old-" + dead + "-1", ".out.evfs-tmp-" + dead + "-x", ".out.evfs-video-work"};
  for (const std::string& name : kept) fs::create_directories(sandbox.root / name);
  WriteIn((sandbox.root / kept[0]).string(), "partial.png", "x");
  WriteIn((sandbox.root / kept[1]).string(), "notes.txt", "mine");
  fs::copy(out, sandbox.root / kept[2], fs::copy_options::recursive);
  WriteIn((sandbox.root / kept[2]).string(), "notes.txt", "mine");

  OutputOptions overwrite = sandbox.Options(out);
  overwrite.overwrite = true;
  std::vector<std::string> notes;
  overwrite.warn = [&notes](const std::string& note) { notes.push_back(note); };
  MakeOutput(overwrite, "new.txt");
  EXPECT_EQ(notes.size(), 3u);
  for (const std::string& note : notes) {
    EXPECT_EQ(note.rfind("removed " + sandbox.root.string() + "/.out.evfs-", 0), 0u) << note;
  }
  for (const std::string& name : kept) EXPECT_TRUE(fs::exists(sandbox.root / name)) << name;
  EXPECT_EQ(sandbox.Others(sandbox.root, "out").size(), 4u + kept.size());
  EXPECT_EQ(test::ReadFile((out / "new.txt").string()), "new.txt");
}

// Read-only folders inside an earlier output (a user protecting frames/) do not leave it
// behind once it is replaced.
TEST(OutputTargetTest, AReplacedOutputWithReadOnlyFoldersIsRemoved) {
  if (geteuid() == 0) GTEST_SKIP() << "running as root: file permissions do not stop removal";
  const Sandbox sandbox("read_only");
  const fs::path out = sandbox.root / "out";
  {
    OutputTarget target(sandbox.Options(out));
    WriteIn(target.staging() + "/frames", "000000.png", "frame");
    target.Commit();
  }
  fs::permissions(out / "frames", fs::perms::owner_read | fs::perms::owner_exec);
  OutputOptions overwrite = sandbox.Options(out);
  overwrite.overwrite = true;
  std::vector<std::string> notes;
  overwrite.warn = [&notes](const std::string& note) { notes.push_back(note); };
  MakeOutput(overwrite, "new.txt");
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(sandbox.Others(sandbox.root, "out").size(), 4u) << "the earlier output was left";
}

TEST(OutputTargetTest, FailureRemovesStagingAndTheParentsItMade) {
  const Sandbox sandbox("failure");
  {
    OutputTarget target(sandbox.Options(sandbox.root / "new/deeper/out"));
    WriteIn(target.staging(), "partial.txt", "partial");
  }  // no Commit: the job threw
  EXPECT_FALSE(fs::exists(sandbox.root / "new"));
}

TEST(OutputTargetTest, RefusesAFolderHoldingFilesEvfsDidNotWrite) {
  const Sandbox sandbox("foreign");
  const fs::path out = sandbox.root / "thesis";
  WriteIn(out.string(), "chapter1.tex", "precious");
  OutputOptions options = sandbox.Options(out);
  options.overwrite = true;  // not even then
  EXPECT_THROW(OutputTarget target(options), InvalidArgumentError);
  EXPECT_EQ(test::ReadFile((out / "chapter1.tex").string()), "precious");
  EXPECT_TRUE(sandbox.Others(sandbox.root, "thesis").size() == 4u) << "left something behind";
}

TEST(OutputTargetTest, ReplacesAnEarlierOutputOnlyWithOverwrite) {
  const Sandbox sandbox("replace");
  const fs::path out = sandbox.root / "out";
  MakeOutput(sandbox.Options(out), "old.txt");
  try {
    OutputTarget target(sandbox.Options(out));
    FAIL() << "replaced without --overwrite";
  } catch (const InvalidArgumentError& error) {
    EXPECT_NE(std::string(error.what()).find("pass --overwrite"), std::string::npos)
        << error.what();
  }
  EXPECT_TRUE(fs::exists(out / "old.txt"));

  OutputOptions overwrite = sandbox.Options(out);
  overwrite.overwrite = true;
  {
    OutputTarget target(overwrite);
    WriteIn(target.staging(), "new.txt", "new");
    EXPECT_TRUE(fs::exists(out / "old.txt")) << "the earlier output went before the new was done";
    target.Commit();
  }
  EXPECT_FALSE(fs::exists(out / "old.txt")) << "old files mixed into the new output";
  EXPECT_TRUE(fs::exists(out / "new.txt"));
  EXPECT_EQ(sandbox.Others(sandbox.root, "out").size(), 4u) << "an aside folder was left";

  // Another command's output is not this command's to replace.
  OutputOptions other = sandbox.Options(out, "simulate");
  other.overwrite = true;
  EXPECT_THROW(OutputTarget target(other), InvalidArgumentError);
  EXPECT_TRUE(fs::exists(out / "new.txt"));
}

TEST(OutputTargetTest, AFailedReplacementKeepsTheEarlierOutput) {
  const Sandbox sandbox("failed_replace");
  const fs::path out = sandbox.root / "out";
  MakeOutput(sandbox.Options(out), "old.txt");
  OutputOptions overwrite = sandbox.Options(out);
  overwrite.overwrite = true;
  {
    OutputTarget target(overwrite);
    WriteIn(target.staging(), "half.txt", "half");
  }
  EXPECT_TRUE(fs::exists(out / "old.txt"));
  EXPECT_EQ(sandbox.Others(sandbox.root, "out").size(), 4u);
}

TEST(OutputTargetTest, AnEmptyFolderIsUsed) {
  const Sandbox sandbox("empty");
  const fs::path out = sandbox.root / "out";
  fs::create_directories(out);
  MakeOutput(sandbox.Options(out), "result.txt");
  EXPECT_TRUE(fs::exists(out / "result.txt"));
}

TEST(OutputTargetTest, RefusesTheRootHomeAndCurrentFoldersAndTheirParents) {
  const Sandbox sandbox("protected");
  for (const char* name : {"root", "home", "cwd"}) {
    SCOPED_TRACE(name);
    OutputOptions options = sandbox.Options(sandbox.root / name);
    options.overwrite = true;
    EXPECT_THROW(OutputTarget target(options), InvalidArgumentError);
    EXPECT_THROW(OutputTarget target(sandbox.Options(sandbox.root / name / ".")),
                 InvalidArgumentError);
  }
  EXPECT_THROW(OutputTarget target(sandbox.Options(sandbox.root)), InvalidArgumentError);
  EXPECT_THROW(OutputTarget target(sandbox.Options(sandbox.root / "home/x/..")),
               InvalidArgumentError);
  // Inside them is where outputs normally go.
  MakeOutput(sandbox.Options(sandbox.root / "home/out"), "result.txt");
  EXPECT_TRUE(fs::exists(sandbox.root / "home/out/result.txt"));
  for (const char* name : {"root", "home", "cwd", "data"}) {
    EXPECT_TRUE(fs::is_directory(sandbox.root / name)) << name;
  }
}

TEST(OutputTargetTest, DefaultProtectedFoldersAreTheRealOnes) {
  const std::vector<ProtectedFolder> folders = DefaultProtectedFolders();
  const auto has = [&folders](const fs::path& path) {
    for (const ProtectedFolder& folder : folders) {
      if (fs::path(folder.path) == path) return true;
    }
    return false;
  };
  EXPECT_TRUE(has("/"));
  EXPECT_TRUE(has(fs::current_path()));
  if (const char* home = std::getenv("HOME")) {
    EXPECT_TRUE(has(home));
  }
}

TEST(OutputTargetTest, RefusesTheInputAFolderInsideItAndOneAroundIt) {
  const Sandbox sandbox("input");
  const fs::path data = sandbox.root / "data";
  fs::create_directory_symlink(data, sandbox.root / "link_to_data");
  fs::create_directories(sandbox.root / "around");
  OutputOptions around = sandbox.Options(sandbox.root / "around");
  around.inputs = {(sandbox.root / "around/inner/recording.h5").string()};
  for (const OutputOptions& options :
       {sandbox.Options(data), sandbox.Options(data / "sub"), sandbox.Options(data / ".."),
        sandbox.Options(sandbox.root / "link_to_data/sub"), around}) {
    SCOPED_TRACE(options.path);
    EXPECT_THROW(OutputTarget target(options), InvalidArgumentError);
  }
  EXPECT_EQ(test::ReadFile((data / "events.txt").string()), "0.1 1 1 1\n");
  EXPECT_FALSE(fs::exists(data / "sub"));
}

TEST(OutputTargetTest, RefusesFilesLinksAndOddNames) {
  const Sandbox sandbox("odd");
  const fs::path file = sandbox.root / "notes.txt";
  test::WriteFile(file.string(), "mine");
  EXPECT_THROW(OutputTarget target(sandbox.Options(file)), InvalidArgumentError);
  EXPECT_EQ(test::ReadFile(file.string()), "mine");

  fs::create_directory_symlink(sandbox.root / "home", sandbox.root / "link");
  EXPECT_THROW(OutputTarget target(sandbox.Options(sandbox.root / "link")), InvalidArgumentError);
  EXPECT_TRUE(fs::is_symlink(sandbox.root / "link"));

  // A FIFO named like the marker is not read (reading it would block forever).
  fs::create_directories(sandbox.root / "fifo");
  ASSERT_EQ(mkfifo((sandbox.root / "fifo" / kOutputMarkerFile).c_str(), 0600), 0);
  EXPECT_THROW(OutputTarget target(sandbox.Options(sandbox.root / "fifo")), InvalidArgumentError);

  EXPECT_THROW(OutputTarget target(sandbox.Options("")), InvalidArgumentError);
}

TEST(OutputTargetTest, AnUnwritablePlaceFailsBeforeAnyWork) {
  const Sandbox sandbox("unwritable");
  test::WriteFile((sandbox.root / "file").string(), "a file");
  try {
    OutputTarget target(sandbox.Options(sandbox.root / "file/out"));
    FAIL() << "accepted a path under a file";
  } catch (const InputError& error) {
    EXPECT_EQ(error.kind(), InputError::Kind::kUnwritable);
  }
  // 255 bytes fit a name but not the name with its temporary suffix.
  try {
    OutputTarget target(sandbox.Options(sandbox.root / std::string(250, 'n')));
    FAIL() << "accepted a name too long for its temporary suffix";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("too long"), std::string::npos) << error.what();
  }
  EXPECT_EQ(sandbox.Others(sandbox.root, "file").size(), 4u);
}

TEST(OutputTargetTest, SomethingThatAppearedMeanwhileIsNotReplaced) {
  const Sandbox sandbox("race");
  const fs::path out = sandbox.root / "out";
  {
    OutputTarget target(sandbox.Options(out));
    WriteIn(out.string(), "user.txt", "created while evfs worked");
    EXPECT_THROW(target.Commit(), InvalidArgumentError);
  }
  EXPECT_TRUE(fs::exists(out / "user.txt"));
  EXPECT_EQ(sandbox.Others(sandbox.root, "out").size(), 4u);
}

TEST(OutputTargetTest, AFileOutputKeepsItsExtensionAndReplacesOnlyItsOwnFiles) {
  const Sandbox sandbox("file");
  const fs::path out = sandbox.root / "recording.h5";
  OutputOptions options = sandbox.Options(out, "convert");
  options.kind = OutputOptions::Kind::kFile;
  options.is_own_file = [](const std::string& path) {
    return test::ReadFile(path).rfind("evfs", 0) == 0;
  };
  {
    OutputTarget target(options);
    EXPECT_EQ(fs::path(target.staging()).extension(), ".h5");
    EXPECT_TRUE(fs::is_regular_file(target.staging()));
    test::WriteFile(target.staging(), "evfs 1");
    target.Commit();
  }
  EXPECT_EQ(test::ReadFile(out.string()), "evfs 1");
  EXPECT_THROW(OutputTarget target(options), InvalidArgumentError);  // no --overwrite
  options.overwrite = true;
  {
    OutputTarget target(options);
    test::WriteFile(target.staging(), "evfs 2");
    target.Commit();
  }
  EXPECT_EQ(test::ReadFile(out.string()), "evfs 2");

  test::WriteFile(out.string(), "someone else's recording");
  EXPECT_THROW(OutputTarget target(options), InvalidArgumentError);
  EXPECT_EQ(test::ReadFile(out.string()), "someone else's recording");
  EXPECT_EQ(sandbox.Others(sandbox.root, "recording.h5").size(), 4u);
}

// A forked worker writes into a staging folder until a signal kills it; its parent, told of
// the staging folder through a CleanupChannel, removes it. The earlier output stays untouched.
void ExpectSignalCleansUp(int signal_number) {
  const Sandbox sandbox(std::string("signal_") + std::to_string(signal_number));
  const fs::path out = sandbox.root / "out";
  MakeOutput(sandbox.Options(out), "old.txt");
  OutputOptions options = sandbox.Options(out);
  options.overwrite = true;

  CleanupChannel channel;
  ASSERT_TRUE(channel.valid());
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    channel.AttachWorker();
    OutputTarget target(options);
    for (int i = 0;; ++i) {
      WriteIn(target.staging() + "/frames", std::to_string(i) + ".png", std::string(4096, 'x'));
    }
  }
  channel.AttachSupervisor();
  // Wait until the worker is writing frames, then stop it.
  fs::path staging;
  for (int wait_ms = 0; wait_ms < 20000 && staging.empty(); ++wait_ms) {
    for (const auto& entry : fs::directory_iterator(sandbox.root)) {
      if (entry.path().filename().string().rfind(".out.evfs-tmp-", 0) == 0 &&
          fs::exists(entry.path() / "frames/10.png")) {
        staging = entry.path();
      }
    }
    if (staging.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_FALSE(staging.empty()) << "the worker never wrote";
  ASSERT_EQ(kill(child, signal_number), 0);
  channel.ReadUntilWorkerEnds();
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), signal_number);
  EXPECT_TRUE(fs::exists(staging)) << "nothing to clean up: the test proves nothing";

  // The staging folder and the lock file beside OUT, which the worker registered too.
  std::vector<std::string> removed = channel.RemoveLeftovers();
  std::sort(removed.begin(), removed.end());
  EXPECT_EQ(removed, (std::vector<std::string>{
                         OutputLock::LockPath((sandbox.root / "out").string()), staging.string()}));
  EXPECT_FALSE(fs::exists(staging));
  std::vector<std::string> others = sandbox.Others(sandbox.root, "out");
  EXPECT_EQ(others.size(), 4u) << "a staging folder was left";
  EXPECT_EQ(test::ReadFile((out / "old.txt").string()), "old.txt");
}

// A second run on the same --out is refused, naming the output and the first run's process,
// for as long as the first holds the lock; a SIGKILL of the holder releases it.
TEST(OutputLockTest, ASecondRunIsRefusedWhileTheFirstHoldsTheLock) {
  const Sandbox sandbox("lock");
  const fs::path out = sandbox.root / "out";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t holder = ::fork();
  ASSERT_GE(holder, 0);
  if (holder == 0) {
    ::close(ready[0]);
    OutputTarget target(sandbox.Options(out));
    const char byte = 1;
    if (::write(ready[1], &byte, 1) != 1) ::_exit(1);
    ::pause();  // until killed
    ::_exit(0);
  }
  ::close(ready[1]);
  char byte = 0;
  ASSERT_EQ(::read(ready[0], &byte, 1), 1);
  ::close(ready[0]);

  const std::string holder_pid = std::to_string(holder);
  for (const bool direct : {true, false}) {
    try {
      if (direct) {
        OutputLock lock(out.string());
      } else {
        OutputTarget target(sandbox.Options(out));
      }
      ADD_FAILURE() << "a second run took the lock";
    } catch (const InvalidArgumentError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(out.string()), std::string::npos) << message;
      EXPECT_NE(message.find("process " + holder_pid), std::string::npos) << message;
    }
  }
  // The holder's staging folder is not a leftover while it runs.
  bool staging_kept = false;
  for (const std::string& name : sandbox.Others(sandbox.root, "out")) {
    staging_kept |= name.rfind(".out.evfs-tmp-" + holder_pid, 0) == 0;
  }
  EXPECT_TRUE(staging_kept);

  ::kill(holder, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(holder, &status, 0), holder);
  // The killed run's lock file is still there, and does not block.
  EXPECT_TRUE(fs::exists(OutputLock::LockPath(out.string())));
  {
    OutputTarget target(sandbox.Options(out));
    target.Commit();
  }
  EXPECT_TRUE(fs::exists(out / kOutputMarkerFile));
  EXPECT_FALSE(fs::exists(OutputLock::LockPath(out.string())));
}

// The lock file lies beside OUT: an output that exists is replaced with --overwrite while
// its own run's lock file is there, and nothing of the lock is inside the output.
TEST(OutputLockTest, TheLockFileIsNoPartOfTheOutput) {
  const Sandbox sandbox("lock_overwrite");
  const fs::path out = sandbox.root / "out";
  {
    OutputTarget target(sandbox.Options(out));
    EXPECT_TRUE(fs::exists(OutputLock::LockPath(out.string())));
    target.Commit();
  }
  OutputOptions options = sandbox.Options(out);
  options.overwrite = true;
  {
    OutputTarget target(options);
    target.Commit();
  }
  EXPECT_EQ(sandbox.Others(sandbox.root, "out").size(), 4u);  // root, home, cwd, data
  EXPECT_EQ(sandbox.Others(out, "").size(), 1u);              // the marker
}

// A user's file that happens to carry the lock's name is not evfs' to overwrite or delete:
// the run is refused and the file is left as it was. A stale lock of a run that died (a
// process id) and an empty file are evfs' own and are taken over.
TEST(OutputLockTest, AForeignFileOfTheLocksNameSurvives) {
  const Sandbox sandbox("lock_foreign");
  const fs::path out = sandbox.root / "out";
  const std::string lock_path = OutputLock::LockPath(out.string());
  for (const std::string& content :
       {std::string("my notes\n"), std::string("12345\n12345\n"), std::string(100, '7')}) {
    test::WriteFile(lock_path, content);
    try {
      OutputTarget target(sandbox.Options(out));
      ADD_FAILURE() << "a run took a lock file holding '" << content << "'";
    } catch (const InvalidArgumentError& error) {
      EXPECT_NE(std::string(error.what()).find("not evfs'"), std::string::npos) << error.what();
    }
    EXPECT_EQ(test::ReadFile(lock_path), content);
    EXPECT_FALSE(fs::exists(out));
  }
  fs::remove(lock_path);
  fs::create_directory(lock_path);
  EXPECT_THROW(OutputTarget target(sandbox.Options(out)), std::exception);
  EXPECT_TRUE(fs::is_directory(lock_path));
  fs::remove(lock_path);

  for (const std::string& content : {std::string(), std::string("4242\n")}) {
    test::WriteFile(lock_path, content);
    {
      OutputTarget target(sandbox.Options(out));
      target.Commit();
    }
    EXPECT_FALSE(fs::exists(lock_path));
    fs::remove_all(out);
  }
}

TEST(SignalCleanupTest, AReleasedPathIsNotRemoved) {
  const Sandbox sandbox("released");
  CleanupChannel channel;
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    channel.AttachWorker();
    MakeOutput(sandbox.Options(sandbox.root / "out"), "done.txt");
    ScopedCleanupPath left((sandbox.root / "left").string());
    fs::create_directories(sandbox.root / "left");
    _exit(3);  // dies without unwinding, as a failed CHECK does
  }
  channel.AttachSupervisor();
  channel.ReadUntilWorkerEnds();
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_EQ(channel.RemoveLeftovers(), std::vector<std::string>{(sandbox.root / "left").string()});
  EXPECT_TRUE(fs::exists(sandbox.root / "out/done.txt"));
  EXPECT_FALSE(fs::exists(sandbox.root / "left"));
}

TEST(SignalCleanupTest, SigintWhileWritingRemovesStagingAndKeepsEarlierOutput) {
  ExpectSignalCleansUp(SIGINT);
}

TEST(SignalCleanupTest, SigtermWhileWritingRemovesStagingAndKeepsEarlierOutput) {
  ExpectSignalCleansUp(SIGTERM);
}

TEST(SignalCleanupTest, SighupWhileWritingRemovesStagingAndKeepsEarlierOutput) {
  ExpectSignalCleansUp(SIGHUP);
}

}  // namespace
}  // namespace evfs
