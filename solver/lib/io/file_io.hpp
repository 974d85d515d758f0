#pragma once
// Whole-file writes that survive a full disk, and the checksum that lets a reader prove a file is the one
// written. Both the checkpoint (checkpoint.cpp) and the result file (output.cpp) are built in memory and
// written through writeFileAtomically: the bytes go to `path.tmp`, are flushed to the disk, and renamed over
// `path`, so a run stopped or a disk filled at any moment leaves the previous complete file, and a failed write
// removes its temporary file and says which file and how many bytes it needed. A run directory belongs to one
// run at a time: DirectoryLock holds an exclusive lock on it for the run's whole life.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace enamel {

/// A write that did not complete. `diskFull` when the file system or a quota ran out of space (ENOSPC,
/// EDQUOT, EFBIG from a file-size limit); otherwise the file or directory could not be written at all.
struct WriteError : std::runtime_error {
  WriteError(const std::string& what, bool full) : std::runtime_error(what), diskFull(full) {}
  bool diskFull;
};

/// CRC-32 (ISO-HDLC: the polynomial of zlib, PNG and Python's zlib.crc32) of `n` bytes, continuing from `crc`
/// (0 to start). Python checks the result file's checksum with zlib.crc32, so one algorithm serves both sides.
std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc = 0);

/// Write `bytes` to `path.tmp`, fsync it and rename it over `path`. On any failure the temporary file is
/// removed, `path` is left as it was, and WriteError says "<what> '<path.tmp>' (<n> bytes): <reason>".
void writeFileAtomically(const std::string& path, const std::string& bytes, const std::string& what);

/// Another process holds a run directory's lock (DirectoryLock); the message names the directory and the
/// holder's pid and host, as the holder wrote them into the lock file.
struct DirectoryLocked : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// An exclusive lock on a run directory for as long as this object lives: flock(2) on DIR/.lock through an open
/// descriptor, so the kernel drops it when the process ends, however it ends (a killed run leaves no stale
/// lock). The lock file is created if needed and, once locked, holds "pid <pid> host <host> since <UTC time>".
/// Waits up to waitSeconds for the holder to let go (0: not at all), then throws DirectoryLocked; WriteError
/// when the lock file cannot be created. A file system without locks (flock fails with another error than
/// EWOULDBLOCK) gives an unlocked object: held() is false and why() says why.
class DirectoryLock {
 public:
  static constexpr const char* kFileName = ".lock";
  DirectoryLock(const std::string& dir, double waitSeconds);
  ~DirectoryLock();
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;
  bool held() const { return held_; }
  const std::string& why() const { return why_; }

 private:
  int fd_ = -1;
  bool held_ = false;
  std::string why_;
};

/// Who holds the lock of `dir`, as its lock file says ("pid 123 host node7 since <start, UTC, ISO 8601>"), or
/// "" when the file is absent or empty.
std::string directoryLockHolder(const std::string& dir);

}  // namespace enamel
