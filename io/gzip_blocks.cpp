#include "io/gzip_blocks.hpp"

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <exception>
#include <vector>

#include "engine/error.hpp"
#include "engine/image/parallel_items.hpp"

namespace vb {
namespace {

/// Payload bytes per block: large enough that a fresh deflate dictionary per block costs little
/// ratio (256 KiB: under 1% larger files than one stream), small enough that the blocks in
/// flight (one per core, raw and deflated) stay about a megabyte.
constexpr std::size_t kBlockBytes = std::size_t(256) << 10;

struct Block {
  std::vector<unsigned char> raw, packed;
  std::uint32_t crc = 0;
  std::exception_ptr error;
};

/// Raw deflate of `in`, ended by a sync flush (the stream goes on in the next block) or, for the
/// last block, finished.
void deflate_block(Block& b, int level, bool last) {
  z_stream z{};
  if (deflateInit2(&z, level, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error("cannot start zlib's deflate");
  b.packed.resize(deflateBound(&z, uLong(b.raw.size())) + 16);
  z.next_in = b.raw.data();
  z.avail_in = uInt(b.raw.size());
  z.next_out = b.packed.data();
  z.avail_out = uInt(b.packed.size());
  const int rc = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
  const std::size_t produced = b.packed.size() - z.avail_out;
  deflateEnd(&z);
  if (rc != (last ? Z_STREAM_END : Z_OK) || z.avail_in != 0) throw Error("zlib's deflate failed");
  b.packed.resize(produced);
}

void put_le32(std::vector<unsigned char>& out, std::uint32_t v) {
  for (int s = 0; s < 32; s += 8) out.push_back(static_cast<unsigned char>(v >> s));
}

}  // namespace

bool write_blocks(std::FILE* file, const std::string& prefix, std::size_t payload_bytes, const FillBytes& fill,
                  BlockCompression compression, int level, const BlocksWritten& written) {
  const bool gzip = compression != BlockCompression::None, zlib = compression == BlockCompression::Zlib;
  const std::size_t total = prefix.size() + payload_bytes;
  const std::size_t block_count = std::max<std::size_t>(1, (total + kBlockBytes - 1) / kBlockBytes);
  const std::size_t in_flight = chunk_count(block_count, 1);
  std::vector<Block> blocks(std::min(in_flight, block_count));
  bool ok = true;
  if (zlib) {
    static const unsigned char header[2] = {0x78, 0x9c};  // deflate, 32 KiB window; (0x789c % 31) == 0
    ok = std::fwrite(header, 1, sizeof header, file) == sizeof header;
  } else if (gzip) {
    static const unsigned char header[10] = {0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3};  // deflate, no name, Unix
    ok = std::fwrite(header, 1, sizeof header, file) == sizeof header;
  }
  std::uint32_t crc = std::uint32_t(zlib ? adler32(0, nullptr, 0) : crc32(0, nullptr, 0));
  for (std::size_t first = 0; first < block_count; first += blocks.size()) {
    const std::size_t round = std::min(blocks.size(), block_count - first);
    for_each_index_dynamic(round, [&](std::size_t r) {
      Block& b = blocks[r];
      const std::size_t begin = (first + r) * kBlockBytes, end = std::min(total, begin + kBlockBytes);
      b.error = nullptr;
      try {
        b.raw.resize(end - begin);
        if (begin < prefix.size())
          std::memcpy(b.raw.data(), prefix.data() + begin, std::min(end, prefix.size()) - begin);
        const std::size_t from = std::max(begin, prefix.size());
        if (end > from) fill(from - prefix.size(), b.raw.data() + (from - begin), end - from);
        if (gzip) {
          b.crc = std::uint32_t(zlib ? adler32(1, b.raw.data(), uInt(b.raw.size()))
                                     : crc32(0, b.raw.data(), uInt(b.raw.size())));
          deflate_block(b, level, first + r + 1 == block_count);
        }
      } catch (...) {
        b.error = std::current_exception();
      }
    }, [](std::size_t) {});
    for (std::size_t r = 0; r < round; ++r) {
      Block& b = blocks[r];
      if (b.error) std::rethrow_exception(b.error);
      const std::vector<unsigned char>& bytes = gzip ? b.packed : b.raw;
      ok = ok && std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
      if (zlib) crc = std::uint32_t(adler32_combine(crc, b.crc, z_off_t(b.raw.size())));
      else if (gzip) crc = std::uint32_t(crc32_combine(crc, b.crc, z_off_t(b.raw.size())));
    }
    if (written) written(double(first + round) / double(block_count));
  }
  if (zlib) {
    const unsigned char trailer[4] = {static_cast<unsigned char>(crc >> 24), static_cast<unsigned char>(crc >> 16),
                                      static_cast<unsigned char>(crc >> 8), static_cast<unsigned char>(crc)};
    ok = ok && std::fwrite(trailer, 1, sizeof trailer, file) == sizeof trailer;  // Adler-32, big-endian
  } else if (gzip) {
    std::vector<unsigned char> trailer;
    put_le32(trailer, crc);
    put_le32(trailer, std::uint32_t(total & 0xffffffffu));
    ok = ok && std::fwrite(trailer.data(), 1, trailer.size(), file) == trailer.size();
  }
  return ok;
}

}  // namespace vb
