#include "core/log.hpp"

#include <cstdio>
#include <unistd.h>

#include "core/format.hpp"

namespace spx {

Log& Log::silent() {
  static thread_local Log log("", -1);
  return log;
}

namespace {
bool stderr_is_tty() {
  static const bool tty = ::isatty(2) != 0;
  return tty;
}
// Clears a transient stage line before anything permanent is printed.
void clear_line() {
  if (stderr_is_tty()) std::fputs("\r\x1b[K", stderr);
}
}  // namespace

void Log::clear_transient() { clear_line(); }

void Log::info(const std::string& msg) const {
  if (verbosity_ < 0) return;
  clear_line();
  std::fprintf(stderr, "%s: %s\n", tool_.c_str(), escape_controls(msg).c_str());
}

void Log::begin(const std::string& stage) const {
  if (verbosity_ < 0 || tool_.empty() || !stderr_is_tty()) return;
  std::fprintf(stderr, "\r\x1b[K%s: %s...", tool_.c_str(), escape_controls(stage).c_str());
  std::fflush(stderr);
}

void Log::detail(const std::string& msg) const {
  if (verbosity_ < 1) return;
  clear_line();
  std::fprintf(stderr, "%s: %s\n", tool_.c_str(), escape_controls(msg).c_str());
}

void Log::warn(const std::string& msg) {
  warnings_.push_back(msg);
  if (verbosity_ >= 0) clear_line();
  if (verbosity_ >= 0) std::fprintf(stderr, "%s: warning: %s\n", tool_.c_str(), escape_controls(msg).c_str());
}

void Log::progress(const char* stage, size_t done, size_t total) const {
  if (verbosity_ < 0 || total == 0) return;
  if (!stderr_is_tty()) return;
  const size_t step = total / 20 + 1;
  if (done % step != 0 && done != total) return;
  std::fprintf(stderr, "\r%s: %s %3d%%%s", tool_.c_str(), stage, static_cast<int>(100.0 * done / total),
               done == total ? "\n" : "");
}

void Log::record_time(const std::string& stage, double seconds) {
  timings_.emplace_back(stage, seconds);
  detail(stage + " took " + std::to_string(seconds) + " s");
}

void Log::join(const Log& other) {
  warnings_.insert(warnings_.end(), other.warnings_.begin(), other.warnings_.end());
  timings_.insert(timings_.end(), other.timings_.begin(), other.timings_.end());
}

StageTimer::StageTimer(Log& log, std::string stage)
    : log_(log), stage_(std::move(stage)), start_(std::chrono::steady_clock::now()) {
  if (stage_ != "total") log_.begin(stage_);
}

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
