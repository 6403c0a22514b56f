#include "app/nrp_server.h"

#include <pybind11/embed.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <nlohmann/json.hpp>

#include "app/simulation.h"
#include "convoy/datapacks.pb.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "datapack/camera.h"
#include "datapack/json.h"
#include "datapack/registry.h"
#include "nrp_protobuf/gazebo.pb.h"
#include "transport/grpc_security.h"

namespace convoy::app {

namespace fs = std::filesystem;
namespace py = pybind11;

namespace {

constexpr std::string_view kTypeUrlPrefix = "type.googleapis.com/";

std::string type_of(const google::protobuf::Any& any) {
  const std::string& url = any.type_url();
  const size_t slash = url.rfind('/');
  return slash == std::string::npos ? url : url.substr(slash + 1);
}

// The client's datapacks as the engines' datapacks. Throws std::invalid_argument naming a
// datapack that cannot be read.
std::vector<engine::DataPack> from_client(const ::NrpCore::DataPacks& in) {
  std::vector<engine::DataPack> out;
  datapack::InlineBlobWriter writer;
  for (const auto& msg : in.jsondatapacks()) {
    const auto& id = msg.datapackid();
    const std::string what =
        "JSON datapack '" + id.datapackname() + "' for engine '" + id.enginename() + "'";
    ::NrpCore::JsonMessage json;
    if (!msg.data().UnpackTo(&json))
      throw std::invalid_argument(what + " does not hold a JsonMessage but a " +
                                  type_of(msg.data()));
    nlohmann::json value = nlohmann::json::parse(json.data(), nullptr, /*allow_exceptions=*/false);
    if (value.is_discarded()) throw std::invalid_argument(what + " is not valid JSON");
    auto& dp = out.emplace_back();
    dp.mutable_id()->set_name(id.datapackname());
    dp.mutable_id()->set_engine_name(id.enginename());
    datapack::Builder builder(&dp, writer);
    datapack::write_json(builder, value);
  }
  for (const auto& msg : in.protodatapacks()) {
    const auto& id = msg.datapackid();
    const std::string type = type_of(msg.data());
    if (type.empty()) {
      throw std::invalid_argument("protobuf datapack '" + id.datapackname() + "' for engine '" +
                                  id.enginename() + "' holds no message");
    }
    auto& dp = out.emplace_back();
    dp.mutable_id()->set_name(id.datapackname());
    dp.mutable_id()->set_engine_name(id.enginename());
    dp.mutable_id()->set_type(type);
    dp.mutable_proto()->set_type_name(type);
    dp.mutable_proto()->set_data(msg.data().value());
  }
  return out;
}

// A datapack whose blobs are inline as a self-contained message for the client: JSON as text,
// Convoy's standard camera, joint and link under NRP-Core's names (Gazebo.Camera / Joint /
// Link, the messages of NRP-Core's GazeboCameraDataPack...), so that NRP-Core's own client
// decodes them, any other protobuf message as it is.
void to_client(const engine::DataPack& dp, ::NrpCore::TrajectoryMessage* out) {
  datapack::View view(dp, datapack::inline_blob_reader());
  auto* any = out->mutable_data();
  if (view.is_json()) {
    ::NrpCore::JsonMessage json;
    json.set_data(datapack::json_text(view));
    any->PackFrom(json);
    return;
  }
  const std::string& type = view.proto_type();
  if (type == datapack::type_name<data::Camera>()) {
    const datapack::CameraImage image = datapack::read_camera(view);
    Gazebo::Camera camera;
    camera.set_imageheight(image.height);
    camera.set_imagewidth(image.width);
    camera.set_imagedepth(image.depth);
    camera.set_imagedata(image.pixels.data(), image.pixels.size());
    any->PackFrom(camera);
    return;
  }
  // Joint and Link: the same field numbers and types in both packages (datapack/nrp.h).
  std::string_view nrp_type = type;
  if (type == datapack::type_name<data::Joint>())
    nrp_type = Gazebo::Joint::descriptor()->full_name();
  if (type == datapack::type_name<data::Link>()) nrp_type = Gazebo::Link::descriptor()->full_name();
  any->set_type_url(std::string(kTypeUrlPrefix) + std::string(nrp_type));
  any->set_value(dp.proto().data());
}

}  // namespace

NrpServer::NrpServer(const config::SimulationConfig& cfg, fs::path run_dir, RunLog& log)
    : cfg_(cfg), run_dir_(std::move(run_dir)), log_(log) {}

NrpServer::~NrpServer() { stop_local(); }

void NrpServer::stop_local() {
  if (!local_) return;
  // Its thread takes the GIL to drop its thread state as it ends: a caller holding the GIL
  // lets it go meanwhile.
  if (Py_IsInitialized() && PyGILState_Check()) {
    py::gil_scoped_release release;
    local_.reset();
  } else {
    local_.reset();
  }
}

const char* NrpServer::name(State s) {
  switch (s) {
    case State::kCreated:
      return "Created";
    case State::kInitialized:
      return "Initialized";
    case State::kRunning:
      return "Running";
    case State::kStopped:
      return "Stopped";
    case State::kFailed:
      return "Failed";
  }
  return "";
}

void NrpServer::listen(const std::string& address, bool insecure) {
  if (!insecure && !transport::is_loopback_address(address)) {
    throw UserError("--server_address " + address +
                    " is not a loopback address: the NRP-Core server has neither TLS nor a "
                    "token, so anyone who reaches it could step the simulation and feed it "
                    "datapacks. Listen on localhost (127.0.0.1), or say --insecure");
  }
  if (insecure && !transport::is_loopback_address(address))
    log_.info("warning: --insecure: serving at " + address + " without TLS or token");
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(address, grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(this);
  server_ = builder.BuildAndStart();
  if (!server_ || port == 0) {
    server_.reset();
    throw UserError("--server_address " + address +
                    ": cannot listen there (address in use, or not an address of this machine)");
  }
  log_.info("serving NRP-Core clients at " + address);
}

void NrpServer::listen_local(const std::string& path) {
  // The serving thread keeps one Python thread state for its life: without it each call's
  // GIL acquisition (request()) made and freed a thread state, its frame stack mapped and
  // unmapped, every step.
  const auto with_thread_state = [](const std::function<void()>& body) {
    py::gil_scoped_acquire gil;
    py::gil_scoped_release release;  // keeps the thread state, frees the GIL between calls
    body();
  };
  // pybind11's state is made on first use: here, by this thread (which holds the GIL), not by
  // the serving thread racing the first use of this one.
  py::detail::get_internals();
  try {
    local_ = std::make_unique<transport::LocalRpcServer>(
        path,
        [this](uint8_t method, const std::string& request) { return local_call(method, request); },
        with_thread_state);
  } catch (const std::runtime_error& e) {
    throw UserError(std::string("--local_socket: ") + e.what());
  }
  log_.info("serving NRP-Core clients at the local socket " + path + " too");
}

template <typename In, typename Out, typename Call>
transport::LocalReply NrpServer::local(const std::string& request, Call call) {
  In in;
  if (!in.ParseFromString(request))
    return {grpc::StatusCode::INVALID_ARGUMENT, "the local call's request does not parse"};
  Out out;
  const grpc::Status status = (this->*call)(nullptr, &in, &out);
  if (!status.ok()) return {status.error_code(), status.error_message()};
  return {0, out.SerializeAsString()};
}

transport::LocalReply NrpServer::local_call(uint8_t method, const std::string& request) {
  using namespace ::NrpCore;
  switch (method) {
    case 0:
      return local<EmptyMessage, InitializeResponse>(request, &NrpServer::initialize);
    case 1:
      return local<RunLoopMessage, RunLoopResponse>(request, &NrpServer::runLoop);
    case 2:
      return local<EmptyMessage, RunLoopResponse>(request, &NrpServer::runUntilTimeout);
    case 3:
      return local<EmptyMessage, Response>(request, &NrpServer::stopLoop);
    case 4:
      return local<ResetMessage, ResetResponse>(request, &NrpServer::reset);
    case 5:
      return local<EmptyMessage, Response>(request, &NrpServer::shutdown);
    case 6:
      return local<TypeRequest, TypeDescription>(request, &NrpServer::describeType);
  }
  return {grpc::StatusCode::UNIMPLEMENTED, "no method " + std::to_string(method)};
}

void NrpServer::wait(pid_t parent) {
  std::unique_lock<std::mutex> lock(done_mutex_);
  while (!shut_down_) {
    done_cv_.wait_for(lock, std::chrono::milliseconds(100));
    if (job_ && !job_done_) {
      lock.unlock();
      (*job_)();
      lock.lock();
      job_done_ = true;
      done_cv_.notify_all();
      continue;
    }
    if (interrupted()) break;
    if (parent > 0 && getppid() != parent) {
      log_.info("the client that started this server is gone: shutting down");
      interrupt_signal().store(SIGTERM);
      break;
    }
  }
}

void NrpServer::run_in_main_thread(const std::function<void()>& job) {
  std::exception_ptr thrown;
  const std::function<void()> guarded = [&] {
    try {
      job();
    } catch (...) {
      thrown = std::current_exception();
    }
  };
  {
    std::unique_lock<std::mutex> lock(done_mutex_);
    job_ = &guarded;
    job_done_ = false;
    done_cv_.notify_all();
    // The main thread has left wait() only on an interrupt: then nothing runs the job.
    while (!job_done_ && !interrupted()) done_cv_.wait_for(lock, std::chrono::milliseconds(100));
    const bool ran = job_done_;
    job_ = nullptr;
    if (!ran) throw EngineError("", interrupted_text());
  }
  if (thrown) std::rethrow_exception(thrown);
}

void NrpServer::stop_serving() {
  stop_ = true;
  stop_local();
  if (server_) server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(5));
}

void NrpServer::finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!session_) return;
  figures_ = session_->figures();
  std::string error = session_->shut_down(exit_code_ == kExitOk && !interrupted());
  if (!error.empty() && exit_code_ == kExitOk) {
    exit_code_ = kExitEngineError;
    error_ = error;
  }
  session_.reset();
}

