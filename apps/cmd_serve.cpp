// voxbreast serve — a scene simulated live, its surface streamed to the page over a WebSocket
// (docs/VIEW.md, "Live simulation").
//   voxbreast serve data-samples/phantom/scene.toml            # prints http://127.0.0.1:8642/
//   voxbreast serve scene.toml --port 0 --pause-at-step 2000     # stops stepping at step 2000
// The simulation runs on its own thread in chunks of solver.check_every steps (then the state
// check, as `simulate` does); after each chunk it publishes the surface positions. A sender
// thread sends the newest published frame to each client, so a slow client loses frames, never
// steps. Control messages (JSON, at most 4 KiB) change gravity, pause, resume or reset the run.
#include <civetweb.h>

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "apps/commands.hpp"
#include "apps/simulation_setup.hpp"
#include "apps/web_server.hpp"
#include "engine/error.hpp"
#include "engine/loads/posture.hpp"
#include "engine/sim/simulator.hpp"
#include "engine/surface/surface_mesh.hpp"

namespace vb::app {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxMessageBytes = 4096;

struct ServeOptions {
  std::string scene, device, precision;
  std::string host = "127.0.0.1";
  int port = 8642;
  bool open = false;
  std::int64_t pause_at_step = 0;
};

/// A control from a client, applied by the simulation thread between chunks.
struct Control {
  std::optional<Vec3> gravity_m_s2;
  std::optional<bool> paused;
  bool reset = false;
};

/// Parses one control message: {"gravity": [x, y, z]} (m/s², world LPS, |g| ≤ 100) or
/// {"posture": "prone"}, {"pause": true|false}, {"reset": true}. Throws vb::Error naming what
/// is wrong.
Control parse_control(const std::string& text) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw Error("not a JSON object");
  Control c;
  for (const auto& [key, value] : j.items()) {
    if (key == "gravity") {
      if (!value.is_array() || value.size() != 3) throw Error("gravity must be [x, y, z] in m/s^2");
      Vec3 g;
      for (int i = 0; i < 3; ++i) {
        if (!value[i].is_number()) throw Error("gravity must be [x, y, z] in m/s^2");
        g[i] = value[i].get<double>();
      }
      if (!g.allFinite() || g.norm() > 100) throw Error("gravity must be finite and at most 100 m/s^2");
      c.gravity_m_s2 = g;
    } else if (key == "posture") {
      if (!value.is_string()) throw Error("posture must be a name");
      c.gravity_m_s2 = gravity_for_posture(value.get<std::string>());
    } else if (key == "pause") {
      if (!value.is_boolean()) throw Error("pause must be true or false");
      c.paused = value.get<bool>();
    } else if (key == "reset") {
      if (!value.is_boolean()) throw Error("reset must be true");
      c.reset = value.get<bool>();
    } else {
      throw Error("unknown control '" + key + "' (gravity, posture, pause, reset)");
    }
  }
  return c;
}

struct Live {
  // Fixed before the server starts.
  fs::path web_dir;
  std::string token;
  std::string mesh_message;  ///< JSON: triangles, rest positions (mm), postures
  std::string scene_name;

  // The newest frame: header (frame number, step, time s, paused) as 4 float64, then the surface
  // vertex positions as float32 x, y, z (mm, world LPS).
  std::mutex frame_mutex;
  std::condition_variable frame_ready;
  std::vector<char> frame;
  std::uint64_t frame_number = 0;

  std::mutex control_mutex;
  std::vector<Control> controls;

  std::mutex clients_mutex;
  std::set<mg_connection*> clients;
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> refused_messages{0};
};

int handle_page(mg_connection* conn, void* data) {
  auto& live = *static_cast<Live*>(data);
  const mg_request_info* ri = mg_get_request_info(conn);
  const std::string method = ri->request_method ? ri->request_method : "";
  if (method != "GET" && method != "HEAD") return web::send_text(conn, 405, "text/plain", "only GET and HEAD\n");
  std::string cookie;
  if (!live.token.empty()) {
    if (!web::same_token(web::request_token(conn), live.token))
      return web::send_text(conn, 401, "text/plain", "a valid token is required (the URL that voxbreast serve printed)\n");
    cookie = web::token_cookie(live.token);
  }
  const std::string path = ri->local_uri_raw ? ri->local_uri_raw : "";
  if (path == "/") return web::send_file(conn, live.web_dir / "index.html", cookie);
  if (path == "/manifest.json") {
    const nlohmann::json manifest = {{"kind", "live"}, {"title", live.scene_name}, {"files", nlohmann::json::array()},
                                     {"live", "live"}, {"input_ct", nullptr}, {"input_ct_note", ""}};
    return web::send_text(conn, 200, "application/json", manifest.dump(), cookie);
  }
  for (const char* asset : {"/view.js", "/style.css", "/view.js.LEGAL.txt"})
    if (path == asset) return web::send_file(conn, live.web_dir / (path.c_str() + 1), cookie);
  return web::send_text(conn, 404, "text/plain", "not found\n");
}

