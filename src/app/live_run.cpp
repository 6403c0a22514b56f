#include "app/live_run.h"

#include <unistd.h>

#include <chrono>
#include <stdexcept>

#include "app/scene_setup.h"
#include "core/error.h"
#include "live/static_files.h"
#include "python/live_module.h"

namespace convoy::app {

namespace {

live::ServerOptions server_options(const RunOptions& options, const config::SimulationConfig& cfg) {
  live::ServerOptions o;
  try {
    o.address = live::parse_listen_address(options.live);
  } catch (const std::invalid_argument& e) {
    throw UserError(e.what());
  }
  o.insecure = options.insecure;
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  o.info.name = "convoy " CONVOY_VERSION;
  o.info.session_id =
      std::to_string(getpid()) + "-" +
      std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(now).count());
  o.info.metadata = {{"simulation", cfg.name}, {"config", cfg.file.string()}};
  o.info.capabilities = {"time", "clientPublish"};  // /convoy/control
  o.info.supported_encodings = {"json"};
  // The dashboard at / (share/convoy/dashboard, built from web/dashboard).
  o.http = live::make_http_handler(
      share_dir() / "dashboard", std::nullopt,
      live::no_dashboard_page(
          share_dir() / "dashboard",
          "Meanwhile, Foxglove or Lichtblick can show this run: open a Foxglove "
          "WebSocket connection to ws://" +
              o.address.text() + "\n"));
  return o;
}

live::LogLevel level_of(bool error, const std::string& line) {
  if (error) return live::LogLevel::kError;
  return line.rfind("warning:", 0) == 0 ? live::LogLevel::kWarning : live::LogLevel::kInfo;
}

}  // namespace

LiveRun::LiveRun(const RunOptions& options, const config::SimulationConfig& cfg, RunLog& log)
    : log_(log) {
  live::ServerOptions o = server_options(options, cfg);
  try {
    server_ = std::make_unique<live::LiveServer>(o);
  } catch (const std::exception& e) {  // std::invalid_argument, std::runtime_error
    throw UserError(e.what());
  }
  live::TapOptions t;
  t.camera_hz = options.live_camera_hz;
  t.scene_hz = options.live_scene_hz;
  const SceneSetup scene = scene_setup(cfg, log_);
  t.map = scene.map;
  t.scene = scene.options;
  tap_ = std::make_unique<live::LiveTap>(*server_, t);
  control_ = std::make_unique<live::RunControl>(*server_, gate_);
  python::set_live_publisher([control = control_.get()](const std::string& topic,
                                                        const std::string& json, int64_t time_ns) {
    return control->publish(topic, json, time_ns);
  });
  if (options.insecure && !live::is_loopback_host(o.address.host))
    log_.info("warning: --insecure: the live server listens at " + o.address.text() +
              " without TLS or token");
  log_.sink = [tap = tap_.get()](bool error, const std::string& line) {
    tap->log(level_of(error, line), line);
  };
  log_.info("live: serving at " + server_->url() +
            " (Foxglove or Lichtblick: open a Foxglove WebSocket connection to it)");
  std::string page = server_->url();
  page.replace(0, 2, "http");  // ws://HOST:PORT -> http://HOST:PORT
  log_.info("live: dashboard at " + page + "/");
}

LiveRun::~LiveRun() {
  log_.sink = nullptr;
  finish();
}

nlohmann::json LiveRun::finish() {
  if (finished_) return figures_;
  finished_ = true;
  log_.sink = nullptr;
  python::set_live_publisher(nullptr);
  gate_.close();
  server_->stop(1.0);
  uint64_t dropped = 0;
  nlohmann::json clients = nlohmann::json::array();
  for (const auto& c : server_->stats()) {
    dropped += c.dropped;
    clients.push_back({{"id", c.id},
                       {"peer", c.peer},
                       {"queued", c.queued},
                       {"sent", c.sent},
                       {"dropped", c.dropped},
                       {"errors", c.errors}});
    log_.info("live: client " + std::to_string(c.id) + " (" + c.peer + "): " +
              std::to_string(c.sent) + " messages sent, " + std::to_string(c.dropped) + " dropped" +
              (c.errors ? ", " + std::to_string(c.errors) + " bad requests answered" : ""));
  }
  const auto& frames = tap_->frames();
  figures_ = {{"url", server_->url()},
              {"clients", clients},
              {"dropped_messages", dropped},
              {"datapack_channels", tap_->channels()},
              {"datapacks_encoded", tap_->encoded()},
              {"camera_frames", frames.encoded()},
              {"camera_frames_skipped", frames.skipped()},
              {"control_commands", control_->commands()},
              {"paused_s", gate_.held_ns() * 1e-9},
              {"metrics_published", control_->published()}};
  if (tap_->skipped() > 0)
    log_.info("warning: live: " + std::to_string(tap_->skipped()) +
              " datapacks could not be shown; the first: " + tap_->first_skip());
  if (!frames.error().empty()) log_.info("warning: live: camera frames: " + frames.error());
  return figures_;
}

}  // namespace convoy::app
