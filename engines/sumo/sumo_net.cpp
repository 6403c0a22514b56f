#include "sumo_net.h"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#ifndef CONVOY_NETCONVERT
#define CONVOY_NETCONVERT "netconvert"
#endif

namespace convoy::engines::sumo {
namespace fs = std::filesystem;

namespace {

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// FNV-1a, 64 bits: stable across builds and machines (std::hash is not).
uint64_t fnv1a(std::string_view bytes, uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') {
      out += "'\\''";
    } else {
      out += c;
    }
  }
  return out + "'";
}

// The options netconvert gets besides input and output; part of the cache key.
constexpr const char* kNetconvertOptions = "--no-warnings --no-turnarounds true";

}  // namespace

NetOffset read_net_offset(const fs::path& net_file) {
  // The <location> element comes first in a .net.xml: the first 64 KiB are enough.
  std::ifstream in(net_file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + net_file.string());
  std::string head(64 * 1024, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  NetOffset off;
  const auto loc = head.find("<location");
  if (loc == std::string::npos) return off;
  const auto attr = head.find("netOffset=\"", loc);
  if (attr == std::string::npos) return off;
  if (std::sscanf(head.c_str() + attr + 11, "%lf,%lf", &off.x, &off.y) != 2) {
    throw std::runtime_error(net_file.string() + ": cannot read <location netOffset>");
  }
  return off;
}

fs::path default_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    return fs::path(xdg) / "convoy" / "sumo";
  }
  if (const char* home = std::getenv("HOME"); home && *home) {
    return fs::path(home) / ".cache" / "convoy" / "sumo";
  }
  return fs::temp_directory_path() / "convoy-cache" / "sumo";
}

fs::path convert_opendrive(const fs::path& xodr, const fs::path& cache_dir) {
  const std::string bytes = read_file(xodr);
  char key[17];
  std::snprintf(key, sizeof key, "%016llx",
                static_cast<unsigned long long>(fnv1a(kNetconvertOptions, fnv1a(bytes))));
  const fs::path net = cache_dir / (std::string(key) + ".net.xml");
  std::error_code ec;
  if (fs::exists(net, ec)) return net;
  fs::create_directories(cache_dir, ec);
  if (ec)
    throw std::runtime_error("cannot create the cache folder " + cache_dir.string() + ": " +
                             ec.message());
  // Written under a name of this process, then renamed: two engines converting the same map
  // at once each get a whole file.
  const fs::path tmp =
      cache_dir / (std::string(key) + ".tmp" + std::to_string(getpid()) + ".net.xml");
  const std::string cmd = std::string(CONVOY_NETCONVERT) + " " + kNetconvertOptions +
                          " --opendrive-files " + shell_quote(xodr.string()) + " -o " +
                          shell_quote(tmp.string()) + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) throw std::runtime_error("cannot run netconvert");
  std::string output;
  std::array<char, 4096> buf;
  while (size_t n = std::fread(buf.data(), 1, buf.size(), p)) output.append(buf.data(), n);
  const int status = pclose(p);
  if (status != 0 || !fs::exists(tmp, ec)) {
    fs::remove(tmp, ec);
    if (output.size() > 2000) output = "..." + output.substr(output.size() - 2000);
    throw std::runtime_error("netconvert could not convert " + xodr.string() + " (exit " +
                             std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
                             "): " + output);
  }
  fs::rename(tmp, net, ec);
  if (ec) throw std::runtime_error("cannot write " + net.string() + ": " + ec.message());
  return net;
}

double yaw_from_sumo_angle(double angle_deg) {
  double yaw = (90.0 - angle_deg) * M_PI / 180.0;
  yaw = std::remainder(yaw, 2 * M_PI);
  return yaw <= -M_PI ? yaw + 2 * M_PI : yaw;
}

double sumo_angle_from_yaw(double yaw) {
  double a = std::fmod(90.0 - yaw * 180.0 / M_PI, 360.0);
  return a < 0 ? a + 360.0 : a;
}

}  // namespace convoy::engines::sumo
