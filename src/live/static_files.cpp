#include "live/static_files.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <map>
#include <vector>

namespace convoy::live {

namespace fs = std::filesystem;

namespace {

constexpr const char* kText = "text/plain; charset=utf-8";

HttpAnswer text_answer(unsigned status, std::string body) {
  return HttpAnswer::text(status, std::move(body));
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string html_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string url_escape(std::string_view s) {
  static const char* kHex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : s) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~' || c == '/') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += kHex[c >> 4];
      out += kHex[c & 15];
    }
  }
  return out;
}

// True when `path` is `root` or below it (both canonical).
bool inside(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p)
    if (p == path.end() || *p != *r) return false;
  return true;
}

bool parse_u64(std::string_view s, uint64_t* out) {
  if (s.empty()) return false;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), *out);
  return ec == std::errc() && end == s.data() + s.size();
}

}  // namespace

std::string content_type_of(const fs::path& file) {
  static const std::map<std::string, std::string> kTypes = {
      {".html", "text/html; charset=utf-8"},
      {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".gif", "image/gif"},
      {".svg", "image/svg+xml"},
      {".ico", "image/x-icon"},
      {".mcap", "application/octet-stream"},
      {".mp4", "video/mp4"},
      {".csv", "text/csv; charset=utf-8"},
      {".txt", kText},
      {".log", kText},
      {".wasm", "application/wasm"},
      {".woff2", "font/woff2"},
  };
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  auto it = kTypes.find(ext);
  return it == kTypes.end() ? "application/octet-stream" : it->second;
}

