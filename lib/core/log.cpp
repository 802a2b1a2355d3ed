#include "core/log.hpp"

#include <cstdio>
#include <unistd.h>

namespace spx {

Log& Log::silent() {
  static thread_local Log log("", -1);
  return log;
}

void Log::info(const std::string& msg) const {
  if (verbosity_ >= 0) std::fprintf(stderr, "%s: %s\n", tool_.c_str(), msg.c_str());
}

void Log::detail(const std::string& msg) const {
  if (verbosity_ >= 1) std::fprintf(stderr, "%s: %s\n", tool_.c_str(), msg.c_str());
}

void Log::warn(const std::string& msg) {
  warnings_.push_back(msg);
  if (verbosity_ >= 0) std::fprintf(stderr, "%s: warning: %s\n", tool_.c_str(), msg.c_str());
}

void Log::progress(const char* stage, size_t done, size_t total) const {
  if (verbosity_ < 0 || total == 0) return;
  static const bool tty = ::isatty(2) != 0;
  if (!tty) return;
  const size_t step = total / 20 + 1;
  if (done % step != 0 && done != total) return;
  std::fprintf(stderr, "\r%s: %s %3d%%%s", tool_.c_str(), stage, static_cast<int>(100.0 * done / total),
               done == total ? "\n" : "");
}

void Log::record_time(const std::string& stage, double seconds) {
  timings_.emplace_back(stage, seconds);
  detail(stage + " took " + std::to_string(seconds) + " s");
}

StageTimer::StageTimer(Log& log, std::string stage)
    : log_(log), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {}

StageTimer::~StageTimer() { stop(); }

double StageTimer::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void StageTimer::stop() {
  if (stopped_) return;
  stopped_ = true;
  log_.record_time(stage_, elapsed());
}

}  // namespace spx
