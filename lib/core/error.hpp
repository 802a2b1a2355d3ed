#pragma once
// Failure classes shared by every tool. Each maps to one documented exit code.
#include <stdexcept>
#include <string>

namespace spx {

enum class ExitCode : int {
  ok = 0,
  usage = 1,        // bad command line or parameter
  bad_input = 2,    // unreadable or invalid input file
  unsupported = 3,  // valid input we do not handle (format, newer version)
  cannot_write = 4, // output could not be written
  internal = 5      // a bug: an unexpected failure inside the tool (please report it)
};

class Error : public std::runtime_error {
 public:
  Error(ExitCode code, std::string subject, const std::string& message)
      : std::runtime_error(subject.empty() ? message : subject + ": " + message),
        code_(code), subject_(std::move(subject)) {}
  ExitCode code() const { return code_; }
  const std::string& subject() const { return subject_; }

 private:
  ExitCode code_;
  std::string subject_;
};

// `subject` is what the message is about: a file name or an option name.
[[noreturn]] inline void fail_usage(const std::string& subject, const std::string& msg) {
  throw Error(ExitCode::usage, subject, msg);
}
[[noreturn]] inline void fail_input(const std::string& file, const std::string& msg) {
  throw Error(ExitCode::bad_input, file, msg);
}
[[noreturn]] inline void fail_unsupported(const std::string& file, const std::string& msg) {
  throw Error(ExitCode::unsupported, file, msg);
}
[[noreturn]] inline void fail_write(const std::string& file, const std::string& msg) {
  throw Error(ExitCode::cannot_write, file, msg);
}

}  // namespace spx
