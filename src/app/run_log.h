// The coordinator's log: every line goes to <run>/logs/coordinator.log and to stderr.
#pragma once

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>

namespace convoy::app {

class RunLog {
 public:
  RunLog() = default;
  ~RunLog();
  void open(const std::filesystem::path& file);
  void info(const std::string& line);   // stderr unless quiet
  void error(const std::string& text);  // always on stderr
  bool quiet = false;
  // Also gets every line (`error`: an error line), e.g. the live server's /convoy/log.
  std::function<void(bool error, const std::string& line)> sink;

 private:
  void write(const char* level, const std::string& text);
  std::FILE* file_ = nullptr;
};

}  // namespace convoy::app
