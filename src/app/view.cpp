#include "app/view.h"

#include <chrono>
#include <cstdio>
#include <thread>

#include "app/simulation.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "live/server.h"
#include "live/static_files.h"

namespace convoy::app {

namespace fs = std::filesystem;

std::string view_target(const fs::path& path, fs::path* root) {
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (ec || !fs::exists(status))
    throw UserError("convoy view " + path.string() + ": no such file or folder");
  const fs::path absolute = fs::absolute(path, ec).lexically_normal();
  if (fs::is_regular_file(status)) {
    *root = absolute.parent_path();
    const std::string name = absolute.filename().string();
    if (absolute.extension() == ".mcap") return "/?mcap=files/" + name;
    return "/files/" + name;
  }
  if (!fs::is_directory(status))
    throw UserError("convoy view " + path.string() + ": not a file or folder");
  *root = absolute;
  if (fs::is_regular_file(absolute / "recording.mcap", ec)) return "/?mcap=files/recording.mcap";
  if (fs::is_regular_file(absolute / "report.html", ec)) return "/files/report.html";
  return "/files/";
}

int view_files(const ViewOptions& options) {
  fs::path root;
  std::string target;
  live::ServerOptions o;
  try {
    target = view_target(options.path, &root);
    o.address.host = options.host;
    o.address.port = options.port;
    if (!options.insecure && !live::is_loopback_host(options.host))
      throw UserError("convoy view: --host " + options.host +
                      " is not a loopback address: anyone who reaches it could read the files "
                      "under " +
                      root.string() + ". Give --insecure to allow it");
  } catch (const UserError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitUserError;
  }
  o.insecure = options.insecure;
  o.info.name = "convoy " CONVOY_VERSION " (view)";
  o.option = "convoy view";
  o.another_port = "--port " + std::to_string(options.port == 65535 ? 8766 : options.port + 1);
  const fs::path dashboard = share_dir() / "dashboard";
  install_signal_handlers();
  std::unique_ptr<live::LiveServer> server;
  try {
    const std::string base = "http://" + o.address.text();
    o.http = live::make_http_handler(
        dashboard, root, live::no_dashboard_page(dashboard, "The files: " + base + "/files/\n"));
    server = std::make_unique<live::LiveServer>(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitUserError;
  }
  live::ListenAddress bound = o.address;
  bound.port = server->port();
  std::printf("view: http://%s%s\n", bound.text().c_str(), target.c_str());
  std::fflush(stdout);
  std::fprintf(stderr, "convoy view: serving %s (and the dashboard) until Ctrl-C\n", root.c_str());
  while (!interrupted()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  server->stop(0.5);
  return kExitOk;
}

}  // namespace convoy::app
