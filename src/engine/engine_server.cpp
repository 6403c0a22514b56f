#include "engine/engine_server.h"

#include <google/protobuf/arena.h>
#include <grpcpp/grpcpp.h>

#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <thread>

#include "convoy/engine.grpc.pb.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/utf8.h"
#include "transport/blobs.h"
#include "transport/frame_socket.h"

namespace convoy::engines {

namespace pb = google::protobuf;

namespace {
std::map<std::string, EngineFactory>& registry() {
  static std::map<std::string, EngineFactory> r;
  return r;
}
}  // namespace

bool register_engine(const std::string& type, EngineFactory factory) {
  registry()[type] = std::move(factory);
  return true;
}

std::unique_ptr<Engine> create_engine(const std::string& type) {
  auto it = registry().find(type);
  if (it == registry().end()) return nullptr;
  return it->second();
}

std::vector<std::string> registered_engine_types() {
  std::vector<std::string> out;
  for (auto& [k, v] : registry()) out.push_back(k);
  return out;
}

void EngineServer::get(const engine::DataPackId& id, engine::DataPack* out) {
  *out->mutable_id() = id;
  datapack::Builder builder(out, *blob_writer_);
  engine_.get_datapack(id, builder);
  if (const size_t bytes = out->ByteSizeLong(); bytes > transport::kMaxMessageBytes) {
    throw std::length_error("datapack '" + id.name() + "' is " + std::to_string(bytes) +
                            " bytes, more than one message may carry (" +
                            std::to_string(transport::kMaxMessageBytes) + " bytes)");
  }
}

void EngineServer::put(const engine::DataPack& dp) {
  engine_.set_datapack(datapack::View(dp, *blob_reader_));
}

void EngineServer::do_step(const engine::StepRequest& request, engine::StepReply* reply) {
  int64_t t0 = now_ns();
  for (const auto& dp : request.inputs()) put(dp);
  reply->set_time_ns(engine_.step(request.duration_ns()));
  stale_.clear();
  auto add = [&](const engine::DataPackId& id) { get(id, reply->add_outputs()); };
  for (const auto& id : request.wanted()) {
    if (engine_.unchanged(id))
      stale_.push_back(&id);
    else
      add(id);
  }
  // Unchanged datapacks are left out: the coordinator keeps the ones it has. Their blobs in
  // shared memory stay valid only while no later reply carries blobs (the arena's halves
  // alternate between such replies), so a reply that carries blobs sends them again.
  if (shm_writer_ && shm_writer_->wrote_blobs()) {
    for (const auto* id : stale_) add(*id);
  }
  reply->set_compute_ns(now_ns() - t0);
}

bool EngineServer::handle(const engine::Request& request, engine::Reply* reply) {
  try {
    switch (request.kind_case()) {
      case engine::Request::kInitialize: {
        const int64_t t0 = now_ns();
        const auto& init = request.initialize();
        nlohmann::json config = nlohmann::json::parse(init.config_json());
        auto ids = engine_.initialize(init.engine_name(), config, init.timestep_ns());
        initialized_ = true;
        auto* out = reply->mutable_initialize();
        for (auto& id : ids) *out->add_registered() = id;
        for (auto& w : engine_.take_warnings()) out->add_warnings(w);
        out->set_compute_ns(now_ns() - t0);
        if (const int64_t start = process_start_ns(); start > 0 && start < t0)
          out->set_process_ns(t0 - start);
        break;
      }
      case engine::Request::kStep:
        do_step(request.step(), reply->mutable_step());
        break;
      case engine::Request::kGetDatapacks:
        for (const auto& id : request.get_datapacks().ids())
          get(id, reply->mutable_get_datapacks()->add_datapacks());
        break;
      case engine::Request::kSetDatapacks:
        for (const auto& dp : request.set_datapacks().datapacks()) put(dp);
        reply->mutable_done();
        break;
      case engine::Request::kReset:
        engine_.reset();
        reply->mutable_done();
        break;
      case engine::Request::kShutdown:
        shut_down_ = true;
        engine_.shutdown();
        reply->mutable_done();
        return false;
      default:
        reply->set_error("empty request");
    }
  } catch (const std::exception& e) {
    // `error` is a protobuf string: bytes that are not UTF-8 would make the whole reply
    // unreadable to the coordinator, which would then report a dead engine instead.
    reply->set_error(valid_utf8(e.what()));
    reply->set_user_error(dynamic_cast<const UserError*>(&e) != nullptr);
    if (request.kind_case() == engine::Request::kShutdown) return false;
  }
  return true;
}

void EngineServer::serve_socket(int fd, int shm_out_fd, int shm_in_fd) {
  transport::FrameSocket socket(fd);
  transport::ShmArena out_arena, in_arena;
  std::unique_ptr<transport::ShmBlobWriter> writer;
  if (shm_out_fd >= 0) {
    out_arena.attach(shm_out_fd);
    writer = std::make_unique<transport::ShmBlobWriter>(out_arena);
  }
  shm_writer_ = writer.get();
  if (writer) blob_writer_ = writer.get();
  if (shm_in_fd >= 0) in_arena.attach(shm_in_fd);
  transport::ShmBlobReader reader(shm_in_fd >= 0 ? &in_arena : nullptr);
  blob_reader_ = &reader;
  std::string in, out;
  // Each exchange's request and reply live in an arena reset before the next one: a step's
  // datapacks are not allocated and freed message by message.
  std::vector<char> first_block(64 * 1024);
  pb::ArenaOptions arena_options;
  arena_options.initial_block = first_block.data();
  arena_options.initial_block_size = first_block.size();
  pb::Arena messages(arena_options);
  // Running averages of the wait for the next request and of the work on one.
  int64_t usual_gap_ns = -1, usual_work_ns = -1;
  auto follow = [](int64_t& avg, int64_t x) { avg = avg < 0 ? x : (3 * avg + x) / 4; };
  for (;;) {
    const int64_t waited_from = now_ns();
    // An engine that works longer than it waits is the one the loop waits for: it may yield
    // up to spin_us_. The others, which wait for it, yield only briefly (50 µs), leaving the
    // cores to the coordinator's functions.
    const int64_t max_spin_ns =
        std::min<int64_t>(spin_us_, usual_work_ns >= usual_gap_ns ? spin_us_ : 50) * 1000;
    if (max_spin_ns > 0 && usual_gap_ns >= 0 && usual_gap_ns <= max_spin_ns)
      socket.set_spin(std::min(max_spin_ns, usual_gap_ns + usual_gap_ns / 4 + 20'000), true);
    else
      socket.set_spin(0);
    if (socket.recv(&in, Deadline::max()) != transport::RecvStatus::kOk) break;
    const int64_t received = now_ns();
    follow(usual_gap_ns, received - waited_from);
    messages.Reset();
    auto& request = *pb::Arena::CreateMessage<engine::Request>(&messages);
    auto& reply = *pb::Arena::CreateMessage<engine::Reply>(&messages);
    if (!request.ParseFromString(in)) {
      reply.set_error("malformed request frame");
      reply.SerializeToString(&out);
      socket.send(out);
      continue;
    }
    if (writer) writer->next_message();
    bool more = handle(request, &reply);
    out.clear();
    if (!reply.SerializeToString(&out) || out.size() > transport::kMaxMessageBytes) {
      const size_t bytes = reply.ByteSizeLong();
      reply.Clear();
      reply.set_error("the reply is " + std::to_string(bytes) +
                      " bytes, more than one message may carry (" +
                      std::to_string(transport::kMaxMessageBytes) + " bytes)");
      out.clear();
      reply.SerializeToString(&out);
    }
    if (!socket.send(out) || !more) break;
    follow(usual_work_ns, now_ns() - received);
  }
  blob_writer_ = &inline_writer_;
  blob_reader_ = &datapack::inline_blob_reader();
  shm_writer_ = nullptr;
  // The coordinator went away without a Shutdown: still let the engine clean up.
  if (initialized_ && !shut_down_) {
    shut_down_ = true;
    try {
      engine_.shutdown();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "shutdown after disconnect failed: %s\n", e.what());
    }
  }
}

namespace {

// Engines (an embedded Python, say) must be driven from one thread: gRPC's handler threads
// hand each request to the thread that runs serve_grpc() and wait for its reply.
class RequestQueue {
 public:
  engine::Reply submit(const engine::Request& request) {
    Job job{&request, {}};
    auto done = job.reply.get_future();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      jobs_.push_back(&job);
    }
    cv_.notify_one();
    return done.get();
  }
  // Runs jobs until `handle` returns false (Shutdown).
  void run(const std::function<bool(const engine::Request&, engine::Reply*)>& handle) {
    for (;;) {
      Job* job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [&] { return !jobs_.empty(); });
        job = jobs_.front();
        jobs_.pop_front();
      }
      engine::Reply reply;
      bool more = handle(*job->request, &reply);
      job->reply.set_value(std::move(reply));
      if (!more) return;
    }
  }

