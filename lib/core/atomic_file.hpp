#pragma once
// Atomic output: write a temp file beside the target, flush and close it, then rename.
// A failed or interrupted run leaves the previous file (or none), never a half file; one ended
// by SIGINT, SIGTERM or SIGHUP removes the temp file it was writing, too.
#include <string>
#include <string_view>

namespace spx {

// Writes `bytes` to `path` atomically; throws Error(cannot_write) naming `path`. Where `path` is a
// symbolic link, the file it names is replaced (the link stays); where it is a pipe, a terminal or
// a descriptor of the process (/dev/stdout), there is no file to replace: the bytes are written
// to it as to a stream.
void write_file_atomic(const std::string& path, std::string_view bytes);

// Reads a whole file; throws Error(bad_input) naming `path` when it cannot.
std::string read_file(const std::string& path);

// Throws Error(bad_input) naming `path`, which does not exist: "cannot open: no such file", with
// a word on a Windows path (a '\\' in a name a pipeline wrote on Windows) where it holds one.
[[noreturn]] void fail_no_such_file(const std::string& path);

}  // namespace spx