int ws_connect(const mg_connection* conn, void* data) {
  auto& live = *static_cast<Live*>(data);
  if (live.token.empty()) return 0;
  return web::same_token(web::request_token(conn), live.token) ? 0 : 1;  // 1: refuse
}

void ws_ready(mg_connection* conn, void* data) {
  auto& live = *static_cast<Live*>(data);
  // The mesh, then the newest frame at once (a paused run publishes no new one), then every new one.
  mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_TEXT, live.mesh_message.data(), live.mesh_message.size());
  std::vector<char> frame;
  {
    std::lock_guard lock(live.frame_mutex);
    frame = live.frame;
  }
  std::lock_guard lock(live.clients_mutex);
  if (!frame.empty()) mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_BINARY, frame.data(), frame.size());
  live.clients.insert(conn);
}

int ws_data(mg_connection* conn, int bits, char* data, std::size_t size, void* cbdata) {
  auto& live = *static_cast<Live*>(cbdata);
  const int opcode = bits & 0xf;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  if (opcode == MG_WEBSOCKET_OPCODE_PING || opcode == MG_WEBSOCKET_OPCODE_PONG) return 1;
  std::string reply;
  if (opcode != MG_WEBSOCKET_OPCODE_TEXT || size > kMaxMessageBytes) {
    reply = opcode != MG_WEBSOCKET_OPCODE_TEXT ? "only text control messages" : "message over 4096 bytes";
  } else {
    try {
      Control c = parse_control(std::string(data, size));
      std::lock_guard lock(live.control_mutex);
      live.controls.push_back(std::move(c));
      return 1;
    } catch (const std::exception& e) {
      reply = e.what();
    }
  }
  ++live.refused_messages;
  std::fprintf(stderr, "voxbreast serve: refused a control message: %s\n", reply.c_str());
  const std::string error = nlohmann::json{{"error", reply}}.dump();
  mg_lock_connection(conn);
  mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_TEXT, error.data(), error.size());
  mg_unlock_connection(conn);
  return 1;  // the run and the connection go on
}

void ws_close(const mg_connection* conn, void* data) {
  auto& live = *static_cast<Live*>(data);
  std::lock_guard lock(live.clients_mutex);
  live.clients.erase(const_cast<mg_connection*>(conn));
}

/// Sends the newest frame to every client; waits for the next one. A client that takes long
/// to receive delays only this thread, and meanwhile the frames it missed are replaced.
void send_frames(Live& live) {
  std::uint64_t sent = 0;
  std::vector<char> frame;
  while (!live.stopping) {
    {
      std::unique_lock lock(live.frame_mutex);
      live.frame_ready.wait_for(lock, std::chrono::milliseconds(200), [&] { return live.frame_number != sent || live.stopping; });
      if (live.frame_number == sent) continue;
      sent = live.frame_number;
      frame = live.frame;
    }
    std::lock_guard lock(live.clients_mutex);
    for (mg_connection* c : live.clients) {
      mg_lock_connection(c);
      mg_websocket_write(c, MG_WEBSOCKET_OPCODE_BINARY, frame.data(), frame.size());
      mg_unlock_connection(c);
    }
  }
}