 private:
  struct Job {
    const engine::Request* request;
    std::promise<engine::Reply> reply;
  };
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Job*> jobs_;
};

class GrpcService final : public engine::Engine::Service {
 public:
  GrpcService(RequestQueue& queue, std::string token) : queue_(queue), token_(std::move(token)) {}

  grpc::Status Initialize(grpc::ServerContext* c, const engine::InitializeRequest* req,
                          engine::InitializeReply* out) override {
    engine::Request r;
    *r.mutable_initialize() = *req;
    return run(c, r, [&](engine::Reply& rep) { *out = rep.initialize(); });
  }
  grpc::Status Step(grpc::ServerContext* c, const engine::StepRequest* req,
                    engine::StepReply* out) override {
    engine::Request r;
    *r.mutable_step() = *req;
    return run(c, r, [&](engine::Reply& rep) { *out = std::move(*rep.mutable_step()); });
  }
  grpc::Status RunLoopStep(grpc::ServerContext* c, const engine::StepRequest* req,
                           engine::StepReply* out) override {
    return Step(c, req, out);
  }
  grpc::Status GetDataPacks(grpc::ServerContext* c, const engine::GetDataPacksRequest* req,
                            engine::GetDataPacksReply* out) override {
    engine::Request r;
    *r.mutable_get_datapacks() = *req;
    return run(c, r, [&](engine::Reply& rep) { *out = std::move(*rep.mutable_get_datapacks()); });
  }
  grpc::Status SetDataPacks(grpc::ServerContext* c, const engine::SetDataPacksRequest* req,
                            engine::Empty*) override {
    engine::Request r;
    *r.mutable_set_datapacks() = *req;
    return run(c, r, [](engine::Reply&) {});
  }
  grpc::Status Reset(grpc::ServerContext* c, const engine::Empty*, engine::Empty*) override {
    engine::Request r;
    r.mutable_reset();
    return run(c, r, [](engine::Reply&) {});
  }
  grpc::Status Shutdown(grpc::ServerContext* c, const engine::Empty*, engine::Empty*) override {
    engine::Request r;
    r.mutable_shutdown();
    return run(c, r, [](engine::Reply&) {});
  }

