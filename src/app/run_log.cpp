#include "app/run_log.h"

#include <chrono>
#include <ctime>

namespace convoy::app {

RunLog::~RunLog() {
  if (file_) std::fclose(file_);
}

void RunLog::open(const std::filesystem::path& file) { file_ = std::fopen(file.c_str(), "a"); }

void RunLog::write(const char* level, const std::string& text) {
  if (sink) sink(level[0] == 'e', text);
  if (!file_) return;
  auto now = std::chrono::system_clock::now();
  std::time_t t = std::chrono::system_clock::to_time_t(now);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", std::localtime(&t));
  std::fprintf(file_, "%s [%s] %s\n", stamp, level, text.c_str());
  std::fflush(file_);
}

void RunLog::info(const std::string& line) {
  write("info", line);
  if (!quiet) std::fprintf(stderr, "%s\n", line.c_str());
}

void RunLog::error(const std::string& text) {
  write("error", text);
  std::fprintf(stderr, "error: %s\n", text.c_str());
}

}  // namespace convoy::app
