#pragma once
// Whole-file writes that survive a full disk, and the checksum that lets a reader prove a file is the one
// written. Both the checkpoint (checkpoint.cpp) and the result file (output.cpp) are built in memory and
// written through writeFileAtomically: the bytes go to `path.tmp`, are flushed to the disk, and renamed over
// `path`, so a run stopped or a disk filled at any moment leaves the previous complete file, and a failed write
// removes its temporary file and says which file and how many bytes it needed.
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

}  // namespace enamel