void NrpServer::fail(const std::string& message, int code) {
  state_ = State::kFailed;
  error_message_ = message;
  if (exit_code_ == kExitOk) {
    exit_code_ = code;
    error_ = message;
  }
  log_.error(message);
}

void NrpServer::set_state(::NrpCore::SimStateMessage* out) const {
  out->set_currentstate(name(state_));
  out->set_errormsg(state_ == State::kFailed ? error_message_ : "");
}

template <typename F>
grpc::Status NrpServer::request(const char* what, std::initializer_list<State> from,
                                ::NrpCore::SimStateMessage* state, F&& action) {
  std::lock_guard<std::mutex> lock(mutex_);
  const State now = state_;
  if (std::find(from.begin(), from.end(), now) == from.end()) {
    std::string hint = now == State::kCreated ? " (call initialize() first)"
                       : now == State::kFailed
                           ? " (it failed: " + error_message_ + "; only shutdown() is possible)"
                           : "";
    return grpc::Status(
        grpc::StatusCode::FAILED_PRECONDITION,
        std::string("can't ") + what + " the simulation in state \"" + name(now) + "\"" + hint);
  }
  py::gil_scoped_acquire gil;
  try {
    action();
  } catch (const std::invalid_argument& e) {
    // The client's request was wrong, not the simulation: nothing has changed.
    if (state_ == State::kRunning) state_ = now;
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, e.what());
  } catch (...) {
    Outcome outcome = outcome_of(std::current_exception());
    fail(outcome.error, outcome.code);
  }
  set_state(state);
  return grpc::Status::OK;
}

