#include "core/tool.hpp"

#include <cstdio>
#include <new>

#include "core/error.hpp"

namespace spx {

const char* version_string() { return SPX_VERSION; }

Tool::Tool(std::string name, const std::string& description)
    : app(description, name), log(name, 0), name_(std::move(name)) {
  app.set_version_flag("--version", std::string(name_) + " (spx) " + SPX_VERSION);
  app.add_option("--report", report_path_, "Write a machine-readable JSON report to this file");
  app.add_flag("-q,--quiet", quiet_, "Print errors only");
  app.add_flag("-v,--verbose", verbose_, "Print stage timings and details");
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
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "Error: %s (see %s --help)\n", e.what(), name_.c_str());
    return static_cast<int>(ExitCode::usage);
  }
  log.set_verbosity(quiet_ > 0 ? -1 : verbose_);

  ExitCode code = ExitCode::ok;
  try {
    StageTimer total(log, "total");
    body();
    total.stop();
    if (!report_path_.empty()) {
      json r = report;
      r["generator"] = name_ + " (spx) " + SPX_VERSION;
      r["status"] = "ok";
      r["warnings"] = log.warnings();
      json t = json::object();
      for (const auto& [stage, seconds] : log.timings()) t[stage] = seconds;
      r["timings_s"] = t;
      write_json_atomic(report_path_, r);
    }
    return 0;
  } catch (const Error& e) {
    Log::clear_transient();
    std::fprintf(stderr, "Error: %s\n", e.what());
    code = e.code();
  } catch (const std::bad_alloc&) {
    Log::clear_transient();
    std::fprintf(stderr, "Error: %s: out of memory (try a coarser --resolution)\n", name_.c_str());
    code = ExitCode::unsupported;
  } catch (const std::exception& e) {
    // Every expected failure is an spx::Error with its class; anything else is our bug.
    Log::clear_transient();
    std::fprintf(stderr, "Error: %s: internal error: %s (please report it with the inputs)\n", name_.c_str(), e.what());
    code = ExitCode::internal;
  }
  return static_cast<int>(code);
}

}  // namespace spx
