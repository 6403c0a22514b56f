// NRP-Core's server mode: `NRPCoreSim -c CONFIG -m server --server_address HOST:PORT` serves
// the gRPC service NrpCore (proto/convoy/nrp_server.proto) to a Python client
// (python/nrp_client), which initializes, steps, resets and shuts the simulation down.
//
// A synchronous gRPC server: each call runs in the gRPC thread that received it, holding the
// Python GIL, one call at a time (stopLoop excepted: it only sets a flag the loop reads between
// cycles). The states and their transitions are NRP-Core's:
//   Created -initialize-> Initialized -runLoop/runUntilTimeout-> Stopped -reset-> Initialized
//   any failure -> Failed (only shutdown then); shutdown -> Created, and the server exits.
#pragma once

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "app/run_log.h"
#include "app/session.h"
#include "config/simulation_config.h"
#include "convoy/nrp_server.grpc.pb.h"
#include "transport/local_rpc.h"

namespace convoy::app {

class NrpServer final : public NrpCore::NrpCore::Service {
 public:
  NrpServer(const config::SimulationConfig& cfg, std::filesystem::path run_dir, RunLog& log);
  ~NrpServer() override;

  // Listens at `address` (HOST:PORT): the loopback only, unless `insecure`. Throws UserError
  // when it cannot.
  void listen(const std::string& address, bool insecure);
  // Also serves the same calls at the Unix socket `path` (transport/local_rpc.h), method byte
  // = the call's index in the service: 0 initialize, 1 runLoop, 2 runUntilTimeout, 3 stopLoop,
  // 4 reset, 5 shutdown, 6 describeType. Throws UserError naming --local_socket.
  void listen_local(const std::string& path);
  // Blocks until a client's shutdown, an interrupt, or (with `parent` > 0) the exit of the
  // process `parent` (the client that started the server with --slave). Meanwhile runs the
  // jobs that must run in this thread. Call from the main thread, without the GIL.
  void wait(pid_t parent);
  // Stops serving: waits for the call in progress, refuses new ones.
  void stop_serving();
  // Shuts the engines down if a client did not. Needs the GIL.
  void finish();

  // How the run went: the first failure, if any; the loop's figures.
  int exit_code() const { return exit_code_; }
  const std::string& error() const { return error_; }
  const LoopFigures& figures() const { return figures_; }

 private:
  enum class State { kCreated, kInitialized, kRunning, kStopped, kFailed };
  static const char* name(State s);

  grpc::Status initialize(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                          ::NrpCore::InitializeResponse* out) override;
  grpc::Status runLoop(grpc::ServerContext*, const ::NrpCore::RunLoopMessage* in,
                       ::NrpCore::RunLoopResponse* out) override;
  grpc::Status runUntilTimeout(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                               ::NrpCore::RunLoopResponse* out) override;
  grpc::Status stopLoop(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                        ::NrpCore::Response* out) override;
  grpc::Status reset(grpc::ServerContext*, const ::NrpCore::ResetMessage* in,
                     ::NrpCore::ResetResponse* out) override;
  grpc::Status shutdown(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                        ::NrpCore::Response* out) override;
  grpc::Status describeType(grpc::ServerContext*, const ::NrpCore::TypeRequest* in,
                            ::NrpCore::TypeDescription* out) override;

  // Runs `action` in state `from...` (else FAILED_PRECONDITION naming the state), under the
  // lock and the GIL; an exception makes the state Failed, with its message in `state`.
  template <typename F>
  grpc::Status request(const char* what, std::initializer_list<State> from,
                       ::NrpCore::SimStateMessage* state, F&& action);
  void fail(const std::string& message, int code);
  transport::LocalReply local_call(uint8_t method, const std::string& request);
  template <typename In, typename Out, typename Call>
  transport::LocalReply local(const std::string& request, Call call);
  void set_state(::NrpCore::SimStateMessage* out) const;
  void take_trajectory(::NrpCore::Trajectory* out);
  // Runs `job` in the thread that called wait(), and returns when it is done. Engines are
  // forked there: a forked engine gets SIGKILL when the thread that forked it ends
  // (PR_SET_PDEATHSIG), and gRPC ends its idle threads.
  void run_in_main_thread(const std::function<void()>& job);
  // Throws std::invalid_argument unless the datapack names an engine of the simulation.
  void check_engine(const engine::DataPack& dp) const;
  // Ends the local socket's serving thread (with or without the GIL held).
  void stop_local();

  const config::SimulationConfig& cfg_;
  std::filesystem::path run_dir_;
  RunLog& log_;
  std::unique_ptr<Session> session_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<transport::LocalRpcServer> local_;
  std::mutex mutex_;  // one call at a time; taken before the GIL
  std::atomic<State> state_{State::kCreated};
  std::string error_message_;  // why the state is Failed
  std::atomic<bool> stop_{false};
  // The end of serving: a client's shutdown.
  std::mutex done_mutex_;
  std::condition_variable done_cv_;
  bool shut_down_ = false;
  const std::function<void()>* job_ = nullptr;  // for the main thread; null when none
  bool job_done_ = false;
  int exit_code_ = 0;
  std::string error_;
  LoopFigures figures_;
};

}  // namespace convoy::app