void NrpServer::check_engine(const engine::DataPack& dp) const {
  if (session_->loop().has_engine(dp.id().engine_name())) return;
  std::string list;
  for (const auto& e : cfg_.engines) list += (list.empty() ? "" : ", ") + e.name;
  throw std::invalid_argument("datapack '" + dp.id().name() + "' is for unknown engine '" +
                              dp.id().engine_name() + "' (engines: " + list + ")");
}

void NrpServer::take_trajectory(::NrpCore::Trajectory* out) {
  int32_t index = 0;
  for (const auto& dp : session_->loop().take_observations()) {
    auto* item = dp.payload_case() == engine::DataPack::kJsonMsgpack
                     ? out->add_jsontrajectorymessages()
                     : out->add_prototrajectorymessages();
    item->set_dataindex(index++);
    to_client(dp, item);
  }
}

grpc::Status NrpServer::initialize(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                                   ::NrpCore::InitializeResponse* out) {
  return request("initialize", {State::kCreated}, out->mutable_simstate(), [&] {
    session_ = std::make_unique<Session>(cfg_, run_dir_, log_, /*quiet=*/true);
    {
      py::gil_scoped_release release;  // the main thread takes it
      run_in_main_thread([&] {
        py::gil_scoped_acquire gil;
        session_->initialize(/*keep_observations=*/true);
      });
    }
    state_ = State::kInitialized;
    take_trajectory(out->mutable_trajectory());
  });
}

