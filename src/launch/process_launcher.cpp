#include "launch/process_launcher.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace convoy::launch {

namespace {

std::string resolve_program(const LaunchSpec& spec) {
  if (spec.program.find('/') != std::string::npos) return spec.program;
  for (const auto& dir : spec.search_dirs) {
    auto p = dir / spec.program;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  const char* path = getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    size_t end = dirs.find(':', start);
    if (end == std::string::npos) end = dirs.size();
    std::string p = dirs.substr(start, end - start) + "/" + spec.program;
    if (access(p.c_str(), X_OK) == 0) return p;
    start = end + 1;
  }
  throw std::runtime_error("program '" + spec.program +
                           "' not found (searched the Convoy bin "
                           "directory and PATH)");
}

[[noreturn]] void child_fail(int pipe_fd, int err) {
  ssize_t ignored = write(pipe_fd, &err, sizeof err);
  (void)ignored;
  _exit(127);
}

}  // namespace

ChildProcess launch(const LaunchSpec& spec) {
  std::string program = resolve_program(spec);
  std::vector<std::string> argv_s{program};
  argv_s.insert(argv_s.end(), spec.args.begin(), spec.args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);

  std::vector<std::string> env_s;
  for (char** e = environ; *e; ++e) env_s.emplace_back(*e);
  for (const auto& kv : spec.env) {
    auto eq = kv.find('=');
    std::string key = kv.substr(0, eq);
    std::erase_if(env_s, [&](const std::string& s) { return s.rfind(key + "=", 0) == 0; });
    env_s.push_back(kv);
  }
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);

  int log_fd = open(spec.log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) {
    throw std::runtime_error("cannot open log file " + spec.log_file.string() + ": " +
                             std::strerror(errno));
  }
  int err_pipe[2];
  if (pipe2(err_pipe, O_CLOEXEC) != 0) {
    close(log_fd);
    throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  }
  pid_t parent = getpid();
  pid_t pid = fork();
  if (pid < 0) {
    close(log_fd);
    close(err_pipe[0]);
    close(err_pipe[1]);
    throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  }
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(1);  // the coordinator died before prctl
    // Restore default signal handling for the engine.
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, 0);
    if (dup2(log_fd, 1) < 0 || dup2(log_fd, 2) < 0) child_fail(err_pipe[1], errno);
    // Move the passed fds out of the way first, then into place (3, 4, ...).
    // (No allocation here: the parent may have threads.)
    int moved[16];
    size_t n_moved = std::min<size_t>(spec.pass_fds.size(), 16);
    for (size_t i = 0; i < n_moved; ++i) {
      moved[i] = fcntl(spec.pass_fds[i], F_DUPFD_CLOEXEC, 64);
      if (moved[i] < 0) child_fail(err_pipe[1], errno);
    }
    for (size_t i = 0; i < n_moved; ++i) {
      if (dup2(moved[i], static_cast<int>(3 + i)) < 0) child_fail(err_pipe[1], errno);
    }
    if (!spec.working_dir.empty() && chdir(spec.working_dir.c_str()) != 0)
      child_fail(err_pipe[1], errno);
    execve(program.c_str(), argv.data(), envp.data());
    child_fail(err_pipe[1], errno);
  }
  setpgid(pid, pid);
  close(log_fd);
  close(err_pipe[1]);
  int child_errno = 0;
  ssize_t n;
  do {
    n = read(err_pipe[0], &child_errno, sizeof child_errno);
  } while (n < 0 && errno == EINTR);
  close(err_pipe[0]);
  ChildProcess child(pid);
  if (n == sizeof child_errno) {
    child.wait_for(1.0);
    throw std::runtime_error("cannot execute '" + program + "': " + std::strerror(child_errno));
  }
  return child;
}

bool ChildProcess::poll() {
  if (pid_ <= 0 || exited_) return exited_;
  int st = 0;
  pid_t r = waitpid(pid_, &st, WNOHANG);
  if (r == pid_) {
    exited_ = true;
    status_ = st;
  } else if (r < 0 && errno == ECHILD) {
    exited_ = true;
  }
  return exited_;
}

bool ChildProcess::wait_for(double seconds) {
  auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!poll()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

void ChildProcess::signal_group(int sig) {
  if (pid_ <= 0) return;
  if (kill(-pid_, sig) != 0 && !exited_) kill(pid_, sig);
}

void ChildProcess::terminate(double grace) {
  if (pid_ <= 0) return;
  if (!poll()) {
    signal_group(SIGTERM);
    if (!wait_for(grace)) {
      signal_group(SIGKILL);
      wait_for(5.0);
    }
  }
  // Whatever the engine itself started goes too.
  kill(-pid_, SIGKILL);
}

std::string ChildProcess::describe() const {
  if (!exited_) return "still running";
  if (WIFEXITED(status_)) return "exited with status " + std::to_string(WEXITSTATUS(status_));
  if (WIFSIGNALED(status_)) {
    int sig = WTERMSIG(status_);
    return "killed by signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
  }
  return "ended";
}

}  // namespace convoy::launch
