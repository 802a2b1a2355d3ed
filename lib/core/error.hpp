#pragma once
// Failure classes shared by every tool. Each maps to one documented exit code.
#include <new>
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
        code_(code), subject_(std::move(subject)), message_(message) {}
  ExitCode code() const { return code_; }
  const std::string& subject() const { return subject_; }
  const std::string& message() const { return message_; }

 private:
  ExitCode code_;
  std::string subject_, message_;
};

// A bad value in a library function's typed options. `option` is the field's name
// ("max_radius"); the command-line layer names it as its users spell it ("--max-radius").
class OptionError : public Error {
 public:
  OptionError(const std::string& option, const std::string& message) : Error(ExitCode::usage, option, message) {}
  const std::string& option() const { return subject(); }
};

[[noreturn]] inline void fail_option(const std::string& option, const std::string& msg) {
  throw OptionError(option, msg);
}
// `subject` is what the message is about: a file name, or a value given on the command line.
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

// A library that catches every exception and keeps only its text (assimp's importer and exporter)
// turns running out of memory into an error message. Thrown again as what it was, the tool says
// "out of memory" (exit 3), not that the file is bad.
inline void rethrow_out_of_memory(const std::string& library_message) {
  if (library_message == std::bad_alloc().what()) throw std::bad_alloc();
}

}  // namespace spx
