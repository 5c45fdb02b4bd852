#include "apps/view_folder.hpp"

#include <algorithm>
#include <fstream>
#include <toml++/toml.h>

#include "engine/error.hpp"

namespace vb::app {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxFiles = 20000;

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// The types the page reads. Vector fields (the DVFs) are left out: the page shows their
/// magnitude from displacement_mm.nii.gz, and they are the folder's largest images.
bool viewable(const std::string& name) {
  if (name.rfind("dvf", 0) == 0) return false;
  for (const char* ext : {".json", ".csv", ".vtp", ".pvd", ".png", ".toml", ".nii.gz", ".nii"})
    if (ends_with(name, ext)) return true;
  return false;
}

/// Folders whose content the page never reads: case folders of sweeps and batches (their
/// numbers are in the sweep's tables) and DICOM series (the page reads the NIfTI copies).
bool skipped_folder(const std::string& name) {
  return name == "cases" || name == "warped_ct_dicom" || name == "dicom" || name == "checkpoints";
}

bool is_inside(const fs::path& root, const fs::path& canonical) {
  auto r = root.begin(), c = canonical.begin();
  for (; r != root.end(); ++r, ++c)
    if (c == canonical.end() || *r != *c) return false;
  return true;
}

void collect(const fs::path& root, const fs::path& dir, int depth, std::vector<std::string>& out) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end && out.size() < kMaxFiles; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name[0] == '.') continue;  // staging folders, temporary files, manifests
    std::error_code canonical_ec;
    const fs::path target = fs::canonical(it->path(), canonical_ec);
    if (canonical_ec || !is_inside(root, target)) continue;  // a link out of the folder
    if (fs::is_directory(target, canonical_ec)) {
      if (depth < 2 && !skipped_folder(name)) collect(root, it->path(), depth + 1, out);
    } else if (fs::is_regular_file(target, canonical_ec) && viewable(name)) {
      out.push_back(it->path().lexically_relative(root).generic_string());
    }
  }
}

bool has(const std::vector<std::string>& files, const std::string& name) {
  return std::binary_search(files.begin(), files.end(), name);
}

std::string folder_kind(const fs::path& root, const std::vector<std::string>& files) {
  const auto exists = [&](const char* name) { return fs::exists(root / name); };
  if (has(files, "probe_summary.json") || has(files, "probe_curves.csv")) return "probe";
  if (has(files, "haptic_summary.json")) return "haptic";
  if (has(files, "fit_curve.json")) return "fit_curve";
  if (has(files, "bench.json") || has(files, "bench.csv") || has(files, "throughput.csv")) return "bench";
  if (has(files, "regions.csv") || has(files, "history.csv")) return "fit";
  if (fs::is_directory(root / "cases") && (has(files, "metrics.csv") || has(files, "sweep.json"))) return "sweep";
  if (has(files, "summary.json") && (exists("result.h5") || has(files, "surface.vtp"))) return "simulate";
  if (has(files, "ct.nii.gz") && has(files, "labels.nii.gz")) return "phantom";
  return "unknown";
}

/// The input CT named by the scene that summary.json records (model.image, relative to the
/// scene file), when it is a NIfTI file or a folder (a DICOM series).
fs::path scene_input_ct(const fs::path& root, std::string& note) {
  std::ifstream in(root / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
  if (summary.is_discarded() || !summary.contains("scene") || !summary["scene"].is_string()) return {};
  const fs::path scene = summary["scene"].get<std::string>();
  std::error_code ec;
  if (!fs::is_regular_file(scene, ec)) {
    note = "the scene '" + scene.string() + "' that summary.json names is not here: pass --ct to show the input CT";
    return {};
  }
  try {
    const toml::table table = toml::parse_file(scene.string());
    const auto image = table["model"]["image"].value<std::string>();
    if (!image) return {};  // an analytic model: no CT
    fs::path ct = *image;
    if (ct.is_relative()) ct = scene.parent_path() / ct;
    if (fs::exists(ct, ec)) return ct;
    note = "the input CT '" + ct.string() + "' is not here: pass --ct to show it";
  } catch (const toml::parse_error&) {
    note = "the scene '" + scene.string() + "' could not be read: pass --ct to show the input CT";
  }
  return {};
}

}  // namespace

ViewFolder scan_view_folder(const fs::path& dir, const fs::path& ct_override) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw Error("'" + dir.string() + "' is not a folder (give an output folder of a VoxBreast run)");
  ViewFolder folder;
  folder.root = fs::canonical(dir, ec);
  if (ec) throw Error("cannot read folder '" + dir.string() + "': " + ec.message());
  collect(folder.root, folder.root, 0, folder.files);
  std::sort(folder.files.begin(), folder.files.end());
  folder.kind = folder_kind(folder.root, folder.files);
  if (!ct_override.empty()) {
    if (!fs::exists(ct_override, ec)) throw Error("--ct '" + ct_override.string() + "' does not exist");
    folder.input_ct = ct_override;
  } else if (folder.kind == "simulate" && has(folder.files, "warped_ct.nii.gz")) {
    folder.input_ct = scene_input_ct(folder.root, folder.input_ct_note);
  }
  return folder;
}

nlohmann::json view_manifest(const ViewFolder& folder) {
  nlohmann::json files = nlohmann::json::array();
  for (const std::string& f : folder.files) files.push_back("data/" + f);
  return {{"kind", folder.kind},
          {"title", folder.root.filename().string()},
          {"files", files},
          {"input_ct", folder.input_ct.empty() ? nlohmann::json(nullptr) : nlohmann::json("input/ct.nii.gz")},
          {"input_ct_note", folder.input_ct_note}};
}

std::optional<fs::path> resolve_inside(const fs::path& root, const std::string& relative) {
  if (relative.empty() || relative.front() == '/' || relative.find('\0') != std::string::npos ||
      relative.find('\\') != std::string::npos)
    return std::nullopt;
  std::size_t start = 0;
  while (start <= relative.size()) {
    const std::size_t slash = std::min(relative.find('/', start), relative.size());
    const std::string segment = relative.substr(start, slash - start);
    if (segment == "." || segment == ".." || segment.empty()) return std::nullopt;
    start = slash + 1;
  }
  std::error_code ec;
  const fs::path canonical = fs::canonical(root / relative, ec);
  if (ec || !is_inside(root, canonical) || !fs::is_regular_file(canonical, ec)) return std::nullopt;
  return canonical;
}

}  // namespace vb::app
