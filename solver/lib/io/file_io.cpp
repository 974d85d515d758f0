#include "io/file_io.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <thread>

namespace enamel {

std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc) {
  const auto* p = static_cast<const Bytef*>(data);
  uLong c = crc;
  while (n > 0) {  // zlib takes at most 4 GiB - 1 at a time
    const uInt chunk = static_cast<uInt>(std::min<std::size_t>(n, 1u << 30));
    c = ::crc32(c, p, chunk);
    p += chunk;
    n -= chunk;
  }
  return static_cast<std::uint32_t>(c);
}

namespace {

bool isDiskFull(int err) { return err == ENOSPC || err == EDQUOT || err == EFBIG; }

[[noreturn]] void failWrite(const std::string& what, const std::string& tmp, std::size_t n, int err, int fd) {
  if (fd >= 0) ::close(fd);
  ::unlink(tmp.c_str());
  const std::string reason = std::strerror(err);
  throw WriteError("cannot write " + what + " '" + tmp + "' (" + std::to_string(n) + " bytes): " + reason +
                       (isDiskFull(err) ? " (disk full or quota reached: free that much space and run again with "
                                          "--resume; the files written before are kept)"
                                        : ""),
                   isDiskFull(err));
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::string& bytes, const std::string& what) {
  const std::string tmp = path + ".tmp";
  const std::size_t n = bytes.size();
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) failWrite(what, tmp, n, errno, -1);
  for (std::size_t done = 0; done < n;) {
    const ssize_t w = ::write(fd, bytes.data() + done, n - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) failWrite(what, tmp, n, w < 0 ? errno : ENOSPC, fd);
    done += static_cast<std::size_t>(w);
  }
  // A file system may accept the bytes into its cache and refuse them only when they are flushed (NFS,
  // quotas), so the write counts only after fsync and close succeed.
  if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) failWrite(what, tmp, n, errno, fd);
  if (::close(fd) != 0) failWrite(what, tmp, n, errno, -1);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) failWrite(what, tmp, n, errno, -1);
}

namespace {

std::string lockFileOf(const std::string& dir) { return dir + "/" + DirectoryLock::kFileName; }

// The lock file's text, read through `fd` (at most a line).
std::string readHolder(int fd) {
  char buf[256];
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  std::string s(buf, n > 0 ? static_cast<std::size_t>(n) : 0);
  return s.substr(0, s.find('\n'));
}

// "pid <pid> host <host> since <UTC time>": who holds the lock, written once it is held.
std::string holderLine() {
  char host[256] = "unknown";
  if (::gethostname(host, sizeof host - 1) != 0) std::snprintf(host, sizeof host, "unknown");
  host[sizeof host - 1] = '\0';
  char when[32] = "";
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  if (gmtime_r(&now, &utc)) std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return "pid " + std::to_string(::getpid()) + " host " + host + " since " + when + "\n";
}

// flock, retried every 0.2 s until waitSeconds have passed: 0 when locked, else the last errno.
int lockWithin(int fd, double waitSeconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(std::max(0.0, waitSeconds));
  while (true) {
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return 0;
    const int err = errno;
    if (err == EINTR) continue;
    if (err != EWOULDBLOCK || std::chrono::steady_clock::now() >= until) return err;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

}  // namespace

DirectoryLock::DirectoryLock(const std::string& dir, double waitSeconds) {
  const std::string path = lockFileOf(dir);
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0)
    throw WriteError("cannot create the run directory's lock file '" + path + "': " + std::strerror(errno), false);
  const int err = lockWithin(fd_, waitSeconds);
  if (err == EWOULDBLOCK) {
    const std::string holder = readHolder(fd_);
    ::close(fd_);
    fd_ = -1;
    throw DirectoryLocked("run directory '" + dir + "' is in use by another run (" +
                          (holder.empty() ? "holder not yet written" : holder) + ", lock file " + path + ")" +
                          (waitSeconds > 0 ? ", still after waiting " + std::to_string(std::lround(waitSeconds)) + " s"
                                           : "") +
                          ": refused, nothing in it was changed; wait for that run to end or use another --out");
  }
  if (err != 0) {  // a file system without flock (a Lustre mount without -o flock, ...): run unlocked
    why_ = "cannot lock '" + path + "' (flock: " + std::strerror(err) + ")";
    return;
  }
  held_ = true;
  const std::string line = holderLine();
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, line.data(), line.size(), 0) != static_cast<ssize_t>(line.size()))
    why_ = "the lock file '" + path + "' does not say who holds it (" + std::strerror(errno) + ")";
}

DirectoryLock::~DirectoryLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the last descriptor releases the lock
}

std::string directoryLockHolder(const std::string& dir) {
  const int fd = ::open(lockFileOf(dir).c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return "";
  const std::string holder = readHolder(fd);
  ::close(fd);
  return holder;
}

}  // namespace enamel
