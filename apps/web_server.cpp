#include "apps/web_server.hpp"

#include <pthread.h>
#include <spawn.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <vector>

#include "engine/error.hpp"

extern char** environ;

namespace vb::app::web {
namespace fs = std::filesystem;

namespace {

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

void common_headers(mg_connection* conn) {
  mg_response_header_add(conn, "Cache-Control", "no-store", -1);
  mg_response_header_add(conn, "X-Content-Type-Options", "nosniff", -1);
  mg_response_header_add(conn, "Referrer-Policy", "no-referrer", -1);
  mg_response_header_add(conn, "Connection", "close", -1);
}

int log_message(const mg_connection*, const char* message) {
  std::fprintf(stderr, "voxbreast: server: %s\n", message);
  return 1;
}

void open_browser(const std::string& url) {
  for (const char* program : {"xdg-open", "chromium", "firefox"}) {
    char* argv[] = {const_cast<char*>(program), const_cast<char*>(url.c_str()), nullptr};
    pid_t pid = 0;
    if (posix_spawnp(&pid, program, nullptr, nullptr, argv, environ) == 0) return;
  }
  std::fprintf(stderr, "voxbreast: no browser found (xdg-open, chromium, firefox): open the URL yourself\n");
}

}  // namespace

/// The bundled page (index.html and its assets): $VOXBREAST_WEB_DIR, else `web/` next to the
/// executable, where the build puts it.
fs::path assets_dir() {
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


int send_text(mg_connection* conn, int status, const std::string& content_type, const std::string& body,
              const std::string& cookie) {
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
std::string request_token(const mg_connection* conn) {
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

std::string token_cookie(const std::string& token) {
  return "voxbreast_token=" + token + "; HttpOnly; SameSite=Strict; Path=/";
}

int run_until_stopped(const ListenOptions& o, const std::string& command, const std::string& what, std::string& token,
                      const std::function<void(mg_context*)>& add_handlers, const std::function<void()>& before_stop) {
  if (!is_ipv4(o.host) && o.host != "localhost")
    throw Error("--host '" + o.host + "' is not an IPv4 address (such as 127.0.0.1 or 0.0.0.0)");
  if (o.port < 0 || o.port > 65535) throw Error("--port " + std::to_string(o.port) + " is not a port (0 to 65535)");
  token = is_loopback(o.host) ? "" : random_token();

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
  add_handlers(context.get());
  mg_server_port ports[1] = {};
  if (mg_get_server_ports(context.get(), 1, ports) < 1) throw Error("cannot read the listening port");

  std::string url = "http://" + (o.host == "0.0.0.0" ? std::string("HOST") : o.host) + ":" + std::to_string(ports[0].port) + "/";
  if (!token.empty()) url += "?token=" + token;
  std::printf("voxbreast %s: %s at %s\n", command.c_str(), what.c_str(), url.c_str());
  if (o.host == "0.0.0.0")
    std::printf("voxbreast %s: replace HOST with this machine's address; the token is required on every request\n", command.c_str());
  std::printf("voxbreast %s: Ctrl-C stops\n", command.c_str());
  std::fflush(stdout);
  if (o.open) open_browser(o.host == "0.0.0.0" ? "http://127.0.0.1:" + std::to_string(ports[0].port) + "/" +
                                                     (token.empty() ? "" : "?token=" + token)
                                               : url);
  int signal = 0;
  sigwait(&stop_signals, &signal);
  if (before_stop) before_stop();
  context.reset();
  mg_exit_library();
  return 0;
}

}  // namespace vb::app::web
