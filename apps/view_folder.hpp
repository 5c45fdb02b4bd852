#pragma once
/// What `voxbreast view` shows of an output folder: its kind, the files the page may read, and
/// the check that keeps every served path inside the folder (docs/VIEW.md).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace vb::app {

/// An output folder as the page sees it.
struct ViewFolder {
  std::filesystem::path root;  ///< canonical path of the output folder
  /// "simulate", "sweep", "fit", "probe", "bench", "haptic", "fit_curve", "phantom" or "unknown"
  std::string kind;
  /// files the page may fetch, relative to root with '/' separators, sorted: the viewable
  /// types only (JSON, CSV, VTP, PVD, NIfTI scalar images, PNG, TOML), regular files inside root
  std::vector<std::string> files;
  /// the run's input CT when the page can show it: a NIfTI file, or a DICOM folder the server
  /// converts to NIfTI; empty when unknown or not found
  std::filesystem::path input_ct;
  std::string input_ct_note;  ///< why there is no input CT to show (shown on the page), or ""
};

/// Scans `dir` (which must be a folder): kind, viewable files (at most 20000, hidden entries
/// and the DICOM series skipped, symbolic links followed only when they stay inside the
/// folder) and the input CT (`ct_override` when not empty, else the scene named in
/// summary.json). Throws vb::Error when `dir` is not a readable folder.
ViewFolder scan_view_folder(const std::filesystem::path& dir, const std::filesystem::path& ct_override = {});

/// The page's manifest: kind, title, files (each as the URL path the page fetches: "data/<file>"),
/// and "input_ct" ("input/ct.nii.gz" or null) with its note.
nlohmann::json view_manifest(const ViewFolder& folder);

/// The file a request path names inside `root`, or nothing when it must be refused: a path that
/// is empty, absolute, holds a NUL or backslash, a "." or ".." segment, or that resolves (links
/// followed) outside `root` (canonical). `relative` is already percent-decoded.
std::optional<std::filesystem::path> resolve_inside(const std::filesystem::path& root, const std::string& relative);

}  // namespace vb::app
