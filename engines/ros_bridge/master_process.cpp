// Reaching the ROS master and starting one (master_process.h).
#include "master_process.h"

#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <vector>

namespace convoy::ros_bridge {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

namespace {

constexpr char kGetPid[] =
    "<?xml version=\"1.0\"?><methodCall><methodName>getPid</methodName><params><param>"
    "<value><string>/convoy_probe</string></value></param></params></methodCall>";

int remaining_ms(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now()).count();
  return left > 0 ? static_cast<int>(left) : 0;
}

// Connects within the deadline: the socket, or -1 and why not.
int connect_until(const addrinfo* a, Clock::time_point deadline, std::string* why) {
  const int fd = socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    *why = std::strerror(errno);
    return -1;
  }
  if (connect(fd, a->ai_addr, a->ai_addrlen) == 0) return fd;
  if (errno == EINPROGRESS) {
    pollfd p{fd, POLLOUT, 0};
    const int n = poll(&p, 1, remaining_ms(deadline));
    int err = 0;
    socklen_t len = sizeof err;
    if (n > 0 && getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len) == 0 && err == 0) return fd;
    *why = n == 0 ? "no connection within the time" : std::strerror(n < 0 ? errno : err);
  } else {
    *why = std::strerror(errno);
  }
  close(fd);
  return -1;
}

// Sends getPid and reads the answer until the deadline: "" for an XML-RPC methodResponse,
// else what happened.
std::string asks_pid(int fd, const MasterUri& uri, Clock::time_point deadline) {
  const std::string body = kGetPid;
  const std::string request =
      "POST /RPC2 HTTP/1.0\r\nHost: " + uri.host + ":" + std::to_string(uri.port) +
      "\r\nContent-Type: text/xml\r\nContent-length: " + std::to_string(body.size()) + "\r\n\r\n" +
      body;
  size_t sent = 0;
  std::string answer;
  char buf[4096];
  while (remaining_ms(deadline) > 0) {
    pollfd p{fd, static_cast<short>(sent < request.size() ? POLLOUT : POLLIN), 0};
    if (poll(&p, 1, remaining_ms(deadline)) <= 0) break;
    if (sent < request.size()) {
      const ssize_t n = send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
      if (n <= 0)
        return "the connection failed while asking (" + std::string(std::strerror(errno)) + ")";
      sent += static_cast<size_t>(n);
      continue;
    }
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n <= 0) return "it accepted the connection but closed it without an XML-RPC answer";
    answer.append(buf, static_cast<size_t>(n));
    if (answer.find("</methodResponse>") != std::string::npos) return "";
  }
  return "it accepted the connection but gave no XML-RPC answer in time";
}

}  // namespace

MasterProbe probe_master(const MasterUri& uri, milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(uri.port);
  if (int rc = getaddrinfo(uri.host.c_str(), port.c_str(), &hints, &found); rc != 0)
    return {MasterProbe::kNothing, "unknown host " + uri.host + " (" + gai_strerror(rc) + ")"};
  MasterProbe probe{MasterProbe::kNothing, "no address"};
  for (const addrinfo* a = found; a; a = a->ai_next) {
    const int fd = connect_until(a, deadline, &probe.why);
    if (fd < 0) continue;
    const std::string why = asks_pid(fd, uri, deadline);
    close(fd);
    probe = why.empty() ? MasterProbe{MasterProbe::kMaster, ""}
                        : MasterProbe{MasterProbe::kNotMaster, why};
    break;
  }
  freeaddrinfo(found);
  return probe;
}

void MasterProcess::start(const MasterUri& uri, const std::filesystem::path& log,
                          milliseconds timeout) {
  const std::string port = std::to_string(uri.port);
  const std::string command = "rosmaster --core -p " + port;
  int log_fd = -1;
  if (!log.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(log.parent_path(), ec);
    log_fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  }
  // Everything the child needs is prepared before fork(): only async-signal-safe calls after.
  std::vector<std::string> env_text;
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "ROS_MASTER_URI=", 15) != 0) env_text.emplace_back(*e);
  env_text.push_back("ROS_MASTER_URI=" + uri.text);
  std::vector<char*> envp;
  for (auto& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);
  const char* argv[] = {"rosmaster", "--core", "-p", port.c_str(), nullptr};
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start " + command + ": " + std::strerror(errno));
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(1);
    setpgid(0, 0);
    if (log_fd >= 0) {
      dup2(log_fd, STDOUT_FILENO);
      dup2(log_fd, STDERR_FILENO);
    } else {
      dup2(STDERR_FILENO, STDOUT_FILENO);
    }
    execvpe(argv[0], const_cast<char* const*>(argv), envp.data());
    constexpr char kFailed[] = "cannot run rosmaster (not on PATH?)\n";
    [[maybe_unused]] ssize_t n = write(STDERR_FILENO, kFailed, sizeof kFailed - 1);
    _exit(127);
  }
  if (log_fd >= 0) close(log_fd);
  pid_ = pid;
  const std::string where = log.empty() ? "" : " (its output: " + log.string() + ")";
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      throw std::runtime_error(command + " exited with status " + std::to_string(code) +
                               (code == 127 ? " (is rosmaster installed? python3-rosmaster)" : "") +
                               " before it answered" + where);
    }
    if (probe_master(uri, milliseconds(500)).state == MasterProbe::kMaster) return;
    if (Clock::now() > deadline) {
      stop();
      throw std::runtime_error(command + " did not answer at " + uri.text + " within " +
                               std::to_string(timeout.count() / 1000.0).substr(0, 4) + " s" +
                               where);
    }
    std::this_thread::sleep_for(milliseconds(50));
  }
}

void MasterProcess::stop() {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  const auto deadline = Clock::now() + milliseconds(2000);
  int status = 0;
  while (waitpid(pid_, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status, 0);
      break;
    }
    std::this_thread::sleep_for(milliseconds(20));
  }
  pid_ = -1;
}

}  // namespace convoy::ros_bridge
