#include "engine/sim/program_cache.hpp"

#include <openssl/evp.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <fstream>
#include <mutex>
#include <sstream>
#include <system_error>

namespace vb {
namespace {

namespace fs = std::filesystem;

constexpr const char* kMagic = "voxbreast-program-cache 1";
constexpr const char* kEntrySuffix = ".vbprog";
constexpr const char* kTempMarker = ".vbprog.tmp.";

bool is_set(const char* s) { return s != nullptr && *s != '\0'; }

std::mutex folder_mutex;
fs::path& folder() {
  static fs::path dir;
  return dir;
}

fs::path entry_path(const fs::path& dir, const std::string& key) { return dir / (sha256_hex(key) + kEntrySuffix); }

std::string hex_digest(const unsigned char* data, std::size_t size) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  EVP_Digest(data, size, digest.data(), &length, EVP_sha256(), nullptr);
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += kHex[digest[i] >> 4];
    out += kHex[digest[i] & 15];
  }
  return out;
}

bool is_entry(const fs::path& p) { return p.extension() == kEntrySuffix && p.stem().string().size() == 64; }

bool is_cache_file(const fs::path& p) {
  return is_entry(p) || p.filename().string().find(kTempMarker) != std::string::npos;
}

}  // namespace

void set_program_cache_dir(fs::path dir) {
  const std::lock_guard<std::mutex> lock(folder_mutex);
  folder() = std::move(dir);
}

fs::path program_cache_dir() {
  const std::lock_guard<std::mutex> lock(folder_mutex);
  return folder();
}

fs::path default_program_cache_dir(const char* override_dir, const char* xdg_cache_home, const char* home) {
  if (is_set(override_dir)) return std::string(override_dir) == "off" ? fs::path() : fs::path(override_dir);
  if (is_set(xdg_cache_home)) return fs::path(xdg_cache_home) / "voxbreast";
  if (is_set(home)) return fs::path(home) / ".cache" / "voxbreast";
  return {};
}

std::string sha256_hex(const std::string& bytes) {
  return hex_digest(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
}

std::optional<std::vector<unsigned char>> read_program_cache(const fs::path& dir, const std::string& key) {
  std::ifstream in(entry_path(dir, key), std::ios::binary);
  if (!in) return std::nullopt;
  std::string magic, header;
  if (!std::getline(in, magic) || magic != kMagic || !std::getline(in, header)) return std::nullopt;
  std::istringstream fields(header);
  std::size_t key_size = 0, binary_size = 0;
  std::string checksum;
  if (!(fields >> key_size >> binary_size >> checksum) || key_size != key.size()) return std::nullopt;
  std::string stored_key(key_size, '\0');
  if (!in.read(stored_key.data(), std::streamsize(key_size)) || stored_key != key) return std::nullopt;
  std::vector<unsigned char> binary(binary_size);
  if (!in.read(reinterpret_cast<char*>(binary.data()), std::streamsize(binary_size))) return std::nullopt;
  if (in.peek() != std::char_traits<char>::eof()) return std::nullopt;  // longer than it says
  if (hex_digest(binary.data(), binary.size()) != checksum) return std::nullopt;
  return binary;
}

bool write_program_cache(const fs::path& dir, const std::string& key, const std::vector<unsigned char>& binary) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return false;
  const fs::path target = entry_path(dir, key);
  // unique per process and per call, in the entry's folder so that the rename stays on one file system
  static std::atomic<unsigned> counter{0};
  const fs::path temp = dir / (target.stem().string() + kTempMarker + std::to_string(::getpid()) + "." +
                               std::to_string(counter.fetch_add(1)));
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    out << kMagic << "\n"
        << key.size() << " " << binary.size() << " " << hex_digest(binary.data(), binary.size()) << "\n"
        << key;
    out.write(reinterpret_cast<const char*>(binary.data()), std::streamsize(binary.size()));
    out.close();
    if (!out) {
      fs::remove(temp, ec);
      return false;
    }
  }
  fs::rename(temp, target, ec);
  if (ec) {
    fs::remove(temp, ec);
    return false;
  }
  return true;
}

ProgramCacheUsage program_cache_usage(const fs::path& dir) {
  ProgramCacheUsage usage;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec) || !is_entry(it->path())) continue;
    ++usage.entries;
    usage.bytes += it->file_size(ec);
  }
  return usage;
}

std::size_t clear_program_cache(const fs::path& dir) {
  std::vector<fs::path> doomed;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec) && is_cache_file(it->path())) doomed.push_back(it->path());
  std::size_t removed = 0;
  for (const auto& p : doomed) removed += fs::remove(p, ec) ? 1 : 0;
  return removed;
}

}  // namespace vb
