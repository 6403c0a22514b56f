// Master URI parsing (master_uri.h).
#include "master_uri.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace convoy::ros_bridge {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string first_label(const std::string& host) { return host.substr(0, host.find('.')); }

int parse_port(const std::string& text, const std::string& uri) {
  if (text.empty() || text.size() > 5 ||
      !std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); })) {
    throw std::invalid_argument("the port of \"" + uri + "\" is not a number: \"" + text + "\"");
  }
  const int port = std::stoi(text);
  if (port < 1 || port > 65535)
    throw std::invalid_argument("the port of \"" + uri + "\" is out of range: " + text);
  return port;
}

}  // namespace

MasterUri parse_master_uri(const std::string& uri) {
  MasterUri out;
  out.text = uri;
  std::string rest = uri;
  if (const size_t scheme = rest.find("://"); scheme != std::string::npos) {
    if (lower(rest.substr(0, scheme)) != "http")
      throw std::invalid_argument("\"" + uri + "\" is not an http:// URI");
    rest = rest.substr(scheme + 3);
  }
  if (const size_t slash = rest.find('/'); slash != std::string::npos) {
    if (rest.find_first_not_of('/', slash) != std::string::npos)
      throw std::invalid_argument("\"" + uri + "\" has a path; a master URI has none");
    rest.resize(slash);
  }
  std::string port_text;
  if (!rest.empty() && rest.front() == '[') {
    const size_t close = rest.find(']');
    if (close == std::string::npos)
      throw std::invalid_argument("\"" + uri + "\": '[' without ']' around the host");
    out.host = rest.substr(1, close - 1);
    const std::string after = rest.substr(close + 1);
    if (!after.empty() && after.front() != ':')
      throw std::invalid_argument("\"" + uri + "\": unexpected text after the host");
    if (!after.empty()) port_text = after.substr(1);
    if (after == ":") port_text = ":";
  } else {
    const size_t colon = rest.find(':');
    out.host = rest.substr(0, colon);
    if (colon != std::string::npos) port_text = rest.substr(colon + 1);
    if (colon != std::string::npos && port_text.empty()) port_text = ":";
  }
  if (out.host.empty()) throw std::invalid_argument("\"" + uri + "\" names no host");
  if (!port_text.empty()) out.port = parse_port(port_text == ":" ? "" : port_text, uri);
  return out;
}

MasterUri choose_master_uri(const std::string& configured, const char* env) {
  std::string text = configured, source = "MasterURI";
  if (text.empty() && env && *env) text = env, source = "ROS_MASTER_URI";
  if (text.empty()) text = kDefaultMasterUri, source = "default";
  try {
    MasterUri uri = parse_master_uri(text);
    uri.source = source;
    return uri;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": " + e.what());
  }
}

bool is_local_host(const std::string& host, const std::string& this_host) {
  const std::string h = lower(host);
  if (h == "localhost" || h == "localhost.localdomain" || h == "::1" || h == "0.0.0.0" ||
      h.rfind("127.", 0) == 0) {
    return true;
  }
  if (this_host.empty()) return false;
  const std::string me = lower(this_host);
  if (h == me) return true;
  // "vm" and "vm.example.org" are the same machine; "vm.a.org" and "vm.b.org" need not be.
  const bool one_short = h.find('.') == std::string::npos || me.find('.') == std::string::npos;
  return one_short && first_label(h) == first_label(me);
}

}  // namespace convoy::ros_bridge
