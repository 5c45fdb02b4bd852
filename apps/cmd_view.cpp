// voxbreast view — an output folder's meshes, CT slices and numbers in the browser (docs/VIEW.md).
//   voxbreast view out/phantom                      # prints http://127.0.0.1:8642/
//   voxbreast view out/phantom --port 0 --open      # any free port, opens the browser
//   voxbreast view out/phantom --host 0.0.0.0       # reachable from other machines, with a token
//   voxbreast view out/phantom --export report/     # a static folder to zip and send
// The server (civetweb) answers GET and HEAD only, with the page's assets, the folder's viewable
// files and a manifest of them; nothing else on the machine is reachable through it.
#include <civetweb.h>
#include <spawn.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <mutex>
#include <random>
#include <set>

#include "apps/commands.hpp"
#include "apps/view_folder.hpp"
#include "engine/error.hpp"
#include "io/dicom_io.hpp"
#include "io/nifti_io.hpp"

extern char** environ;

namespace vb::app {
namespace fs = std::filesystem;

namespace {

struct ViewOptions {
  std::string out_dir;
  int port = 8642;
  std::string host = "127.0.0.1";
  bool open = false;
  std::string export_dir;
  std::string ct;
};

/// The bundled page (index.html and its assets): $VOXBREAST_WEB_DIR, else `web/` next to the
/// executable, where the build puts it.
fs::path web_assets_dir() {
  fs::path dir;
  if (const char* env = std::getenv("VOXBREAST_WEB_DIR"); env && *env) {
    dir = env;
  } else {
    std::error_code ec;
    dir = fs::read_symlink("/proc/self/exe", ec).parent_path() / "web";
  }
  std::error_code ec;
  if (!fs::is_regular_file(dir / "index.html", ec))
    throw Error("the page is not built ('" + (dir / "index.html").string() +
                "' is missing): run scripts/setup.sh and scripts/build.sh (npm ci in apps/web)");
  return fs::canonical(dir);
}

bool is_loopback(const std::string& host) { return host == "127.0.0.1" || host == "localhost"; }

/// Dotted IPv4 only: civetweb's "ADDR:PORT" form without IPv6 brackets.
bool is_ipv4(const std::string& host) {
  int parts = 0, value = -1;
  for (const char c : host + ".") {
    if (c == '.') {
      if (value < 0 || value > 255) return false;
      ++parts, value = -1;
    } else if (c >= '0' && c <= '9') {
      value = (value < 0 ? 0 : value * 10) + (c - '0');
    } else {
      return false;
    }
  }
  return parts == 4;
}

/// 128 random bits as hex, from the operating system's entropy source (std::random_device reads
/// /dev/urandom on Linux): the token a client must show when the server is not on loopback.
std::string random_token() {
  std::random_device device;
  std::string token;
  for (int i = 0; i < 4; ++i) {
    char part[9];
    std::snprintf(part, sizeof part, "%08x", unsigned(device()));
    token += part;
  }
  return token;
}

bool same_token(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

const char* mime_type(const std::string& name) {
  const auto ends = [&](const char* ext) {
    const std::string e = ext;
    return name.size() >= e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".html")) return "text/html; charset=utf-8";
  if (ends(".js") || ends(".mjs")) return "text/javascript; charset=utf-8";
  if (ends(".css")) return "text/css; charset=utf-8";
  if (ends(".json")) return "application/json";
  if (ends(".csv")) return "text/csv; charset=utf-8";
  if (ends(".png")) return "image/png";
  if (ends(".svg")) return "image/svg+xml";
  if (ends(".vtp") || ends(".pvd")) return "application/xml";
  if (ends(".wasm")) return "application/wasm";
  if (ends(".toml")) return "text/plain; charset=utf-8";
  // .nii.gz is sent as the gzip file it is (no Content-Encoding): NiiVue inflates it itself.
  return "application/octet-stream";
}

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

void common_headers(mg_connection* conn) {
  mg_response_header_add(conn, "Cache-Control", "no-store", -1);
  mg_response_header_add(conn, "X-Content-Type-Options", "nosniff", -1);
  mg_response_header_add(conn, "Referrer-Policy", "no-referrer", -1);
  mg_response_header_add(conn, "Connection", "close", -1);
}

int send_text(mg_connection* conn, int status, const std::string& content_type, const std::string& body,
              const std::string& cookie = "") {
  mg_response_header_start(conn, status);
  mg_response_header_add(conn, "Content-Type", content_type.c_str(), -1);
  mg_response_header_add(conn, "Content-Length", std::to_string(body.size()).c_str(), -1);
  if (!cookie.empty()) mg_response_header_add(conn, "Set-Cookie", cookie.c_str(), -1);
  common_headers(conn);
  mg_response_header_send(conn);
  if (std::string(mg_get_request_info(conn)->request_method) != "HEAD") mg_write(conn, body.data(), body.size());
  return status;
}

int send_file(mg_connection* conn, const fs::path& file, const std::string& cookie) {
  std::ifstream in(file, std::ios::binary);
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (!in || ec) return send_text(conn, 404, "text/plain", "not found\n");
  mg_response_header_start(conn, 200);
  mg_response_header_add(conn, "Content-Type", mime_type(file.filename().string()), -1);
  mg_response_header_add(conn, "Content-Length", std::to_string(size).c_str(), -1);
  if (!cookie.empty()) mg_response_header_add(conn, "Set-Cookie", cookie.c_str(), -1);
  common_headers(conn);
  mg_response_header_send(conn);
  if (std::string(mg_get_request_info(conn)->request_method) == "HEAD") return 200;
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    if (in.gcount() > 0 && mg_write(conn, buffer.data(), std::size_t(in.gcount())) <= 0) break;
  }
  return 200;
}

/// The token of a request: ?token=, the cookie the page got with it, or "Authorization: Bearer".
std::string request_token(mg_connection* conn) {
  const mg_request_info* ri = mg_get_request_info(conn);
  char value[128] = {};
  if (ri->query_string && mg_get_var(ri->query_string, std::strlen(ri->query_string), "token", value, sizeof value) > 0)
    return value;
  if (const char* cookie = mg_get_header(conn, "Cookie"); cookie && mg_get_cookie(cookie, "voxbreast_token", value, sizeof value) > 0)
    return value;
  if (const char* auth = mg_get_header(conn, "Authorization"); auth && std::strncmp(auth, "Bearer ", 7) == 0)
    return auth + 7;
  return "";
}

int handle_request(mg_connection* conn, void* data) {
  auto& server = *static_cast<Server*>(data);
  const mg_request_info* ri = mg_get_request_info(conn);
  const std::string method = ri->request_method ? ri->request_method : "";
  if (method != "GET" && method != "HEAD") return send_text(conn, 405, "text/plain", "only GET and HEAD\n");
  std::string cookie;
  if (!server.token.empty()) {
    if (!same_token(request_token(conn), server.token))
      return send_text(conn, 401, "text/plain", "a valid token is required (the URL that voxbreast view printed)\n");
    cookie = "voxbreast_token=" + server.token + "; HttpOnly; SameSite=Strict; Path=/";
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

int log_message(const mg_connection*, const char* message) {
  std::fprintf(stderr, "voxbreast view: %s\n", message);
  return 1;
}

void open_browser(const std::string& url) {
  for (const char* program : {"xdg-open", "chromium", "firefox"}) {
    char* argv[] = {const_cast<char*>(program), const_cast<char*>(url.c_str()), nullptr};
    pid_t pid = 0;
    if (posix_spawnp(&pid, program, nullptr, nullptr, argv, environ) == 0) return;
  }
  std::fprintf(stderr, "voxbreast view: no browser found (xdg-open, chromium, firefox): open the URL yourself\n");
}

int serve(const ViewOptions& o, Server& server) {
  if (!is_ipv4(o.host) && o.host != "localhost")
    throw Error("--host '" + o.host + "' is not an IPv4 address (such as 127.0.0.1 or 0.0.0.0)");
  if (o.port < 0 || o.port > 65535) throw Error("--port " + std::to_string(o.port) + " is not a port (0 to 65535)");
  if (!is_loopback(o.host)) server.token = random_token();

  // Ctrl-C and SIGTERM are taken by sigwait below: blocked before civetweb starts its threads,
  // which inherit the mask, so no request thread is interrupted.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  mg_init_library(0);
  const std::string listen = (o.host == "localhost" ? std::string("127.0.0.1") : o.host) + ":" + std::to_string(o.port);
  const char* options[] = {"listening_ports", listen.c_str(), "num_threads", "8", "request_timeout_ms", "30000",
                           "enable_directory_listing", "no", nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = log_message;
  std::unique_ptr<mg_context, void (*)(mg_context*)> context(mg_start(&callbacks, nullptr, options), mg_stop);
  if (!context) throw Error("cannot listen on " + listen + " (is the port in use? choose another with --port, 0 for any)");
  mg_set_request_handler(context.get(), "/", handle_request, &server);
  mg_server_port ports[1] = {};
  if (mg_get_server_ports(context.get(), 1, ports) < 1) throw Error("cannot read the listening port");

  std::string url = "http://" + (o.host == "0.0.0.0" ? std::string("HOST") : o.host) + ":" + std::to_string(ports[0].port) + "/";
  if (!server.token.empty()) url += "?token=" + server.token;
  std::printf("voxbreast view: '%s' (%s) at %s\n", server.folder.root.string().c_str(), server.folder.kind.c_str(), url.c_str());
  if (o.host == "0.0.0.0") std::printf("voxbreast view: replace HOST with this machine's address; the token is required on every request\n");
  std::printf("voxbreast view: Ctrl-C stops\n");
  std::fflush(stdout);
  if (o.open) open_browser(o.host == "0.0.0.0" ? "http://127.0.0.1:" + std::to_string(ports[0].port) + "/" +
                                                     (server.token.empty() ? "" : "?token=" + server.token)
                                               : url);
  int signal = 0;
  sigwait(&stop_signals, &signal);
  context.reset();
  mg_exit_library();
  return 0;
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
    server.web_dir = web_assets_dir();
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
    return o->export_dir.empty() ? serve(*o, server) : export_folder(*o, server);
  }};
}

}  // namespace vb::app
