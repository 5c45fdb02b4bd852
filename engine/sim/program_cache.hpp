#pragma once
/// On-disk cache of built OpenCL program binaries, shared by every process of a user.
///
/// build_program() (engine/sim/opencl_runtime.hpp) looks a program up here before building it from
/// source and stores what it builds, keyed by the full source, the build options and the platform,
/// device and driver names and versions; with $VOXBREAST_DUMP_KERNELS set it always builds from
/// source, so that the dump is complete.
///
/// An entry is named by the SHA-256 of its key (the full program source, the build options, and the
/// platform, device and driver names and versions) and holds the key itself, the binary's length and
/// the binary's SHA-256: a read returns the binary only when all three match, so a truncated, corrupt
/// or colliding entry reads as a miss and is rebuilt. Writes go to a temporary file in the same folder
/// that is renamed over the entry, so processes filling the cache at once (MPI ranks, parallel tests)
/// each see either no entry or a whole one.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vb {

/// The folder build_program() keeps programs in, for every context of this process; empty (the
/// default): every process builds its programs from source. The app sets it once at start-up from
/// its own settings (default_program_cache_dir), before any program is built.
void set_program_cache_dir(std::filesystem::path dir);
std::filesystem::path program_cache_dir();

/// The folder for the cache: `override_dir` when set (VOXBREAST_CACHE_DIR), else
/// `xdg_cache_home`/voxbreast, else `home`/.cache/voxbreast; empty (no disk cache) when
/// `override_dir` is "off" or none is set. The caller (the app) reads the environment; null pointers
/// and empty strings count as unset.
std::filesystem::path default_program_cache_dir(const char* override_dir, const char* xdg_cache_home,
                                                const char* home);

/// Lowercase hexadecimal SHA-256 of `bytes`.
std::string sha256_hex(const std::string& bytes);

/// The entry for `key` in `dir`, when present and whole (key, length and checksum match).
std::optional<std::vector<unsigned char>> read_program_cache(const std::filesystem::path& dir,
                                                             const std::string& key);

/// Stores `binary` for `key` in `dir` (created when missing) by an atomic rename. Returns false, and
/// leaves no temporary file, when the folder cannot be written: the cache only saves time.
bool write_program_cache(const std::filesystem::path& dir, const std::string& key,
                         const std::vector<unsigned char>& binary);

/// Entries in the cache folder and their total size.
struct ProgramCacheUsage {
  std::size_t entries = 0;
  std::uintmax_t bytes = 0;
};
ProgramCacheUsage program_cache_usage(const std::filesystem::path& dir);

/// Deletes every entry (and stray temporary file) in the folder; returns how many files it removed.
/// Other files in the folder are left alone.
std::size_t clear_program_cache(const std::filesystem::path& dir);

}  // namespace vb
