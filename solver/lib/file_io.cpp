#include "file_io.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

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

}  // namespace enamel
