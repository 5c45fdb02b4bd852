/// libFuzzer target: vb::parse_scene_text on arbitrary text, the strict TOML scene parser with its
/// range checks, "did you mean" hints and label resolution. Built and run by scripts/fuzz.sh;
/// seeds in tests/fuzz/corpus/scene/ (the bundled scenes). vb::Error is the expected outcome for
/// bad input; any other exception, a crash or a sanitizer report (float-cast-overflow included)
/// is a finding. With VB_FUZZ_VERBOSE=1 each call's outcome is printed.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "engine/error.hpp"
#include "io/scene_file.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Relative data paths resolve against the scene's folder: a private one, so that a path the
  // fuzzer makes up never names a real file outside it.
  const std::string source = (vb::fuzz::work_dir("scene_file") / "scene.toml").string();
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const vb::Scene scene = vb::parse_scene_text(text, source);
    if (vb::fuzz::verbose()) std::fprintf(stderr, "parsed: %zu shapes\n", scene.model.shapes.size());
  } catch (const vb::Error& e) {
    if (vb::fuzz::verbose()) std::fprintf(stderr, "vb::Error: %s\n", e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_scene_file: unexpected exception: %s\n", e.what());
    std::abort();
  }
  return 0;
}
