#pragma once
// The shell every command-line tool shares: CLI11 parsing, --version, -q/-v, --report,
// and the mapping from failures to one stderr line and a documented exit code.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "core/json_io.hpp"
#include "core/log.hpp"

namespace spx {

const char* version_string();

class Tool {
 public:
  Tool(std::string name, const std::string& description);

  CLI::App app;
  Log log;
  json report = json::object();  // tool-specific fields; generator/status/timings added by run()

  // Parses argv, runs `body`, writes --report on success. Returns the process exit code.
  int run(int argc, char** argv, const std::function<void()>& body);

  const std::string& name() const { return name_; }

 private:
  std::string name_;
  std::string report_path_;
  int quiet_ = 0;
  int verbose_ = 0;
};

}  // namespace spx
