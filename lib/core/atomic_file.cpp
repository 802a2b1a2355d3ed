#include "core/atomic_file.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <unistd.h>

#include "core/error.hpp"
#include "core/hash.hpp"

namespace spx {
namespace {

// The temporary files being written, so that Ctrl-C, make's or a farm's SIGTERM, or a closed
// terminal does not leave one behind (kill -9 still can: under a hidden name, never the target's).
// The handler only reads these slots and unlinks, which is safe in a signal handler.
constexpr size_t kTempSlots = 64;
std::atomic<const char*> g_temps[kTempSlots];

extern "C" void remove_temps_and_end(int sig) {
  for (auto& slot : g_temps)
    if (const char* path = slot.load()) ::unlink(path);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

// Installed on the first write, for the signals whose action is still the default (a host that
// set its own keeps it). A file-size limit (ulimit -f) would end the run by SIGXFSZ mid-write;
// ignored, the write fails with EFBIG instead and the run ends with its one error line (exit 4).
void install_temp_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction xfsz {};
    if (::sigaction(SIGXFSZ, nullptr, &xfsz) == 0 && xfsz.sa_handler == SIG_DFL) std::signal(SIGXFSZ, SIG_IGN);
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction now {};
      if (::sigaction(sig, nullptr, &now) != 0 || now.sa_handler != SIG_DFL) continue;
      struct sigaction act {};
      act.sa_handler = remove_temps_and_end;
      sigemptyset(&act.sa_mask);
      ::sigaction(sig, &act, nullptr);
    }
  });
}

// A temporary file listed for the handler while it lives (no slot free: it is simply not listed).
class ListedTemp {
 public:
  explicit ListedTemp(std::string path) : path_(std::move(path)) {
    install_temp_cleanup();
    for (auto& s : g_temps) {
      const char* empty = nullptr;
      if (s.compare_exchange_strong(empty, path_.c_str())) {
        slot_ = &s;
        break;
      }
    }
  }
  ~ListedTemp() {
    if (slot_) slot_->store(nullptr);
  }
  ListedTemp(const ListedTemp&) = delete;
  ListedTemp& operator=(const ListedTemp&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::atomic<const char*>* slot_ = nullptr;
};

std::string temp_path_for(const std::string& path) {
  namespace fs = std::filesystem;
  fs::path target(path);
  fs::path dir = target.parent_path();
  const std::string file = target.filename().string(), tail = ".tmp." + std::to_string(::getpid());
  std::string name = "." + file + tail;
  // A name near the file system's limit (255 bytes) is still written: its temporary file takes a
  // part of it and a hash of the whole (it failed with "File name too long").
  constexpr size_t kLongestName = 255;
  if (name.size() > kLongestName) {
    char hash[20];
    const unsigned long long whole = fnv1a(kFnvOffset, file.data(), file.size());
    std::snprintf(hash, sizeof hash, "~%016llx", whole);
    name = "." + file.substr(0, kLongestName - 1 - std::strlen(hash) - tail.size()) + hash + tail;
  }
  return (dir / name).string();
}

std::string errno_text() { return std::strerror(errno); }

void rename_into_place(const std::string& tmp, const std::string& target, const std::string& path) {
  if (std::rename(tmp.c_str(), target.c_str()) != 0) {
    std::string why = errno_text();
    std::remove(tmp.c_str());
    fail_write(path, "cannot rename temporary file into place: " + why);
  }
}

// Where a write to `path` lands. Through its symbolic links: a link a pipeline keeps ("latest")
// stays a link, and the file it names is replaced. A stream where there is no file to replace: a
// pipe, a terminal, a descriptor of the process (/dev/stdout, /proc/self/fd/1, even where it is a
// file the shell opened, perhaps to append to), which a rename would have replaced by a file (and
// as root, /dev/stdout itself).
struct Destination {
  std::string file;
  bool stream = false;
};

Destination destination_of(const std::string& path) {
  namespace fs = std::filesystem;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) return {path, true};
  fs::path p(path);
  for (int hop = 0; hop < 40; ++hop) {  // the kernel's own bound on a chain of links
    std::error_code ec;
    const std::string folder = fs::weakly_canonical(fs::absolute(p, ec).parent_path(), ec).string();
    if (folder == "/proc" || folder.rfind("/proc/", 0) == 0) return {path, true};
    if (!fs::is_symlink(p, ec)) break;
    const fs::path to = fs::read_symlink(p, ec);
    if (ec) break;
    p = to.is_absolute() ? to : p.parent_path() / to;
  }
  return {p.string(), false};
}

// `bytes` written to `fd`; false with errno set where a write fails.
bool write_all(int fd, std::string_view bytes) {
  const char* p = bytes.data();
  size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    p += n;
    left -= static_cast<size_t>(n);
  }
  return true;
}

void write_stream(const std::string& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (fd < 0) fail_write(path, "cannot open output: " + errno_text());
  if (!write_all(fd, bytes)) {
    std::string why = errno_text();
    ::close(fd);
    fail_write(path, "write failed: " + why);
  }
  ::close(fd);
}

}  // namespace

void write_file_atomic(const std::string& path, std::string_view bytes) {
  const Destination to = destination_of(path);
  if (to.stream) return write_stream(path, bytes);
  const ListedTemp listed(temp_path_for(to.file));
  const std::string& tmp = listed.path();
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail_write(path, "cannot create output: " + errno_text());
  if (!write_all(fd, bytes)) {
    std::string why = errno_text();
    ::close(fd);
    std::remove(tmp.c_str());
    fail_write(path, "write failed: " + why);
  }
  if (::fsync(fd) != 0 && errno != EINVAL) {
    std::string why = errno_text();
    ::close(fd);
    std::remove(tmp.c_str());
    fail_write(path, "fsync failed: " + why);
  }
  if (::close(fd) != 0) {
    std::string why = errno_text();
    std::remove(tmp.c_str());
    fail_write(path, "close failed: " + why);
  }
  rename_into_place(tmp, to.file, path);
}

void fail_no_such_file(const std::string& path) {
  if (path.find('\\') != std::string::npos)
    fail_input(path, "cannot open: no such file (a Windows path? folders here are separated by '/', and '\\' is part "
                     "of a name)");
  fail_input(path, "cannot open: no such file");
}

std::string read_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail_no_such_file(path);
  if (std::filesystem::is_directory(path, ec)) fail_input(path, "is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail_input(path, std::string("cannot open: ") + errno_text());
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) fail_input(path, "read failed");
  return ss.str();
}

FolderLock::FolderLock(const std::string& dir, const std::function<void()>& waiting) {
  fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) return;  // the writes that follow say what is wrong with the folder
  if (::flock(fd_, LOCK_EX | LOCK_NB) == 0) return;
  if (errno == EWOULDBLOCK) {
    if (waiting) waiting();
    int held;
    while ((held = ::flock(fd_, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (held == 0) return;
  }
  ::close(fd_);  // no locks here (ENOLCK, EINVAL): written as before
  fd_ = -1;
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);  // closing lets go of the lock
}

}  // namespace spx
