// The coordinator's log: every line goes to <run>/logs/coordinator.log and to stderr.
#pragma once

#include <cstdio>
#include <filesystem>
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

 private:
  void write(const char* level, const std::string& text);
  std::FILE* file_ = nullptr;
};

}  // namespace convoy::app
