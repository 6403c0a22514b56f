// Static files over HTTP on the live server's port: the web dashboard (share/convoy/dashboard)
// at "/", and in `convoy view PATH` the files under PATH at "/files/". Read-only, GET and HEAD,
// Content-Type by extension, Content-Length, single byte ranges (Range: bytes=...). A request
// never leaves its folder: the path is percent-decoded, then ".." is refused and the file's
// real path (symbolic links resolved) must lie under the folder's.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "live/connection.h"

namespace convoy::live {

// "text/html; charset=utf-8", "image/png"...; "application/octet-stream" when unknown.
std::string content_type_of(const std::filesystem::path& file);

// The path below `prefix` ("/" or "/files/") that `target` names, percent-decoded, without the
// query or fragment, empty segments and "." dropped ("" for the folder itself). nullopt when
// the target is not below the prefix or is not acceptable: "..", a NUL or a backslash (after
// decoding), a bad %-escape.
std::optional<std::string> relative_path(std::string_view target, std::string_view prefix);

// A Range header against a file of `size` bytes: one range of bytes ("bytes=0-99",
// "bytes=100-", "bytes=-100"). Several ranges or another unit: the whole file.
struct ByteRange {
  enum class Kind { kWhole, kPart, kUnsatisfiable } kind = Kind::kWhole;
  uint64_t offset = 0, length = 0;
};
ByteRange parse_range(std::string_view header, uint64_t size);

// The files under one folder, at one URL prefix.
class StaticFiles {
 public:
  // `root` need not exist yet (a dashboard built later is served once it is there).
  // `list_folders`: a folder without index.html gets a page listing it.
  StaticFiles(std::filesystem::path root, std::string prefix, bool list_folders = false);
  const std::filesystem::path& root() const { return root_; }
  bool handles(std::string_view target) const;
  // The file `target` names, a folder's index.html (or listing), or 404 / 405 / 416.
  HttpAnswer answer(const HttpRequest& request) const;
  // The real path of `relative` when it is a regular file inside the root.
  std::optional<std::filesystem::path> find(const std::string& relative) const;

 private:
  HttpAnswer listing(const std::filesystem::path& folder, const std::string& relative) const;
  std::filesystem::path root_;
  std::string prefix_;
  bool list_folders_;
};

// The HTTP side of a port: the dashboard at "/" (when its index.html is missing, "/" answers
// `no_dashboard_text`, a plain text page), and `files` at "/files/" when given.
std::function<HttpAnswer(const HttpRequest&)> make_http_handler(
    std::filesystem::path dashboard, std::optional<std::filesystem::path> files,
    std::string no_dashboard_text);

// The text of "/" when the dashboard is not built: how to build it, and `more`.
std::string no_dashboard_page(const std::filesystem::path& dashboard, const std::string& more);

}  // namespace convoy::live
