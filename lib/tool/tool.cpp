#include "tool/tool.hpp"

#include <malloc.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <new>
#include <optional>
#include <system_error>

#include "core/error.hpp"
#include "core/format.hpp"

namespace spx {
namespace {

// Memory or a thread the system would not give (a memory limit, ulimit -v): std::thread says so
// by its error code, TBB only in its message's last words, strerror's.
bool refused_by_the_system(const std::exception& e) {
  if (const auto* system = dynamic_cast<const std::system_error*>(&e))
    return system->code() == std::errc::resource_unavailable_try_again || system->code() == std::errc::not_enough_memory;
  const std::string what = e.what();
  for (int code : {EAGAIN, ENOMEM}) {
    const std::string words = std::strerror(code);
    if (what.size() >= words.size() && what.compare(what.size() - words.size(), words.size(), words) == 0) return true;
  }
  return false;
}

// Large blocks come from the heap and stay there when freed. glibc maps every block past 32 MiB
// afresh (its largest mmap threshold) and unmaps it when freed; on these virtual machines each
// fresh page costs a fault and the kernel's zeroing, and the covers' pair tables (tens of MiB,
// built and freed round after round) paid that every time: pose-map's 48-frame walk spent a
// third of its reductions' time on it. The peak is the same; the memory is kept until exit.
void keep_large_blocks_on_the_heap() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
}

// A number above 0 (or, zero_allowed, at least 0), said as a person reads it.
CLI::Validator bounded_below(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value) || std::isnan(value)) return "'" + text + "' is not a number";
        if (zero_allowed ? value < 0 : !(value > 0))
          return std::string("must be ") + (zero_allowed ? "0 or more" : "above 0") + ", not " + text;
        return std::string();
      },
      zero_allowed ? "NONNEGATIVE" : "POSITIVE");
}
}  // namespace

const CLI::Validator kPositive = bounded_below(false), kNonNegative = bounded_below(true);

Tool::Tool(std::string name, const std::string& description)
    : app(description, name), log(name, 0), name_(std::move(name)) {
  app.set_version_flag("--version", std::string(name_) + " (spx) " + version_string());
  app.add_option("--report", report_path_, "Write a machine-readable JSON report to this file");
  app.add_flag("-q,--quiet", quiet_, "Print errors only");
  app.add_flag("-v,--verbose", verbose_, "Print stage timings and details");
  app.add_option("--threads", threads_,
                 "Use at most this many threads (default: every core); the outputs are the same whatever the count")
      ->check(kPositive);
  // What a script branches on, where the person writing it looks first.
  app.footer(
      "Exit codes:\n"
      "  0  success\n"
      "  1  usage: a bad option or value\n"
      "  2  bad input: a file missing, unreadable or invalid\n"
      "  3  unsupported: a format or version not read here, a grid past the memory limit, out of memory\n"
      "  4  an output that cannot be written\n"
      "  5  internal error: a bug (please report it with the inputs)\n"
      "A failure prints one line, 'Error: <file>: <what is wrong>', and leaves no half-written output.");
}

std::vector<const CLI::Option*> Tool::given(const std::vector<std::string>& flags) const {
  std::vector<const CLI::Option*> out;
  for (const std::string& flag : flags) {
    const CLI::Option* option = app.get_option_no_throw(flag);
    if (option && option->count() > 0) out.push_back(option);
  }
  return out;
}

std::vector<const CLI::Option*> Tool::given_files() const {
  std::vector<std::string> flags = file_outputs_;
  flags.push_back("--report");
  return given(flags);
}

std::string Tool::conversion_error(const std::string& what) const {
  // CLI11 says "Could not convert: --resolution = abc"; said as the option and what it takes.
  const std::string head = "Could not convert: ";
  const size_t equals = what.find(" = ");
  if (what.rfind(head, 0) != 0 || equals == std::string::npos) return what;
  const std::string name = what.substr(head.size(), equals - head.size()), value = what.substr(equals + 3);
  const CLI::Option* option = app.get_option_no_throw(name);
  if (!option) return what;
  const std::string type = option->get_type_name();
  const std::string takes = type.rfind("UINT", 0) == 0  ? "a whole number from 0"
                            : type.rfind("INT", 0) == 0 ? "a whole number"
                            : type.rfind("FLOAT", 0) == 0 ? "a number"
                                                         : "";
  if (takes.empty()) return what;
  const bool list = option->get_items_expected_max() > 1;
  return name + ": '" + value + "' is not " + takes + (list ? " (or a list of them)" : "");
}