std::optional<std::string> relative_path(std::string_view target, std::string_view prefix) {
  target = target.substr(0, target.find_first_of("?#"));
  // "/files" is the folder "/files/".
  if (prefix.size() > 1 && target == prefix.substr(0, prefix.size() - 1)) return std::string();
  if (target.substr(0, prefix.size()) != prefix) return std::nullopt;
  target.remove_prefix(prefix.size());
  std::string decoded;
  for (size_t i = 0; i < target.size(); ++i) {
    if (target[i] != '%') {
      decoded += target[i];
      continue;
    }
    if (i + 2 >= target.size()) return std::nullopt;
    const int hi = hex_value(target[i + 1]), lo = hex_value(target[i + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    decoded += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  if (decoded.find('\0') != std::string::npos || decoded.find('\\') != std::string::npos)
    return std::nullopt;
  std::string out;
  size_t start = 0;
  while (start <= decoded.size()) {
    size_t end = decoded.find('/', start);
    if (end == std::string::npos) end = decoded.size();
    std::string_view segment(decoded.data() + start, end - start);
    if (segment == "..") return std::nullopt;
    if (!segment.empty() && segment != ".") {
      if (!out.empty()) out += '/';
      out += segment;
    }
    start = end + 1;
  }
  return out;
}

ByteRange parse_range(std::string_view header, uint64_t size) {
  ByteRange whole{ByteRange::Kind::kWhole, 0, size};
  constexpr std::string_view kUnit = "bytes=";
  if (header.substr(0, kUnit.size()) != kUnit) return whole;
  header.remove_prefix(kUnit.size());
  while (!header.empty() && header.front() == ' ') header.remove_prefix(1);
  while (!header.empty() && header.back() == ' ') header.remove_suffix(1);
  if (header.find(',') != std::string_view::npos) return whole;  // several: the whole file
  const size_t dash = header.find('-');
  if (dash == std::string_view::npos) return whole;
  const std::string_view first = header.substr(0, dash), last = header.substr(dash + 1);
  uint64_t a = 0, b = 0;
  ByteRange unsatisfiable{ByteRange::Kind::kUnsatisfiable, 0, 0};
  if (first.empty()) {  // the last `b` bytes
    if (!parse_u64(last, &b)) return whole;
    if (b == 0 || size == 0) return unsatisfiable;
    b = std::min(b, size);
    return {ByteRange::Kind::kPart, size - b, b};
  }
  if (!parse_u64(first, &a)) return whole;
  if (last.empty()) {
    b = size == 0 ? 0 : size - 1;
  } else {
    if (!parse_u64(last, &b) || b < a) return whole;
    b = std::min(b, size == 0 ? 0 : size - 1);
  }
  if (a >= size) return unsatisfiable;
  return {ByteRange::Kind::kPart, a, b - a + 1};
}

StaticFiles::StaticFiles(fs::path root, std::string prefix, bool list_folders)
    : root_(std::move(root)), prefix_(std::move(prefix)), list_folders_(list_folders) {}

bool StaticFiles::handles(std::string_view target) const {
  target = target.substr(0, target.find_first_of("?#"));
  return target.substr(0, prefix_.size()) == prefix_ ||
         (prefix_.size() > 1 && target == std::string_view(prefix_).substr(0, prefix_.size() - 1));
}

std::optional<fs::path> StaticFiles::find(const std::string& relative) const {
  std::error_code ec;
  const fs::path root = fs::canonical(root_, ec);
  if (ec) return std::nullopt;
  fs::path path = fs::canonical(root / relative, ec);
  if (ec || !inside(path, root)) return std::nullopt;
  if (fs::is_directory(path, ec)) {
    path = fs::canonical(path / "index.html", ec);
    if (ec || !inside(path, root)) return std::nullopt;
  }
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  return path;
}

HttpAnswer StaticFiles::listing(const fs::path& folder, const std::string& relative) const {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    std::string name = entry.path().filename().string();
    if (entry.is_directory(ec)) name += '/';
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  const std::string base = prefix_ + (relative.empty() ? "" : relative + "/");
  std::string body = "<!doctype html><meta charset=\"utf-8\"><title>" + html_escape(base) +
                     "</title><h1>" + html_escape(base) + "</h1><ul>";
  if (!relative.empty()) body += "<li><a href=\"../\">../</a></li>";
  for (const auto& n : names)
    body +=
        "<li><a href=\"" + html_escape(url_escape(base + n)) + "\">" + html_escape(n) + "</a></li>";
  body += "</ul>\n";
  return HttpAnswer::text(200, body, "text/html; charset=utf-8");
}

HttpAnswer StaticFiles::answer(const HttpRequest& request) const {
  if (request.method != "GET" && request.method != "HEAD") {
    HttpAnswer a = text_answer(405, "GET and HEAD only\n");
    a.headers.push_back({"Allow", "GET, HEAD"});
    return a;
  }
  const auto relative = relative_path(request.target, prefix_);
  if (!relative) return text_answer(404, "not found\n");
  auto file = find(*relative);
  if (!file) {
    if (list_folders_) {
      std::error_code ec;
      const fs::path root = fs::canonical(root_, ec);
      const fs::path folder = ec ? fs::path() : fs::canonical(root / *relative, ec);
      if (!ec && inside(folder, root) && fs::is_directory(folder, ec))
        return listing(folder, *relative);
    }
    return text_answer(404, "not found\n");
  }
  std::error_code ec;
  const uint64_t size = fs::file_size(*file, ec);
  if (ec) return text_answer(404, "not found\n");
  HttpAnswer a;
  a.status = 200;
  a.content_type = content_type_of(*file);
  a.file = file->string();
  a.file_length = size;
  a.headers = {{"Accept-Ranges", "bytes"}, {"Cache-Control", "no-cache"}};
  if (!request.range.empty()) {
    const ByteRange r = parse_range(request.range, size);
    if (r.kind == ByteRange::Kind::kUnsatisfiable) {
      HttpAnswer refused = text_answer(416, "range not satisfiable\n");
      refused.headers.push_back({"Content-Range", "bytes */" + std::to_string(size)});
      return refused;
    }
    if (r.kind == ByteRange::Kind::kPart) {
      a.status = 206;
      a.file_offset = r.offset;
      a.file_length = r.length;
      a.headers.push_back({"Content-Range", "bytes " + std::to_string(r.offset) + "-" +
                                                std::to_string(r.offset + r.length - 1) + "/" +
                                                std::to_string(size)});
    }
  }
  return a;
}

std::string no_dashboard_page(const fs::path& dashboard, const std::string& more) {
  return "The Convoy dashboard is not built (no " + (dashboard / "index.html").string() +
         ").\nBuild it with:\n  (cd web/dashboard && npm ci && npm run build)\n"
         "(scripts/setup.sh does it), then reload this page.\n" +
         more;
}

std::function<HttpAnswer(const HttpRequest&)> make_http_handler(fs::path dashboard,
                                                                std::optional<fs::path> files,
                                                                std::string no_dashboard_text) {
  auto site = std::make_shared<StaticFiles>(dashboard, "/");
  std::shared_ptr<StaticFiles> shared;
  if (files) shared = std::make_shared<StaticFiles>(*files, "/files/", /*list_folders=*/true);
  return [site, shared, text = std::move(no_dashboard_text)](const HttpRequest& r) {
    if (shared && shared->handles(r.target)) return shared->answer(r);
    HttpAnswer a = site->answer(r);
    if (a.status == 404 && !site->find("index.html")) {
      const auto relative = relative_path(r.target, "/");
      if (relative && relative->empty()) return text_answer(200, text);
    }
    return a;
  };
}

}  // namespace convoy::live
