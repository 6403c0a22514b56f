// Where the ROS master is: the URI from the config, $ROS_MASTER_URI or ROS's default, its host
// and port, and whether the host is this machine (the bridge starts a master only there).
#pragma once

#include <string>

namespace convoy::ros_bridge {

inline constexpr const char* kDefaultMasterUri = "http://localhost:11311";
inline constexpr int kDefaultMasterPort = 11311;

struct MasterUri {
  std::string text;    // as given ("http://127.0.0.1:11411/")
  std::string source;  // where it came from: "MasterURI", "ROS_MASTER_URI" or "default"
  std::string host;    // without brackets for IPv6
  int port = kDefaultMasterPort;
};

// The URI to use: `configured` (the MasterURI key) when not empty, else `env` (the value of
// ROS_MASTER_URI, nullptr when unset or empty), else kDefaultMasterUri. Throws
// std::invalid_argument naming the source when it does not parse (see parse_master_uri).
MasterUri choose_master_uri(const std::string& configured, const char* env);

// Parses "http://HOST[:PORT][/]" ("HOST:PORT" without scheme too; IPv6 in brackets). Port
// 11311 when left out. Throws std::invalid_argument saying what is wrong.
MasterUri parse_master_uri(const std::string& uri);

// True when `host` is this machine: localhost, 127.x.y.z, ::1, 0.0.0.0, or `this_host` (the
// machine's name, gethostname()), with or without its domain. Case-insensitive.
bool is_local_host(const std::string& host, const std::string& this_host);

}  // namespace convoy::ros_bridge