void Tool::check_no_empty_values() const {
  for (const CLI::Option* option : app.get_options()) {
    // A flag, or an option that may be given bare (precompute-bench's --frames: no sweep), which
    // CLI11 gives an empty value.
    if (option->get_type_size() == 0 || option->get_items_expected_min() == 0) continue;
    for (const std::string& value : option->results())
      if (value.empty())
        fail_usage(option->get_name(), "is empty (a shell or make variable that was not set?)");
  }
}

void Tool::check_output_folders() const {
  namespace fs = std::filesystem;
  // The folders the tool creates, and their parents.
  std::vector<fs::path> created;
  for (const CLI::Option* folder : given(folder_outputs_)) {
    const std::string path = folder->as<std::string>();
    const fs::path target = fs::absolute(path).lexically_normal();
    for (fs::path p = target; !p.empty() && p != p.parent_path(); p = p.parent_path()) {
      created.push_back(p);
      // A file where the folder (or one it goes in) would be fails now, not after the work.
      std::error_code ec;
      if (!fs::exists(p, ec)) continue;
      if (!fs::is_directory(p, ec))
        fail_write(path, "cannot make the folder: " + p.string() + " is a file" +
                             (p == target ? "" : ", not a folder the output can go in"));
      break;
    }
  }
  for (const CLI::Option* file : given_files()) {
    const std::string path = file->as<std::string>();
    std::error_code is_folder;
    if (fs::is_directory(path, is_folder))
      fail_usage(file->get_name(), path + " is a folder; give the name of the file to write (a path in it)");
    const fs::path folder = fs::absolute(path).lexically_normal().parent_path();
    std::error_code ec;
    if (fs::is_directory(folder, ec) || std::find(created.begin(), created.end(), folder) != created.end()) continue;
    fail_write(path, "cannot create output: its folder " + folder.string() +
                         (fs::exists(folder, ec) ? " is a file" : " is not there"));
  }
}

void Tool::check_outputs_apart() const {
  namespace fs = std::filesystem;
  const std::vector<const CLI::Option*> outputs = given_files();
  std::vector<fs::path> paths;
  for (const CLI::Option* o : outputs) paths.push_back(fs::absolute(o->as<std::string>()).lexically_normal());
  for (size_t a = 0; a < outputs.size(); ++a)
    for (size_t b = 0; b < a; ++b)
      if (paths[a] == paths[b]) fail_usage(outputs[a]->get_name(), "writes the file " + outputs[b]->get_name() + " writes");
  for (const CLI::Option* option : app.get_options()) {
    const bool is_output = std::find(outputs.begin(), outputs.end(), option) != outputs.end();
    if (is_output || option->get_type_size() == 0) continue;  // flags name no file
    const std::string name = option->get_name();
    const std::string what = name.rfind("--", 0) == 0 ? name + "'s file" : "the " + name;  // an option, or a positional
    for (const std::string& value : option->results())
      for (size_t k = 0; k < outputs.size(); ++k) {
        std::error_code ec;
        if (fs::equivalent(value, paths[k], ec))
          fail_usage(outputs[k]->get_name(), value + " is also " + what + ": writing it would overwrite an input");
      }
  }
}

std::string Tool::flag_for(const std::string& option) const {
  const auto named = flags_.find(option);
  if (named != flags_.end()) return named->second;
  std::string flag = "--" + option;
  for (char& c : flag)
    if (c == '_') c = '-';
  return app.get_option_no_throw(flag) ? flag : option;
}

void Tool::add_common_fields(json& r) const {
  r["generator"] = name_ + " (spx) " + version_string();
  // What the run could use: the cores in view (as TBB sees them: the affinity mask), capped by --threads.
  r["threads"] = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  r["warnings"] = log.warnings();
  json t = json::object();
  for (const auto& [stage, seconds] : log.timings()) t[stage] = seconds;
  r["timings_s"] = t;
}

int Tool::fail_run(ExitCode code, const std::string& message) noexcept {
  Log::clear_transient();
  std::fprintf(stderr, "Error: %s\n", escape_controls(message).c_str());  // one line, whatever a file name holds
  if (report_path_.empty()) return static_cast<int>(code);
  try {
    check_no_empty_values();  // "" has no absolute path
    check_outputs_apart();  // never over an input, even when the parse stopped before the run checked
    json r = json::object();
    r["status"] = "error";
    r["error"] = message;
    r["exit_code"] = static_cast<int>(code);
    add_common_fields(r);
    write_json_atomic(report_path_, r);
  } catch (...) {
    // The error line is said already; a report that cannot be written (its folder is not there,
    // or it names an input) is left as it was.
  }
  return static_cast<int>(code);
}

