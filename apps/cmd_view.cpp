// voxbreast view — an output folder's meshes, CT slices and numbers in the browser (docs/VIEW.md).
//   voxbreast view out/phantom                      # prints http://127.0.0.1:8642/
//   voxbreast view out/phantom --port 0 --open      # any free port, opens the browser
//   voxbreast view out/phantom --host 0.0.0.0       # reachable from other machines, with a token
//   voxbreast view out/phantom --export report/     # a static folder to zip and send
// The server (civetweb) answers GET and HEAD only, with the page's assets, the folder's viewable
// files and a manifest of them; nothing else on the machine is reachable through it.
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <set>

#include "apps/commands.hpp"
#include "apps/view_folder.hpp"
#include "apps/web_server.hpp"
#include "engine/error.hpp"
#include "io/dicom_io.hpp"
#include "io/nifti_io.hpp"

namespace vb::app {
namespace fs = std::filesystem;

namespace {
using namespace web;

struct ViewOptions {
  std::string out_dir;
  int port = 8642;
  std::string host = "127.0.0.1";
  bool open = false;
  std::string export_dir;
  std::string ct;
};

/// The input CT as the page fetches it: a NIfTI file as it is, a DICOM series converted once
/// into `scratch` (int16 HU on the series' grid, which is the warped CT's grid).
fs::path input_ct_nifti(const fs::path& input_ct, const fs::path& scratch) {
  std::error_code ec;
  if (fs::is_regular_file(input_ct, ec)) return fs::canonical(input_ct);
  fs::create_directories(scratch);
  const fs::path converted = scratch / "ct.nii.gz";
  write_nifti(converted.string(), read_dicom_series(input_ct.string()), NiftiType::Int16);
  return converted;
}

std::string input_ct_url(const fs::path& file) {
  return file.extension() == ".nii" ? "input/ct.nii" : "input/ct.nii.gz";
}

struct Server {
  fs::path root;  ///< the output folder (canonical), fixed at start: read by request threads
  fs::path web_dir;
  fs::path ct_override;
  fs::path ct_file;  ///< the input CT as NIfTI, or empty
  std::string ct_note;  ///< why the input CT is not shown, when reading it failed
  std::string token;  ///< required on every request when not empty
  std::mutex mutex;   ///< guards folder and allowed: the manifest request rescans the folder
  ViewFolder folder;
  std::set<std::string> allowed;

