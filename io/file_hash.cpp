#include "io/file_hash.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <vector>

#include "engine/error.hpp"

namespace fs = std::filesystem;

namespace vb {
namespace {

using Digest = std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)>;

void add_file(EVP_MD_CTX* digest, const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  require(bool(in), "cannot read file", file.string(), "check that the scene's input files exist and are readable");
  std::vector<char> buffer(std::size_t(1) << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    EVP_DigestUpdate(digest, buffer.data(), std::size_t(in.gcount()));
  }
  require(in.eof(), "cannot read file", file.string());
}

}  // namespace

std::string content_sha256(const std::string& path) {
  Digest digest(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  require(digest && EVP_DigestInit_ex(digest.get(), EVP_sha256(), nullptr) == 1, "cannot start SHA-256", path);
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    std::vector<fs::path> files;
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(path, ec))
      if (e.is_regular_file(ec)) files.push_back(e.path());
    require(!ec, "cannot list folder: " + ec.message(), path);
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      const std::string name = f.lexically_relative(path).string();
      EVP_DigestUpdate(digest.get(), name.c_str(), name.size() + 1);  // with its terminating zero
      add_file(digest.get(), f);
    }
  } else {
    add_file(digest.get(), path);
  }
  std::array<unsigned char, EVP_MAX_MD_SIZE> bytes{};
  unsigned int size = 0;
  require(EVP_DigestFinal_ex(digest.get(), bytes.data(), &size) == 1, "cannot finish SHA-256", path);
  static const char* hex = "0123456789abcdef";
  std::string text;
  for (unsigned int i = 0; i < size; ++i) {
    text += hex[bytes[i] >> 4];
    text += hex[bytes[i] & 15];
  }
  return text;
}

}  // namespace vb