int Tool::run(int argc, char** argv, const std::function<void()>& body) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ConversionError& e) {
    return fail_run(ExitCode::usage, conversion_error(e.what()) + " (see " + name_ + " --help)");
  } catch (const CLI::ParseError& e) {
    return fail_run(ExitCode::usage, std::string(e.what()) + " (see " + name_ + " --help)");
  }
  log.set_verbosity(quiet_ > 0 ? -1 : verbose_);
  keep_large_blocks_on_the_heap();
  // A batch that runs several tools at once (make -j) gives each a share of the cores. Every
  // parallel step's result is independent of how many threads ran it, so the outputs are too.
  // More than the cores in view is every core (TBB would size its tables by a huge count).
  std::optional<tbb::global_control> thread_limit;
  if (threads_ > 0)
    thread_limit.emplace(tbb::global_control::max_allowed_parallelism,
                         std::min(threads_, size_t(tbb::info::default_concurrency())));

  try {
    check_no_empty_values();
    check_outputs_apart();
    check_output_folders();
    StageTimer total(log, "total");
    body();
    total.stop();
    if (!report_path_.empty()) {
      json r = report;
      r["status"] = "ok";
      add_common_fields(r);
      write_json_atomic(report_path_, r);
    }
    return 0;
  } catch (const OptionError& e) {
    return fail_run(e.code(), flag_for(e.option()) + ": " + e.message());
  } catch (const Error& e) {
    return fail_run(e.code(), e.what());
  } catch (const std::bad_alloc&) {
    return fail_out_of_memory("");
  } catch (const std::exception& e) {
    if (refused_by_the_system(e)) return fail_out_of_memory(e.what());
    // Every expected failure is an spx::Error with its class; anything else is our bug.
    return fail_run(ExitCode::internal, name_ + ": internal error: " + e.what() + " (please report it with the inputs)");
  }
}

int Tool::fail_out_of_memory(const std::string& what) noexcept {
  std::string message = name_ + ": out of memory";
  if (!what.empty()) message += " (" + what + ")";
  if (!memory_hint_.empty()) message += "; " + memory_hint_;
  return fail_run(ExitCode::unsupported, message);
}

CLI::Option* add_cache_limit(CLI::App& app, uint64_t& limit, CLI::Option* cache) {
  return app
      .add_option("--cache-limit", limit,
                  "Keep the --cache folder under this size (default 4gb; 0: no limit): after the run, the tools' "
                  "cache files least recently used are removed, never this run's")
      ->transform(CLI::AsSizeValue(false))
      ->check(kNonNegative)  // after the units: "-1" would wrap to the largest size
      ->needs(cache);
}

Tolerance parse_tolerance(const std::string& text, const std::string& flag) {
  Tolerance t;
  if (text.empty()) return t;
  std::string number = text;
  if (number.back() == '%') {
    t.percent = true;
    number.pop_back();
  }
  size_t used = 0;
  try {
    t.value = std::stod(number, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != number.size() || number.empty() || !(t.value > 0) || !std::isfinite(t.value))
    fail_usage(flag, "'" + text + "' is not a positive length or percentage (e.g. 0.05 or 1%)");
  return t;
}

std::vector<int> parse_frame_list(const std::vector<std::string>& words, const std::string& flag) {
  // A range this long is past any clip read here: refused before its frames are listed.
  constexpr long long kLongestRange = 1 << 20;
  auto index = [&](const std::string& word, const std::string& part) {
    long long value = -1;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (part.empty() || ec != std::errc() || end != part.data() + part.size() || value < 0 || value > (1 << 30))
      fail_usage(flag, "'" + word + "' is not a frame (a whole number from 0) or a range of them (10-20)");
    return value;
  };
  std::vector<int> frames;
  for (const std::string& given : words) {
    const size_t from = std::min(given.find_first_not_of(' '), given.size());
    const std::string word = given.substr(from, given.find_last_not_of(' ') + 1 - from);  // "0, 4": spaces around
    const size_t dash = word.find('-', 1);
    if (dash == std::string::npos) {
      frames.push_back(int(index(word, word)));
      continue;
    }
    const long long first = index(word, word.substr(0, dash)), last = index(word, word.substr(dash + 1));
    if (last < first)
      fail_usage(flag, "'" + word + "' runs backwards; write it " + std::to_string(last) + "-" + std::to_string(first));
    if (last - first >= kLongestRange)
      fail_usage(flag,
                 "'" + word + "' spans " + std::to_string(last - first + 1) + " frames, more than any clip read here");
    for (long long f = first; f <= last; ++f) frames.push_back(int(f));
  }
  return frames;
}

}  // namespace spx
