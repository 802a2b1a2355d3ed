#pragma once
// Progress and warnings for long steps, on stderr, shared by the library and the tools. Each
// message is one line: a control character a file name brings is written as its escape.
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace spx {

class Log {
 public:
  explicit Log(std::string tool = {}, int verbosity = 0) : tool_(std::move(tool)), verbosity_(verbosity) {}
  static Log& silent();

  int verbosity() const { return verbosity_; }
  void set_verbosity(int v) { verbosity_ = v; }

  void info(const std::string& msg) const;    // shown unless -q
  void detail(const std::string& msg) const;  // shown with -v
  void warn(const std::string& msg);          // shown unless -q, kept for the report
  // Percent progress for long loops, only when stderr is a terminal.
  void progress(const char* stage, size_t done, size_t total) const;
  // "tool: stage..." while a stage runs, only when stderr is a terminal (overwritten in place).
  void begin(const std::string& stage) const;
  // Erases such a line (before an error message, say).
  static void clear_transient();

  const std::vector<std::string>& warnings() const { return warnings_; }
  // Stage timings in seconds, in the order the stages ran.
  const std::vector<std::pair<std::string, double>>& timings() const { return timings_; }
  void record_time(const std::string& stage, double seconds);

  // For a step that runs beside others: a log that prints as this one does and records apart
  // (records are not shared across threads); join() then takes its warnings and timings in.
  Log fork() const { return Log(tool_, verbosity_); }
  void join(const Log& other);

 private:
  std::string tool_;
  int verbosity_;
  std::vector<std::string> warnings_;
  std::vector<std::pair<std::string, double>> timings_;
};

// Times one stage; records it in the log when it ends.
class StageTimer {
 public:
  StageTimer(Log& log, std::string stage);
  ~StageTimer();
  double elapsed() const;
  void stop();

 private:
  Log& log_;
  std::string stage_;
  std::chrono::steady_clock::time_point start_;
  bool stopped_ = false;
};

}  // namespace spx
