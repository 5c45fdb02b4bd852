#pragma once
/// What `voxbreast view` and `voxbreast serve` share: the page's assets, a civetweb server on an
/// address with a token when it is not loopback, responses with the same headers (docs/VIEW.md,
/// "Security").
#include <civetweb.h>

#include <filesystem>
#include <functional>
#include <string>

namespace vb::app::web {

/// The bundled page (index.html and its assets): $VOXBREAST_WEB_DIR, else `web/` next to the
/// executable, where the build puts it. Throws vb::Error when it is not built.
std::filesystem::path assets_dir();

/// 128 random bits as hex from the operating system's entropy source.
std::string random_token();
/// Compares in time independent of where the strings differ.
bool same_token(const std::string& a, const std::string& b);
/// The token of a request: ?token=, the cookie the page got with it, or "Authorization: Bearer".
std::string request_token(const mg_connection* conn);
/// The Set-Cookie value that carries `token` for the page's later requests.
std::string token_cookie(const std::string& token);

const char* mime_type(const std::string& name);
/// A complete response (body not sent for HEAD); returns `status`.
int send_text(mg_connection* conn, int status, const std::string& content_type, const std::string& body,
              const std::string& cookie = "");
/// A file in 1 MiB writes; 404 when it cannot be opened.
int send_file(mg_connection* conn, const std::filesystem::path& file, const std::string& cookie);

struct ListenOptions {
  std::string host = "127.0.0.1";
  int port = 8642;
  bool open = false;  ///< open the printed URL in a browser
};

/// Checks host and port, sets `token` (random when the host is not loopback, else empty) before
/// anything is served, starts civetweb, lets `add_handlers` register on it, prints
/// "voxbreast COMMAND: WHAT at URL", opens a browser when asked, and returns after Ctrl-C or
/// SIGTERM with the server stopped (`before_stop` runs first). Throws vb::Error (bad address,
/// port in use).
int run_until_stopped(const ListenOptions& o, const std::string& command, const std::string& what, std::string& token,
                      const std::function<void(mg_context*)>& add_handlers, const std::function<void()>& before_stop = {});

}  // namespace vb::app::web