grpc::Status NrpServer::runLoop(grpc::ServerContext*, const ::NrpCore::RunLoopMessage* in,
                                ::NrpCore::RunLoopResponse* out) {
  return request("run", {State::kInitialized, State::kStopped}, out->mutable_simstate(), [&] {
    if (in->numiterations() < 0)
      throw std::invalid_argument("numIterations must be >= 0, got " +
                                  std::to_string(in->numiterations()));
    std::vector<engine::DataPack> inputs = from_client(in->datapacks());
    for (const auto& dp : inputs) check_engine(dp);
    for (auto& dp : inputs) session_->loop().add_input(std::move(dp));
    stop_ = false;
    state_ = State::kRunning;
    session_->run_steps(static_cast<uint32_t>(in->numiterations()), stop_);
    if (interrupted()) throw EngineError("", interrupted_text());
    state_ = State::kStopped;
    out->set_doneflag(session_->loop().done());
    out->set_timeoutflag(session_->timed_out());
    // As NRP-Core: the status function's data go back when it says done.
    if (out->doneflag()) take_trajectory(out->mutable_trajectory());
  });
}

grpc::Status NrpServer::runUntilTimeout(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                                        ::NrpCore::RunLoopResponse* out) {
  return request("run", {State::kInitialized, State::kStopped}, out->mutable_simstate(), [&] {
    stop_ = false;
    state_ = State::kRunning;
    session_->run_until_done_or_timeout(stop_);
    if (interrupted()) throw EngineError("", interrupted_text());
    state_ = State::kStopped;
    out->set_doneflag(session_->loop().done());
    out->set_timeoutflag(session_->timed_out());
    take_trajectory(out->mutable_trajectory());
  });
}

grpc::Status NrpServer::stopLoop(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                                 ::NrpCore::Response* out) {
  // Not under the lock: a run in progress holds it, and stops between two cycles.
  const State now = state_;
  if (now == State::kCreated || now == State::kFailed) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        std::string("can't stop the simulation in state \"") + name(now) + "\"");
  }
  stop_ = true;
  out->mutable_simstate()->set_currentstate(name(now));
  return grpc::Status::OK;
}

grpc::Status NrpServer::reset(grpc::ServerContext*, const ::NrpCore::ResetMessage* in,
                              ::NrpCore::ResetResponse* out) {
  return request("reset", {State::kInitialized, State::kStopped}, out->mutable_simstate(), [&] {
    std::vector<engine::DataPack> inputs = from_client(in->datapacks());
    for (const auto& dp : inputs) check_engine(dp);
    session_->reset(std::move(inputs));
    state_ = State::kInitialized;
    take_trajectory(out->mutable_trajectory());
  });
}

grpc::Status NrpServer::shutdown(grpc::ServerContext*, const ::NrpCore::EmptyMessage*,
                                 ::NrpCore::Response* out) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (session_) {
      py::gil_scoped_acquire gil;
      figures_ = session_->figures();
      std::string error = session_->shut_down(state_ != State::kFailed);
      if (!error.empty() && exit_code_ == kExitOk) {
        exit_code_ = kExitEngineError;
        error_ = error;
      }
      session_.reset();
    }
    state_ = State::kCreated;
    set_state(out->mutable_simstate());
  }
  {
    std::lock_guard<std::mutex> lock(done_mutex_);
    shut_down_ = true;
  }
  done_cv_.notify_all();
  return grpc::Status::OK;
}

grpc::Status NrpServer::describeType(grpc::ServerContext*, const ::NrpCore::TypeRequest* in,
                                     ::NrpCore::TypeDescription* out) {
  try {
    auto& registry = datapack::Registry::global();
    if (!registry.find(in->typename_())) registry.add_by_name(in->typename_());
    out->set_filedescriptorset(registry.file_descriptor_set(in->typename_()));
  } catch (const std::exception& e) {
    return grpc::Status(grpc::StatusCode::NOT_FOUND, e.what());
  }
  return grpc::Status::OK;
}

}  // namespace convoy::app
