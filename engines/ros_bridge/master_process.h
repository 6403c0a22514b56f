// Reaching the ROS master, and the rosmaster the bridge starts when none answers locally.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "master_uri.h"

namespace convoy::ros_bridge {

struct MasterProbe {
  enum State {
    kMaster,     // answered the XML-RPC call getPid
    kNothing,    // no connection (refused, unreachable, unknown host, no answer)
    kNotMaster,  // a connection, but no XML-RPC answer within the time
  } state = kNothing;
  std::string why;  // for kNothing and kNotMaster: "connection refused", ...
};

// Asks the master at `uri` for its pid (XML-RPC getPid over HTTP), all within `timeout`: unlike
// roscpp's ros::master::check(), which waits forever for a host that accepts the connection
// and never answers.
MasterProbe probe_master(const MasterUri& uri, std::chrono::milliseconds timeout);

// `rosmaster --core -p PORT` as a child process: killed with SIGKILL if this process dies
// (PR_SET_PDEATHSIG), its output into `log` (the engine's own stderr when empty).
class MasterProcess {
 public:
  MasterProcess() = default;
  MasterProcess(const MasterProcess&) = delete;
  MasterProcess& operator=(const MasterProcess&) = delete;
  ~MasterProcess() { stop(); }

  // Starts it and waits up to `timeout` for its port to answer. Throws std::runtime_error
  // (the command, its exit status or the time waited, and the log) when it does not.
  void start(const MasterUri& uri, const std::filesystem::path& log,
             std::chrono::milliseconds timeout);
  // SIGTERM, then SIGKILL after 2 s; reaps it. Nothing when none was started.
  void stop();
  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
};

}  // namespace convoy::ros_bridge
