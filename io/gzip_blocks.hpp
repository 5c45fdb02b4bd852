#pragma once
/// Large outputs written block by block on all the host's cores: each block is produced (filled
/// from the caller's data, converted to the file's layout) and deflated on its own thread, and
/// the blocks are written in order, so no copy of the whole payload is ever held. Compressed
/// output is one gzip member (RFC 1952): each block is a raw deflate stream ended by a sync flush
/// (the last by the final block), the CRC-32s combined, as pigz writes it, so every gzip reader
/// (zlib, nifti_clib, ITK, Python's gzip) reads it as an ordinary .gz file.
#include <cstddef>
#include <cstdio>
#include <functional>
#include <string>

namespace vb {

/// Fills `out[0, size)` with bytes [offset, offset + size) of the payload. May throw: the
/// first exception is rethrown by write_blocks once the blocks in flight are done.
using FillBytes = std::function<void(std::size_t offset, unsigned char* out, std::size_t size)>;

/// Writes `prefix` followed by `payload_bytes` bytes from `fill` to `file`, gzip-compressed at
/// zlib `level` when `gzip`, else as they are. Returns false on a write error.
bool write_blocks(std::FILE* file, const std::string& prefix, std::size_t payload_bytes, const FillBytes& fill,
                  bool gzip, int level = 6);

}  // namespace vb
