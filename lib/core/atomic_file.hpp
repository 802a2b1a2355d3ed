#pragma once
// Atomic output: write a temp file beside the target, flush and close it, then rename.
// A failed or interrupted run leaves the previous file (or none), never a half file; one ended
// by SIGINT, SIGTERM or SIGHUP removes the temp file it was writing, too.
#include <functional>
#include <string>
#include <string_view>

namespace spx {

// Writes `bytes` to `path` atomically; throws Error(cannot_write) naming `path`. Where `path` is a
// symbolic link, the file it names is replaced (the link stays); where it is a pipe, a terminal or
// a descriptor of the process (/dev/stdout), there is no file to replace: the bytes are written
// to it as to a stream.
void write_file_atomic(const std::string& path, std::string_view bytes);

// An exclusive hold on a folder while a run writes files in it that only make sense together
// (pose-extract's poses and the manifest naming them): another run on the same folder, a make -j
// with two rules writing one folder, waits until this one has written its whole set, so that a
// manifest never names another run's files. `waiting` is called before a wait. The kernel lets
// go when the process ends, however it ends (flock). Where the file system has no such locks the
// folder is written as before.
class FolderLock {
 public:
  FolderLock(const std::string& dir, const std::function<void()>& waiting);
  ~FolderLock();
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_ = -1;
};

// Reads a whole file; throws Error(bad_input) naming `path` when it cannot.
std::string read_file(const std::string& path);

// Throws Error(bad_input) naming `path`, which does not exist: "cannot open: no such file", with
// a word on a Windows path (a '\\' in a name a pipeline wrote on Windows) where it holds one.
[[noreturn]] void fail_no_such_file(const std::string& path);

}  // namespace spx