int run_serve(const ServeOptions& o) {
  Scene scene = load_scene(o.scene, o.precision);
  require(!scene.reference_state.active, "serve does not estimate the unloaded reference state", "reference_state",
          "remove [reference_state] for a live run");
  const ClContext cl(select_device(o.device));
  const PreparedModel model = prepare_model(scene, &cl.info);
  Simulator sim(scene, model.lattice, model.elements, cl);
  const SurfaceMesh mesh = build_surface(model.lattice);
  const std::size_t n = model.lattice.element_count(), nv = mesh.vertex_count();

  Live live;
  live.web_dir = web::assets_dir();
  live.scene_name = fs::path(o.scene).filename().string();
  {
    const std::vector<double> rest = element_positions_m(model.lattice);
    nlohmann::json triangles = nlohmann::json::array(), positions = nlohmann::json::array();
    for (const auto& t : mesh.triangles) triangles.insert(triangles.end(), {t[0], t[1], t[2]});
    for (std::size_t v = 0; v < nv; ++v)
      for (int c = 0; c < 3; ++c) positions.push_back(float(1000 * rest[3 * mesh.element_of_vertex[v] + c]));
    live.mesh_message = nlohmann::json{{"type", "mesh"}, {"triangles", triangles}, {"rest_mm", positions},
                                       {"postures", posture_names()}, {"elements", n}, {"dt_s", sim.dt_s()},
                                       {"gravity_m_s2", {scene.gravity.acceleration_m_s2.x(), scene.gravity.acceleration_m_s2.y(),
                                                         scene.gravity.acceleration_m_s2.z()}},
                                       {"posture", scene.gravity.posture},
                                       {"steps_per_frame", std::max(1, scene.solver.check_every)}}
                            .dump();
  }

  std::atomic<bool> stop{false};
  std::string failure;
  std::thread stepper([&] {
    const std::int64_t chunk = std::max(1, scene.solver.check_every);
    std::vector<double> u, v, zero(3 * n, 0.0);
    bool paused = false, paused_at_step = false;  // --pause-at-step pauses once
    std::vector<char> frame(4 * sizeof(double) + 3 * nv * sizeof(float));
    auto publish = [&] {
      sim.download(u, v);
      const std::vector<double> x = element_positions_m(model.lattice, u);
      auto* p = reinterpret_cast<float*>(frame.data() + 4 * sizeof(double));
      for (std::size_t k = 0; k < nv; ++k)
        for (int c = 0; c < 3; ++c) p[3 * k + c] = float(1000 * x[3 * mesh.element_of_vertex[k] + c]);
      std::lock_guard lock(live.frame_mutex);
      const double header[4] = {double(live.frame_number + 1), double(sim.steps()), sim.time_s(), paused ? 1.0 : 0.0};
      std::memcpy(frame.data(), header, sizeof header);
      live.frame.swap(frame);
      frame.resize(live.frame.size());
      ++live.frame_number;
      live.frame_ready.notify_all();
    };
    try {
      publish();
      while (!stop) {
        std::vector<Control> controls;
        {
          std::lock_guard lock(live.control_mutex);
          controls.swap(live.controls);
        }
        bool changed = false;
        for (const Control& c : controls) {
          if (c.gravity_m_s2) sim.set_gravity(*c.gravity_m_s2);
          if (c.paused) paused = *c.paused;
          if (c.reset) {
            sim.upload(zero, zero);
            sim.restart_clock();
          }
          changed = true;
        }
        if (o.pause_at_step > 0 && sim.steps() >= o.pause_at_step && !paused_at_step) {
          paused = paused_at_step = changed = true;
        }
        if (paused) {
          if (changed) publish();
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
          continue;
        }
        const std::int64_t steps = !paused_at_step && o.pause_at_step > sim.steps() ? std::min(chunk, o.pause_at_step - sim.steps()) : chunk;
        sim.advance(steps);
        const StateCheck check = sim.check();
        if (check.nonfinite_elements > 0) throw Error("the run went unstable (non-finite state); reset or change the control");
        publish();
      }
    } catch (const std::exception& e) {
      failure = e.what();
      std::fprintf(stderr, "voxbreast serve: error: %s\n", e.what());
    }
  });
  std::thread sender([&] { send_frames(live); });
  const int status = web::run_until_stopped(
      {o.host, o.port, o.open}, "serve",
      "'" + o.scene + "' (" + std::to_string(n) + " elements, " + std::to_string(nv) + " surface vertices, device " + cl.info.name + ")",
      live.token,
      [&](mg_context* context) {
        mg_set_request_handler(context, "/", handle_page, &live);
        mg_set_websocket_handler(context, "/live", ws_connect, ws_ready, ws_data, ws_close, &live);
      },
      [&] {
        stop = true;
        live.stopping = true;
        live.frame_ready.notify_all();
        sender.join();
        stepper.join();
      });
  return failure.empty() ? status : 1;
}

}  // namespace

Command add_serve(CLI::App& app) {
  auto* sub = app.add_subcommand("serve", "Simulate a scene live and stream its surface to the browser");
  auto o = std::make_shared<ServeOptions>();
  sub->add_option("scene", o->scene, "scene file (TOML)")->required()->check(CLI::ExistingFile);
  sub->add_option("--port", o->port, "TCP port; 0 takes any free one")->capture_default_str();
  sub->add_option("--host", o->host, "address to listen on; any but 127.0.0.1 requires the printed token")->capture_default_str();
  sub->add_flag("--open", o->open, "open the page in the browser");
  sub->add_option("--device,-d", o->device, "OpenCL device: gpu, cpu, an index or a name");
  sub->add_option("--precision", o->precision, "float or double (default: the scene's)");
  sub->add_option("--pause-at-step", o->pause_at_step, "pause when the run reaches this step (0: never)")
      ->check(CLI::NonNegativeNumber);
  return {sub, [o] { return run_serve(*o); }};
}

}  // namespace vb::app
