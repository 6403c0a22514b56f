// `convoy view PATH [--port P] [--host H [--insecure]]`: serves the web dashboard at / and the
// files under PATH (a run folder, a campaign folder, or the folder of a .mcap file) at
// /files/, read-only, until Ctrl-C. No simulation runs: the dashboard replays a recording.
// Prints the URL to open: `view: http://127.0.0.1:P/?mcap=files/recording.mcap` for a run
// folder, `view: http://127.0.0.1:P/files/report.html` for a campaign folder.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace convoy::app {

struct ViewOptions {
  std::filesystem::path path;
  std::string host = "127.0.0.1";
  uint16_t port = 8765;
  bool insecure = false;  // listen beyond the loopback
};

// The URL path and query to print for `path` (under /files/), e.g.
// "/?mcap=files/recording.mcap"; the folder to serve in `*root`. Throws UserError naming the
// path when it is neither a folder nor a file.
std::string view_target(const std::filesystem::path& path, std::filesystem::path* root);

// Exit 0 after Ctrl-C; 2 (one message on stderr) for a bad PATH or address, a port in use.
int view_files(const ViewOptions& options);

}  // namespace convoy::app