 private:
  template <typename F>
  grpc::Status run(grpc::ServerContext* context, const engine::Request& request, F&& take) {
    if (!token_.empty()) {
      const auto& meta = context->client_metadata();
      auto it = meta.find(transport::kTokenMetadataKey);
      const std::string_view given = it == meta.end()
                                         ? std::string_view()
                                         : std::string_view(it->second.data(), it->second.size());
      if (!transport::same_token(token_, given)) {
        std::fprintf(stderr, "refused a call from %s: %s token\n", context->peer().c_str(),
                     it == meta.end() ? "no" : "wrong");
        std::fflush(stderr);
        return grpc::Status(grpc::StatusCode::UNAUTHENTICATED,
                            it == meta.end() ? "no token given" : "wrong token");
      }
    }
    std::lock_guard<std::mutex> lock(mutex_);  // one call at a time, in arrival order
    engine::Reply reply = queue_.submit(request);
    if (!reply.error().empty())  // a user's input fault travels as INVALID_ARGUMENT
      return grpc::Status(
          reply.user_error() ? grpc::StatusCode::INVALID_ARGUMENT : grpc::StatusCode::INTERNAL,
          reply.error());
    take(reply);
    return grpc::Status::OK;
  }
  RequestQueue& queue_;
  std::string token_;  // "" = none required; never logged
  std::mutex mutex_;
};

}  // namespace

