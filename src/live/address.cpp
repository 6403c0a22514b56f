#include "live/address.h"

#include <boost/asio/ip/address.hpp>
#include <charconv>
#include <stdexcept>

namespace convoy::live {

namespace {

[[noreturn]] void bad(std::string_view spec, const std::string& why) {
  throw std::invalid_argument("--live " + std::string(spec) + ": " + why +
                              " (expected [HOST:]PORT, e.g. 8765 or 127.0.0.1:8765)");
}

}  // namespace

std::string ListenAddress::text() const {
  const bool v6 = host.find(':') != std::string::npos;
  return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

ListenAddress parse_listen_address(std::string_view spec) {
  ListenAddress out;
  std::string_view port = spec;
  if (!spec.empty() && spec.front() == '[') {
    const auto end = spec.find(']');
    if (end == std::string_view::npos || end + 1 >= spec.size() || spec[end + 1] != ':')
      bad(spec, "an IPv6 host needs the form [HOST]:PORT");
    out.host = std::string(spec.substr(1, end - 1));
    port = spec.substr(end + 2);
  } else if (const auto colon = spec.rfind(':'); colon != std::string_view::npos) {
    out.host = std::string(spec.substr(0, colon));
    port = spec.substr(colon + 1);
    if (out.host.find(':') != std::string::npos) bad(spec, "put an IPv6 host in brackets");
  }
  if (out.host.empty()) bad(spec, "empty host");
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || ec != std::errc() || end != port.data() + port.size() || value > 65535)
    bad(spec, "the port must be a number from 0 to 65535");
  out.port = static_cast<uint16_t>(value);
  return out;
}

bool is_loopback_host(std::string_view host) {
  if (host == "localhost") return true;
  boost::system::error_code ec;
  const auto address = boost::asio::ip::make_address(std::string(host), ec);
  return !ec && address.is_loopback();
}

void check_listen_policy(const ListenAddress& address, bool insecure) {
  if (insecure || is_loopback_host(address.host)) return;
  throw std::invalid_argument(
      "--live " + address.text() +
      " is not a loopback address: the live server has neither TLS nor a token, so anyone "
      "who reaches it could watch every datapack of the run. Listen on localhost "
      "(--live 127.0.0.1:" +
      std::to_string(address.port) + "), or say --insecure");
}

}  // namespace convoy::live
