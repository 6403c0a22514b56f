// The static file handler of the live port (the dashboard, `convoy view`'s /files/): paths,
// types, ranges, and requests that try to leave the folder.
#include "live/static_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace convoy::live {
namespace {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/convoy_static_XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  void write(const std::string& relative, const std::string& text) const {
    fs::create_directories((path_ / relative).parent_path());
    std::ofstream(path_ / relative, std::ios::binary) << text;
  }

 private:
  fs::path path_;
};

HttpRequest get(const std::string& target, const std::string& range = "") {
  return {"GET", target, range};
}

TEST(StaticFiles, ContentTypesByExtension) {
  EXPECT_EQ(content_type_of("a/index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(content_type_of("app.JS"), "text/javascript; charset=utf-8");
  EXPECT_EQ(content_type_of("s.css"), "text/css; charset=utf-8");
  EXPECT_EQ(content_type_of("summary.json"), "application/json");
  EXPECT_EQ(content_type_of("birds_eye.png"), "image/png");
  EXPECT_EQ(content_type_of("x.jpg"), "image/jpeg");
  EXPECT_EQ(content_type_of("logo.svg"), "image/svg+xml");
  EXPECT_EQ(content_type_of("recording.mcap"), "application/octet-stream");
  EXPECT_EQ(content_type_of("camera.mp4"), "video/mp4");
  EXPECT_EQ(content_type_of("steps.csv"), "text/csv; charset=utf-8");
  EXPECT_EQ(content_type_of("notes.txt"), "text/plain; charset=utf-8");
  EXPECT_EQ(content_type_of("zstd.wasm"), "application/wasm");
  EXPECT_EQ(content_type_of("no_extension"), "application/octet-stream");
}

TEST(StaticFiles, RelativePathsDecodeAndRefuseToLeaveTheFolder) {
  EXPECT_EQ(relative_path("/", "/"), "");
  EXPECT_EQ(relative_path("/index.html?x=1#top", "/"), "index.html");
  EXPECT_EQ(relative_path("/assets/app%20one.js", "/"), "assets/app one.js");
  EXPECT_EQ(relative_path("//a/./b//c", "/"), "a/b/c");
  EXPECT_EQ(relative_path("/files/run/recording.mcap", "/files/"), "run/recording.mcap");
  EXPECT_EQ(relative_path("/files", "/files/"), "");
  EXPECT_EQ(relative_path("/other", "/files/"), std::nullopt);
  for (const char* bad :
       {"/../etc/passwd", "/a/../../etc/passwd", "/%2e%2e/etc/passwd", "/a/%2E%2E/%2e%2e/x",
        "/..%2fetc%2fpasswd", "/a%00b", "/a%5c..%5cb", "/a\\b", "/%zz", "/%4"})
    EXPECT_EQ(relative_path(bad, "/"), std::nullopt) << bad;
}

TEST(StaticFiles, ByteRanges) {
  using K = ByteRange::Kind;
  auto r = parse_range("bytes=0-9", 100);
  EXPECT_EQ(r.kind, K::kPart);
  EXPECT_EQ(r.offset, 0u);
  EXPECT_EQ(r.length, 10u);
  r = parse_range("bytes=90-", 100);
  EXPECT_EQ(r.kind, K::kPart);
  EXPECT_EQ(r.offset, 90u);
  EXPECT_EQ(r.length, 10u);
  r = parse_range("bytes=-5", 100);
  EXPECT_EQ(r.offset, 95u);
  EXPECT_EQ(r.length, 5u);
  r = parse_range("bytes=50-500", 100);  // clipped to the end
  EXPECT_EQ(r.length, 50u);
  EXPECT_EQ(parse_range("bytes=100-", 100).kind, K::kUnsatisfiable);
  EXPECT_EQ(parse_range("bytes=0-1,5-6", 100).kind, K::kWhole);
  EXPECT_EQ(parse_range("items=0-1", 100).kind, K::kWhole);
  EXPECT_EQ(parse_range("bytes=x-1", 100).kind, K::kWhole);
  EXPECT_EQ(parse_range("bytes=9-1", 100).kind, K::kWhole);
}

TEST(StaticFiles, ServesFilesIndexAndNotFound) {
  TempDir dir;
  dir.write("index.html", "<html>dash</html>");
  dir.write("assets/app.js", "console.log(1)");
  StaticFiles files(dir.path(), "/");
  HttpAnswer a = files.answer(get("/"));
  EXPECT_EQ(a.status, 200u);
  EXPECT_EQ(a.content_type, "text/html; charset=utf-8");
  EXPECT_EQ(fs::path(a.file), fs::canonical(dir.path() / "index.html"));
  EXPECT_EQ(a.file_length, 17u);
  a = files.answer(get("/assets/app.js?v=3"));
  EXPECT_EQ(a.status, 200u);
  EXPECT_EQ(a.content_type, "text/javascript; charset=utf-8");
  EXPECT_EQ(a.file_length, 14u);
  EXPECT_EQ(files.answer(get("/assets/missing.js")).status, 404u);
  EXPECT_EQ(files.answer(get("/assets/")).status, 404u);  // a folder without index.html
  EXPECT_EQ(files.answer({"POST", "/", ""}).status, 405u);
  EXPECT_EQ(files.answer({"HEAD", "/", ""}).status, 200u);
  a = files.answer(get("/index.html", "bytes=6-9"));
  EXPECT_EQ(a.status, 206u);
  EXPECT_EQ(a.file_offset, 6u);
  EXPECT_EQ(a.file_length, 4u);
  bool has_range = false;
  for (const auto& [k, v] : a.headers) has_range |= k == "Content-Range" && v == "bytes 6-9/17";
  EXPECT_TRUE(has_range);
  EXPECT_EQ(files.answer(get("/index.html", "bytes=17-")).status, 416u);
}

TEST(StaticFiles, TraversalAndSymbolicLinksOutOfTheFolderAre404) {
  TempDir outside;
  outside.write("secret.txt", "secret");
  TempDir dir;
  dir.write("run/summary.json", "{}");
  fs::create_symlink(outside.path() / "secret.txt", dir.path() / "run" / "link.txt");
  fs::create_symlink(outside.path(), dir.path() / "run" / "outside");
  fs::create_symlink(dir.path() / "run" / "summary.json", dir.path() / "run" / "inside.json");
  StaticFiles files(dir.path(), "/files/");
  EXPECT_EQ(files.answer(get("/files/run/summary.json")).status, 200u);
  EXPECT_EQ(files.answer(get("/files/run/inside.json")).status, 200u);  // a link inside
  for (const char* bad :
       {"/files/run/link.txt", "/files/run/outside/secret.txt", "/files/../secret.txt",
        "/files/run/%2e%2e/%2e%2e/etc/passwd", "/files/%2Fetc%2Fpasswd", "/files//etc/passwd",
        "/etc/passwd", "/files/run/summary.json%00.html"}) {
    const HttpAnswer a = files.answer(get(bad));
    EXPECT_EQ(a.status, 404u) << bad;
    EXPECT_TRUE(a.file.empty()) << bad;
  }
}

TEST(StaticFiles, TheHandlerRoutesFilesAndSaysWhenTheDashboardIsNotBuilt) {
  TempDir run;
  run.write("recording.mcap", "MCAP");
  TempDir dashboard;
  const fs::path missing = dashboard.path() / "dist";  // not built yet
  auto handler = make_http_handler(missing, run.path(), no_dashboard_page(missing, "files\n"));
  HttpAnswer a = handler(get("/"));
  EXPECT_EQ(a.status, 200u);
  EXPECT_EQ(a.content_type, "text/plain; charset=utf-8");
  EXPECT_NE(a.body.find("npm run build"), std::string::npos) << a.body;
  EXPECT_EQ(handler(get("/app.js")).status, 404u);
  a = handler(get("/files/recording.mcap"));
  EXPECT_EQ(a.status, 200u);
  EXPECT_EQ(a.content_type, "application/octet-stream");
  a = handler(get("/files/"));  // a listing
  EXPECT_EQ(a.status, 200u);
  EXPECT_NE(a.body.find("/files/recording.mcap"), std::string::npos) << a.body;
  // Built later: served without a restart.
  fs::create_directories(missing);
  std::ofstream(missing / "index.html") << "<html></html>";
  a = handler(get("/?mcap=files/recording.mcap"));
  EXPECT_EQ(a.status, 200u);
  EXPECT_EQ(a.content_type, "text/html; charset=utf-8");
}

}  // namespace
}  // namespace convoy::live
