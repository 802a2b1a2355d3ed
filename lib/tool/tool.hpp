#pragma once
// The shell every command-line tool shares: CLI11 parsing, --version, -q/-v, --report, and
// the mapping from failures to one stderr line and a documented exit code. Only apps/ use it:
// the library takes typed options and throws typed errors, and this layer names them as the
// command line spells them.
#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/json_io.hpp"
#include "core/log.hpp"
#include "core/tolerance.hpp"
#include "core/version.hpp"

namespace spx {

class Tool {
 public:
  Tool(std::string name, const std::string& description);

  CLI::App app;
  Log log;
  json report = json::object();  // tool-specific fields; generator/status/timings added by run()

  // Parses argv, runs `body`, writes --report (status "ok", or on failure "error" with the
  // message and the exit code, so that a script never reads an earlier run's report as this
  // one's). Returns the process exit code.
  int run(int argc, char** argv, const std::function<void()>& body);

  const std::string& name() const { return name_; }

  // An option naming a file the tool writes (besides --report): a folder that is not there
  // fails before the work, not after it.
  void writes_file(const std::string& flag) { file_outputs_.push_back(flag); }
  // An option naming a folder the tool creates (with its parents): a --report there is fine.
  void writes_folder(const std::string& flag) { folder_outputs_.push_back(flag); }

  // What makes this tool's run smaller, said after "out of memory" ("try a coarser --resolution"):
  // each tool names its own options, not another's.
  void when_out_of_memory(std::string hint) { memory_hint_ = std::move(hint); }

  // The flag that sets the library option `option` when it is not "--" + the option with
  // '_' as '-' (proxy-export's "pose" is --ply-pose).
  void name_option(const std::string& option, const std::string& flag) { flags_[option] = flag; }
  std::string flag_for(const std::string& option) const;

 private:
  // The options of `flags` given on the command line; those naming files the tool writes.
  std::vector<const CLI::Option*> given(const std::vector<std::string>& flags) const;
  std::vector<const CLI::Option*> given_files() const;
  // CLI11's "Could not convert: --flag = value" said as what the option takes.
  std::string conversion_error(const std::string& what) const;
  // Fails (exit 1, naming the option) where a value is the empty string: no file or folder has
  // that name, and "" has no absolute path to compare.
  void check_no_empty_values() const;
  // Fails (exit 4, naming the file) where an output's folder is not there, and (exit 1, naming
  // the option) where a file output names a folder.
  void check_output_folders() const;
  // Fails (exit 1, naming the flag) where an output is an input's file or another output's: the
  // run would lose what it was given, or write one file twice.
  void check_outputs_apart() const;
  // generator, warnings and timings_s, which every report has.
  void add_common_fields(json& r) const;
  // A failure said: its one "Error: <message>" line, and where --report was given and can be
  // written, its report (status "error", the message, the code). Returns the exit code.
  int fail_run(ExitCode code, const std::string& message) noexcept;
  // Out of memory said (exit 3): `what` the library's words, where it gave any, then this tool's hint.
  int fail_out_of_memory(const std::string& what) noexcept;
  std::map<std::string, std::string> flags_;
  std::vector<std::string> file_outputs_, folder_outputs_;
  std::string name_;
  std::string report_path_;
  std::string memory_hint_;
  int quiet_ = 0;
  int verbose_ = 0;
  size_t threads_ = 0;  // --threads: 0 is every core
};

// CLI11's PositiveNumber and NonNegativeNumber with messages a person reads ("must be above 0,
// not -3"; CLI11's spelled out the range up to the largest double).
extern const CLI::Validator kPositive, kNonNegative;

// sphere-pack's and pose-map's --cache-limit (a size: bytes, or kb, mb, gb in powers of 1024),
// which needs their --cache option `cache`.
CLI::Option* add_cache_limit(CLI::App& app, uint64_t& limit, CLI::Option* cache);

// "0.05" (mesh units) or "1%" (of the diagonal); empty: not set. A usage error naming `flag`.
Tolerance parse_tolerance(const std::string& text, const std::string& flag);

// Frames by index from 0, each word a frame ("4") or a range of them, both ends in ("10-20"), in
// the order given. A usage error naming `flag` for a word that is neither.
std::vector<int> parse_frame_list(const std::vector<std::string>& words, const std::string& flag);

}  // namespace spx
