#include "app/external_processes.h"

#include <cctype>
#include <cstdlib>
#include <map>
#include <stdexcept>

#include "app/simulation.h"
#include "config/simulation_config.h"
#include "core/error.h"

namespace convoy::app {

namespace fs = std::filesystem;

namespace {

void split_into(const std::string& text, std::vector<std::string>* words) {
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    size_t end = i;
    while (end < text.size() && !std::isspace(static_cast<unsigned char>(text[end]))) ++end;
    if (end > i) words->push_back(text.substr(i, end - i));
    i = end;
  }
}

bool name_char(char c, bool first) {
  return c == '_' || std::isalpha(static_cast<unsigned char>(c)) ||
         (!first && std::isdigit(static_cast<unsigned char>(c)));
}

}  // namespace

std::vector<std::string> command_words(const config::ExternalProcessConfig& proc) {
  std::vector<std::string> words;
  split_into(proc.cmd, &words);
  for (const auto& p : proc.start_params) split_into(p, &words);
  return words;
}

std::string expand_variables(const std::string& text,
                             const std::function<std::string(const std::string&)>& lookup) {
  std::string out;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '$' || i + 1 >= text.size()) {
      out += text[i];
      continue;
    }
    if (text[i + 1] == '{') {
      const size_t close = text.find('}', i + 2);
      if (close == std::string::npos) {
        out += text.substr(i);
        break;
      }
      out += lookup(text.substr(i + 2, close - i - 2));
      i = close;
      continue;
    }
    size_t end = i + 1;
    while (end < text.size() && name_char(text[end], end == i + 1)) ++end;
    if (end == i + 1) {
      out += '$';
      continue;
    }
    out += lookup(text.substr(i + 1, end - i - 1));
    i = end - 1;
  }
  return out;
}

std::string external_log_name(const std::string& program, size_t index) {
  std::string base = fs::path(program).filename().string();
  if (!config::name_problem(base).empty() || base.size() > 100) base = "proc";
  return base + "_" + std::to_string(index) + ".log";
}

ExternalProcesses::ExternalProcesses(const config::SimulationConfig& cfg, fs::path log_dir,
                                     double grace_s)
    : procs_(cfg.external_processes),
      config_file_(cfg.file),
      config_dir_(cfg.dir),
      log_dir_(std::move(log_dir)),
      grace_s_(grace_s) {}

ExternalProcesses::~ExternalProcesses() { stop(nullptr); }

void ExternalProcesses::start(RunLog& log) {
  // ProcEnvParams are expanded in order, each seeing the coordinator's environment and the
  // entries before it (NRP-Core evaluates them one `export` after the other).
  for (size_t i = 0; i < procs_.size(); ++i) {
    const auto& proc = procs_[i];
    if (proc.launch_type == "EmptyLaunchCommand") continue;
    const std::vector<std::string> words = command_words(proc);
    launch::LaunchSpec spec;
    spec.program = words.at(0);
    // A relative path runs from the config's folder, where the child starts.
    if (spec.program.find('/') != std::string::npos && fs::path(spec.program).is_relative())
      spec.program = (config_dir_ / spec.program).lexically_normal().string();
    spec.args.assign(words.begin() + 1, words.end());
    std::map<std::string, std::string> set;
    for (const auto& kv : proc.env_params) {
      const size_t eq = kv.find('=');
      const std::string key = kv.substr(0, eq);
      const std::string value = expand_variables(kv.substr(eq + 1), [&](const std::string& name) {
        if (auto it = set.find(name); it != set.end()) return it->second;
        const char* v = std::getenv(name.c_str());
        return std::string(v ? v : "");
      });
      set[key] = value;
      spec.env.push_back(key + "=" + value);
    }
    spec.working_dir = config_dir_;
    spec.log_file = log_dir_ / external_log_name(words[0], i);
    spec.search_dirs = {bin_dir()};
    try {
      started_.push_back({proc.cmd, launch::launch(spec), spec.log_file});
    } catch (const std::exception& e) {
      stop(&log);
      throw UserError(config_file_.string() + ": " + proc.pointer + "/ProcCmd \"" + proc.cmd +
                      "\": " + e.what());
    }
    log.info("started external process \"" + proc.cmd + "\" (pid " +
             std::to_string(started_.back().child.pid()) + ", output in logs/" +
             spec.log_file.filename().string() + ")");
  }
}

void ExternalProcesses::stop(RunLog* log) {
  for (auto& p : started_) {
    if (p.child.poll()) {
      if (log)
        log->info("external process \"" + p.cmd + "\" had ended on its own: " + p.child.describe());
    }
    p.child.terminate(grace_s_);
  }
  started_.clear();
}

size_t ExternalProcesses::running() const {
  size_t n = 0;
  for (const auto& p : started_) n += p.child.running() ? 1 : 0;
  return n;
}

std::optional<ExternalProcesses::Failure> ExternalProcesses::first_failure() {
  for (auto& p : started_) {
    if (!p.child.running() || !p.child.poll()) continue;
    const std::string how = p.child.describe();
    if (how != "exited with status 0") return Failure{"\"" + p.cmd + "\" " + how, p.log};
  }
  return std::nullopt;
}

}  // namespace convoy::app