  nlohmann::json rescan() {
    std::lock_guard lock(mutex);
    folder = scan_view_folder(root, ct_override);
    if (!ct_note.empty()) folder.input_ct_note = ct_note;
    allowed = {folder.files.begin(), folder.files.end()};
    nlohmann::json manifest = view_manifest(folder);
    manifest["input_ct"] = ct_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(input_ct_url(ct_file));
    return manifest;
  }
  bool is_allowed(const std::string& relative) {
    std::lock_guard lock(mutex);
    return allowed.count(relative) > 0;
  }
};

int handle_request(mg_connection* conn, void* data) {
  auto& server = *static_cast<Server*>(data);
  const mg_request_info* ri = mg_get_request_info(conn);
  const std::string method = ri->request_method ? ri->request_method : "";
  if (method != "GET" && method != "HEAD") return send_text(conn, 405, "text/plain", "only GET and HEAD\n");
  std::string cookie;
  if (!server.token.empty()) {
    if (!same_token(request_token(conn), server.token))
      return send_text(conn, 401, "text/plain", "a valid token is required (the URL that voxbreast view printed)\n");
    cookie = token_cookie(server.token);
  }
  // local_uri_raw is percent-decoded but not cleaned of dot segments: resolve_inside refuses them.
  const std::string path = ri->local_uri_raw ? ri->local_uri_raw : "";
  if (path.empty() || path[0] != '/') return send_text(conn, 400, "text/plain", "bad request\n");
  if (path == "/") return send_file(conn, server.web_dir / "index.html", cookie);
  if (path == "/manifest.json") {
    try {
      return send_text(conn, 200, "application/json", server.rescan().dump(), cookie);
    } catch (const std::exception& e) {
      return send_text(conn, 500, "text/plain", std::string(e.what()) + "\n");
    }
  }
  if (path.rfind("/input/", 0) == 0) {
    if (server.ct_file.empty() || path.substr(1) != input_ct_url(server.ct_file))
      return send_text(conn, 404, "text/plain", "not found\n");
    return send_file(conn, server.ct_file, cookie);
  }
  if (path.rfind("/data/", 0) == 0) {
    const std::string relative = path.substr(6);
    const auto file = resolve_inside(server.root, relative);
    if (!file) return send_text(conn, 403, "text/plain", "refused: not a file inside the output folder\n");
    if (!server.is_allowed(relative)) return send_text(conn, 404, "text/plain", "not a file the page shows\n");
    return send_file(conn, *file, cookie);
  }
  const auto asset = resolve_inside(server.web_dir, path.substr(1));
  if (!asset) return send_text(conn, 404, "text/plain", "not found\n");
  return send_file(conn, *asset, cookie);
}

void copy_file_into(const fs::path& from, const fs::path& to) {
  fs::create_directories(to.parent_path());
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
}

int export_folder(const ViewOptions& o, Server& server) {
  const fs::path dir = o.export_dir;
  std::error_code ec;
  if (fs::exists(dir, ec) && !(fs::is_directory(dir, ec) && fs::is_empty(dir, ec)))
    throw Error("--export '" + dir.string() + "' exists and is not an empty folder");
  fs::create_directories(dir, ec);
  if (ec) throw Error("cannot create '" + dir.string() + "': " + ec.message());
  std::size_t count = 0;
  for (const auto& entry : fs::recursive_directory_iterator(server.web_dir)) {
    if (!entry.is_regular_file()) continue;
    copy_file_into(entry.path(), dir / entry.path().lexically_relative(server.web_dir));
    ++count;
  }
  nlohmann::json manifest = server.rescan();
  for (const std::string& file : server.folder.files) {
    copy_file_into(server.folder.root / file, dir / "data" / file);
    ++count;
  }
  if (!server.ct_file.empty()) {
    copy_file_into(server.ct_file, dir / input_ct_url(server.ct_file));
    ++count;
  }
  manifest["exported"] = true;
  std::ofstream(dir / "manifest.json") << manifest.dump(1) << "\n";
  std::printf("voxbreast view: wrote %zu files to '%s' (%s); to look at it: cd '%s' && python3 -m http.server 8000, "
              "then open http://127.0.0.1:8000/\n",
              count + 1, dir.string().c_str(), server.folder.kind.c_str(), dir.string().c_str());
  return 0;
}

}  // namespace

Command add_view(CLI::App& app) {
  auto* sub = app.add_subcommand("view", "Show an output folder (simulate, sweep, fit, probe, bench) in the browser");
  auto o = std::make_shared<ViewOptions>();
  sub->add_option("out_dir", o->out_dir, "output folder of a VoxBreast run")->required();
  sub->add_option("--port", o->port, "TCP port; 0 takes any free one")->capture_default_str();
  sub->add_option("--host", o->host, "address to listen on; any but 127.0.0.1 requires the printed token")
      ->capture_default_str();
  sub->add_flag("--open", o->open, "open the page in the browser (xdg-open, chromium or firefox)");
  sub->add_option("--export", o->export_dir, "write a static copy of the page and its files to this folder, and exit");
  sub->add_option("--ct", o->ct, "the run's input CT (NIfTI file or DICOM folder), when summary.json's scene does not lead to it");
  return {sub, [o] {
    Server server;
    server.web_dir = assets_dir();
    server.ct_override = o->ct;
    server.folder = scan_view_folder(o->out_dir, o->ct);
    server.root = server.folder.root;
    // A DICOM input CT is converted into this folder, removed when the command ends.
    struct Scratch {
      fs::path dir;
      ~Scratch() {
        std::error_code ec;
        fs::remove_all(dir, ec);
      }
    } scratch{fs::temp_directory_path() / ("voxbreast-view-" + std::to_string(getpid()))};
    if (!server.folder.input_ct.empty()) {
      try {
        server.ct_file = input_ct_nifti(server.folder.input_ct, scratch.dir);
      } catch (const Error& e) {
        if (!o->ct.empty()) throw;
        server.ct_note = std::string("the input CT could not be read: ") + e.what();
      }
    }
    server.rescan();
    if (!o->export_dir.empty()) return export_folder(*o, server);
    return run_until_stopped({o->host, o->port, o->open}, "view",
                             "'" + server.root.string() + "' (" + server.folder.kind + ")", server.token,
                             [&](mg_context* context) { mg_set_request_handler(context, "/", handle_request, &server); });
  }};
}

}  // namespace vb::app
