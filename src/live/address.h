// Where the live server listens: `--live [HOST:]PORT` (HOST defaults to 127.0.0.1; an IPv6
// host in brackets, `[::1]:8765`). Beyond the loopback only with --insecure, like the NRP-Core
// server: the live server has neither TLS nor a token, and shows every datapack of the run.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace convoy::live {

struct ListenAddress {
  std::string host = "127.0.0.1";
  uint16_t port = 0;         // 0: the system picks one
  std::string text() const;  // "HOST:PORT" ("[::1]:PORT")
};

// Throws std::invalid_argument naming --live and the text when it is not [HOST:]PORT.
ListenAddress parse_listen_address(std::string_view spec);

// True for "localhost" and the IPv4 / IPv6 loopback addresses (127.0.0.0/8, ::1). A host name
// other than localhost is not known to be one without resolving it (live/server.cpp checks
// the resolved address too).
bool is_loopback_host(std::string_view host);

// Throws std::invalid_argument (the message names --live, the address and --insecure) when
// `address` is not a loopback address and not `insecure`.
void check_listen_policy(const ListenAddress& address, bool insecure);

}  // namespace convoy::live
