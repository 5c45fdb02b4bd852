#pragma once
/// Large outputs written block by block on all the host's cores: each block is produced (filled
/// from the caller's data, converted to the file's layout) and deflated on its own thread, and
/// the blocks are written in order, so no copy of the whole payload is ever held. Compressed
/// output is one gzip member (RFC 1952) or zlib stream (RFC 1950): each block is a raw deflate
/// stream ended by a sync flush (the last by the final block), the CRC-32s (or Adler-32s)
/// combined, as pigz writes it, so every reader (zlib, nifti_clib, ITK, Python's gzip and zlib)
/// reads it as an ordinary compressed file.
#include <cstddef>
#include <cstdio>
#include <functional>
#include <string>

namespace vb {

/// Fills `out[0, size)` with bytes [offset, offset + size) of the payload. May throw: the
/// first exception is rethrown by write_blocks once the blocks in flight are done.
using FillBytes = std::function<void(std::size_t offset, unsigned char* out, std::size_t size)>;

/// How the bytes are stored: as they are, as one gzip member (RFC 1952: .gz, .nii.gz), or as
/// one zlib stream (RFC 1950: MetaImage's CompressedData).
enum class BlockCompression { None, Gzip, Zlib };

/// Told the fraction of the blocks written, in [0, 1], from the calling thread.
using BlocksWritten = std::function<void(double fraction)>;

/// Writes `prefix` followed by `payload_bytes` bytes from `fill` to `file`, compressed (prefix
/// included) at zlib `level` as `compression` says; `written` after each round of blocks.
/// Returns false on a write error.
bool write_blocks(std::FILE* file, const std::string& prefix, std::size_t payload_bytes, const FillBytes& fill,
                  BlockCompression compression, int level = 6, const BlocksWritten& written = {});
/// The same, gzip-compressed when `gzip`.
inline bool write_blocks(std::FILE* file, const std::string& prefix, std::size_t payload_bytes, const FillBytes& fill,
                         bool gzip, int level = 6, const BlocksWritten& written = {}) {
  return write_blocks(file, prefix, payload_bytes, fill, gzip ? BlockCompression::Gzip : BlockCompression::None, level,
                      written);
}

}  // namespace vb
