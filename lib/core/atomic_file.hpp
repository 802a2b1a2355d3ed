#pragma once
// Atomic output: write a temp file beside the target, flush and close it, then rename.
// A failed or interrupted run leaves the previous file (or none), never a half file; one ended
// by SIGINT, SIGTERM or SIGHUP removes the temp file it was writing, too.
#include <functional>
#include <string>
#include <string_view>

namespace spx {

// Writes `bytes` to `path` atomically; throws Error(cannot_write) naming `path`.
void write_file_atomic(const std::string& path, std::string_view bytes);

// For writers that need a real file path (OpenVDB): `write` receives the temp path and
// must produce the file there; the temp is renamed over `path` only if `write` returns.
void write_via_temp(const std::string& path, const std::function<void(const std::string&)>& write);

// Reads a whole file; throws Error(bad_input) naming `path` when it cannot.
std::string read_file(const std::string& path);

}  // namespace spx