void EngineServer::serve_grpc(const std::string& address,
                              const transport::ServerSecurity& security) {
  transport::check_listening_policy(address, security);
  RequestQueue queue;
  GrpcService service(queue, security.token);
  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(address, transport::server_credentials(security), &port);
  builder.SetMaxReceiveMessageSize(static_cast<int>(transport::kMaxMessageBytes));
  builder.SetMaxSendMessageSize(static_cast<int>(transport::kMaxMessageBytes));
  builder.RegisterService(&service);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  if (!server || port == 0) throw std::runtime_error("cannot listen for gRPC at " + address);
  const bool tls = !security.cert_file.empty();
  std::fprintf(stderr, "serving gRPC at %s (%s%s%s)\n", address.c_str(), tls ? "TLS" : "plain",
               tls && !security.client_ca_file.empty() ? ", client certificates required" : "",
               security.token.empty() ? ", no token" : ", token required");
  if (security.insecure && !transport::is_loopback_address(address) && !tls &&
      security.token.empty()) {
    std::fprintf(stderr,
                 "warning: --insecure: anyone who reaches %s can step this engine and feed it "
                 "datapacks\n",
                 address.c_str());
  }
  std::fflush(stderr);
  queue.run([this](const engine::Request& r, engine::Reply* reply) { return handle(r, reply); });
  // Let the Shutdown reply go out, then stop.
  server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(1));
  server->Wait();
}

int engine_main(int argc, char** argv) {
  tune_allocator_for_frames();
  std::string type, address;
  int fd = -1;
  int64_t spin_us = 0;
  int shm_out = -1, shm_in = -1;
  transport::ServerSecurity security;
  std::string token_file;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&](const char* flag) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", flag);
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--type")
      type = value("--type");
    else if (a == "--convoy-fd")
      fd = std::stoi(value("--convoy-fd"));
    else if (a == "--convoy-shm-out")
      shm_out = std::stoi(value("--convoy-shm-out"));
    else if (a == "--convoy-shm-in")
      shm_in = std::stoi(value("--convoy-shm-in"));
    else if (a == "--convoy-spin-us")
      spin_us = std::stoll(value("--convoy-spin-us"));
    else if (a == "--address" || a == "--serverurl")
      address = value("--address");
    else if (a == "--tls-cert")
      security.cert_file = value("--tls-cert");
    else if (a == "--tls-key")
      security.key_file = value("--tls-key");
    else if (a == "--tls-client-ca")
      security.client_ca_file = value("--tls-client-ca");
    else if (a == "--token-file")
      token_file = value("--token-file");
    else if (a == "--insecure")
      security.insecure = true;
    else if (a == "-h" || a == "--help") {
      std::printf(
          "usage: %s [--type T] (--convoy-fd N | --address host:port [--tls-cert PEM --tls-key "
          "PEM [--tls-client-ca PEM]] [--token-file FILE] [--insecure])\n"
          "  The token is read from --token-file or $%s. Without TLS or a token the server "
          "listens\n  on the loopback only, unless --insecure.\n",
          argv[0], transport::kTokenEnv);
      return 0;
    } else {
      std::fprintf(stderr, "note: ignoring argument %s\n", a.c_str());
    }
  }
  auto types = registered_engine_types();
  if (type.empty() && types.size() == 1) type = types.front();
  auto engine = create_engine(type);
  if (!engine) {
    std::fprintf(stderr, "unknown engine type '%s'\n", type.c_str());
    return 2;
  }
  if (fd < 0 && address.empty()) {
    std::fprintf(stderr, "give --convoy-fd N or --address host:port\n");
    return 2;
  }
  EngineServer server(*engine);
  server.set_spin_us(spin_us);
  try {
    if (fd >= 0) {
      server.serve_socket(fd, shm_out, shm_in);
    } else {
      if (!token_file.empty()) {
        std::ifstream in(token_file);
        if (!in) throw std::invalid_argument("--token-file '" + token_file + "' cannot be read");
        std::getline(in, security.token);
        if (security.token.empty())
          throw std::invalid_argument("--token-file '" + token_file + "' holds no token");
      } else if (const char* env = std::getenv(transport::kTokenEnv)) {
        security.token = env;
      }
      server.serve_grpc(address, security);
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "engine server: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "engine server error: %s\n", e.what());
    return 1;
  }
  const auto& copies = datapack::large_copies();
  std::fprintf(stderr, "frame-sized copies: %llu (%.1f MB)\n",
               static_cast<unsigned long long>(copies.copies.load()),
               static_cast<double>(copies.bytes.load()) / 1e6);
  return 0;
}

}  // namespace convoy::engines
