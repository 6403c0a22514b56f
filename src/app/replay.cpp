#include "app/replay.h"

#include <chrono>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>

#include "app/run_log.h"
#include "app/session.h"
#include "app/simulation.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "python/interpreter.h"
#include "record/recorder.h"

namespace convoy::app {

namespace fs = std::filesystem;

namespace {

constexpr size_t kFirstMismatches = 10;

// An engine of the recording: answers from it, accepts anything.
class ReplayChannel final : public transport::EngineChannel {
 public:
  ReplayChannel(Replay& replay, std::string engine) : replay_(replay), engine_(std::move(engine)) {}

  void start(const engine::Request& request, Deadline) override {
    reply_.Clear();
    switch (request.kind_case()) {
      case engine::Request::kGetDatapacks:
        for (const auto& id : request.get_datapacks().ids()) replay_.check_wanted(engine_, id);
        for (auto& dp : replay_.take_from_engine(engine_, 0))
          reply_.mutable_get_datapacks()->add_datapacks()->Swap(&dp);
        return;
      case engine::Request::kStep: {
        for (const auto& id : request.step().wanted()) replay_.check_wanted(engine_, id);
        time_ns_ += request.step().duration_ns();
        auto* step = reply_.mutable_step();
        step->set_time_ns(time_ns_);
        for (auto& dp : replay_.take_from_engine(engine_, time_ns_)) step->add_outputs()->Swap(&dp);
        return;
      }
      case engine::Request::kShutdown:
        reply_.mutable_done();
        return;
      default:
        reply_.set_error(
            "a replay cannot do this (reset, set datapacks): the recording holds "
            "one run from its start");
    }
  }
  transport::CallStatus finish(engine::Reply* reply, Deadline) override {
    reply->Swap(&reply_);
    return transport::CallStatus::kOk;
  }
  void close() override {}
  std::string describe() const override { return "recording " + replay_.path().string(); }

 private:
  Replay& replay_;
  std::string engine_;
  uint64_t time_ns_ = 0;
  engine::Reply reply_;
};

std::string topic_of(const std::string& engine, const std::string& name, bool to_engine) {
  return engine + "/" + name + (to_engine ? "/in" : "");
}

}  // namespace

Replay::Replay(const fs::path& recording) : path_(recording) {
  std::error_code ec;
  if (!fs::is_regular_file(recording, ec))
    throw UserError(recording.string() +
                    ": no recording here (record a run with `convoy run --record`)");
  try {
    record::McapReader check(recording);
    check.read_to_end();
    if (!check.complete())
      throw UserError(recording.string() + ": incomplete recording: " + check.incomplete_reason() +
                      " (convoy finishes its recordings on every error; was it killed?)");
    auto meta = check.metadata().find("convoy");
    if (meta == check.metadata().end())
      throw UserError(recording.string() +
                      ": no `convoy` metadata record: not a recording made by convoy run --record");
    metadata_ = meta->second;
    if (metadata_["format"] != record::kRecordingFormat)
      throw UserError(recording.string() + ": recording format '" + metadata_["format"] +
                      "', this Convoy reads '" + record::kRecordingFormat + "'");
    record_blobs_ = metadata_["record_blobs"] == "true";
    if (auto e = check.metadata().find("convoy_end"); e != check.metadata().end()) end_ = e->second;
    for (const auto& [id, ch] : check.channels()) {
      // Viewers' channels (a camera's JPEG and calibration, the scene) hold no datapack.
      if (ch.metadata.count("camera") || ch.metadata.count("viewer")) continue;
      auto get = [&](const char* key) -> std::string {
        auto it = ch.metadata.find(key);
        if (it == ch.metadata.end())
          throw UserError(recording.string() + ": channel '" + ch.topic + "' has no '" + key +
                          "' metadata: not a Convoy recording");
        return it->second;
      };
      Topic t;
      t.engine = get("engine");
      t.name = get("datapack");
      t.type = get("type");
      t.to_engine = get("direction") == "to_engine";
      try {
        t.kind = record::kind_from_name(get("kind"));
      } catch (const std::invalid_argument& e) {
        throw UserError(recording.string() + ": channel '" + ch.topic + "': " + e.what());
      }
      if (!t.to_engine) from_topics_.emplace(t.engine, t.name);
      topics_[id] = std::move(t);
    }
    // End of the live run: its convoy_end metadata, else the last message.
    if (auto it = end_.find("sim_time_ns"); it != end_.end()) {
      end_time_ns_ = std::stoull(it->second);
    } else {
      record::McapReader scan(recording);
      record::McapMessage m;
      while (scan.next(&m)) end_time_ns_ = std::max(end_time_ns_, m.log_time);
    }
    reader_ = std::make_unique<record::McapReader>(recording);
  } catch (const record::McapError& e) {
    throw UserError(e.what());
  }
}

std::unique_ptr<transport::EngineChannel> Replay::channel(const std::string& engine) {
  return std::make_unique<ReplayChannel>(*this, engine);
}

void Replay::advance_to(uint64_t time_ns) {
  while (!reader_done_) {
    if (!has_peeked_) {
      try {
        has_peeked_ = reader_->next(&peeked_);
      } catch (const record::McapError& e) {
        throw UserError(e.what());
      }
      if (!has_peeked_) {
        reader_done_ = true;
        return;
      }
    }
    if (peeked_.log_time > time_ns) return;
    has_peeked_ = false;
    const auto topic = topics_.find(peeked_.channel);
    if (topic == topics_.end()) continue;  // a viewers' channel
    const Topic& t = topic->second;
    RecordedDataPack r{peeked_.log_time, peeked_.sequence, t.name,
                       t.kind,           t.type,           std::move(peeked_.data)};
    (t.to_engine ? to_ : from_)[t.engine].push_back(std::move(r));
  }
}

void Replay::check_wanted(const std::string& engine, const engine::DataPackId& id) const {
  if (from_topics_.count({engine, id.name()})) return;
  throw UserError(path_.string() + ": the functions read datapack '" + id.name() + "' of engine '" +
                  engine + "', which the recording does not hold (topic '" +
                  topic_of(engine, id.name(), false) + "')");
}

std::vector<engine::DataPack> Replay::take_from_engine(const std::string& engine,
                                                       uint64_t time_ns) {
  advance_to(time_ns);
  std::vector<engine::DataPack> out;
  auto& queue = from_[engine];
  while (!queue.empty() && queue.front().time_ns <= time_ns) {
    RecordedDataPack& r = queue.front();
    if (r.time_ns == time_ns) {
      try {
        out.push_back(record::decode(r.kind, r.type, r.data, r.name, engine, &placeholders_));
      } catch (const std::runtime_error& e) {
        throw UserError(path_.string() + ": " + e.what());
      }
    }
    queue.pop_front();
  }
  return out;
}

void Replay::mismatch(const std::string& topic, uint64_t cycle, std::string what) {
  ++mismatches_;
  if (first_.size() < kFirstMismatches) first_.push_back({topic, cycle, std::move(what)});
}

void Replay::to_engine(const std::string& engine, const engine::DataPack& dp,
                       const datapack::BlobReader& blobs, const loop::LoadedFunction& fn,
                       uint64_t cycle, int64_t time_ns) {
  advance_to(static_cast<uint64_t>(time_ns));
  ++compared_;
  const std::string topic = topic_of(engine, dp.id().name(), true);
  auto& queue = to_[engine];
  while (!queue.empty() && queue.front().cycle < cycle) {
    mismatch(topic_of(engine, queue.front().name, true), queue.front().cycle,
             "recorded, not sent in the replay");
    queue.pop_front();
  }
  if (queue.empty() || queue.front().cycle != cycle) {
    mismatch(
        topic, cycle,
        fn.label() + " sent it; the recording has nothing more for '" + engine + "' in this cycle");
    return;
  }
  RecordedDataPack r = std::move(queue.front());
  queue.pop_front();
  if (r.name != dp.id().name()) {
    mismatch(topic, cycle, fn.label() + " sent it where the recording has '" + r.name + "'");
    return;
  }
  record::Encoded now;
  try {
    now = record::encode(dp, blobs, record_blobs_);
  } catch (const std::runtime_error& e) {
    mismatch(topic, cycle, e.what());
    return;
  }
  if (now.kind != r.kind || now.type != r.type) {
    mismatch(topic, cycle,
             std::string("a ") + record::kind_name(now.kind) + " datapack of type '" + now.type +
                 "', recorded: " + record::kind_name(r.kind) + " of type '" + r.type + "'");
  } else if (now.data != r.data) {
    std::string what = "different ";
    what += r.kind == record::Kind::kProtobuf ? "bytes" : "value";
    if (r.kind != record::Kind::kProtobuf && now.data.size() + r.data.size() < 400)
      what += ": " + now.data + ", recorded " + r.data;
    mismatch(topic, cycle, what);
  }
}

void Replay::finish(uint64_t until_ns) {
  advance_to(until_ns);
  for (auto& [engine, queue] : to_) {
    for (const auto& r : queue)
      if (r.time_ns <= until_ns)
        mismatch(topic_of(engine, r.name, true), r.cycle, "recorded, not sent in the replay");
    queue.clear();
  }
}

namespace {

// What the coordinator writes into summary.json; the rest is the functions' and engines'.
bool coordinator_field(const std::string& key) {
  static const std::set<std::string> kKeys = {"simulation",
                                              "config",
                                              "exit_code",
                                              "error",
                                              "wall_s",
                                              "cycles",
                                              "sim_time_s",
                                              "loop_wall_s",
                                              "real_time_factor",
                                              "status_function_done",
                                              "frame_copies",
                                              "replay",
                                              "state",
                                              "pid"};
  return kKeys.count(key) > 0;
}

nlohmann::json read_json_file(const fs::path& file) {
  std::ifstream in(file);
  if (!in) return nlohmann::json::object();
  nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_object() ? j : nlohmann::json::object();
}

struct ReplayResult {
  int code = 0;  // the replay's own exit code (mismatches not counted)
  fs::path out_dir;
  uint64_t mismatches = 0;
};

ReplayResult replay(const ReplayOptions& options, const fs::path& default_out) {
  install_signal_handlers();
  RunLog log;
  log.quiet = options.quiet;
  ReplayResult result;
  const fs::path run_dir = fs::absolute(options.run_dir);
  result.out_dir = options.out_dir.empty() ? run_dir / default_out : fs::absolute(options.out_dir);

  std::unique_ptr<Replay> replay;
  config::SimulationConfig cfg;
  try {
    replay = std::make_unique<Replay>(run_dir / record::kRecordingFile);
    fs::create_directories(result.out_dir / "logs");
    log.open(result.out_dir / "logs" / "coordinator.log");
    log.info("replaying " + replay->path().string() + " into " + result.out_dir.string());
    for (const auto& w : replay->warnings()) log.info("warning: " + w);
    fs::path config_file = options.config_file;
    if (config_file.empty()) {
      // The effective config the run recorded (paths already absolute).
      config_file = result.out_dir / "config.json";
      std::ofstream(config_file) << replay->metadata().at("config") << "\n";
    }
    cfg = config::load_simulation_config(fs::absolute(config_file), options.overrides, share_dir());
  } catch (const config::ConfigError& e) {
    log.error(e.what());
    result.code = kExitUserError;
    return result;
  } catch (const UserError& e) {
    log.error(e.what());
    result.code = kExitUserError;
    return result;
  } catch (const std::exception& e) {
    log.error(std::string("replay: ") + e.what());
    result.code = kExitUserError;
    return result;
  }
  std::error_code stale;
  fs::remove(result.out_dir / "summary.json", stale);
  // Run exactly as far as the live run went.
  const uint64_t end_ns = replay->end_time_ns();
  cfg.timeout_ns = end_ns > 0 ? static_cast<int64_t>(end_ns) : 1;
  cfg.record = cfg.record_blobs = false;

  const auto t0 = SteadyClock::now();
  LoopFigures figures;
  Outcome outcome;
  {
    export_run_environment(result.out_dir);
    python::Interpreter interpreter;
    Session session(cfg, result.out_dir, log, options.quiet);
    session.replay_with([&](const config::EngineConfig& e) { return replay->channel(e.name); },
                        replay.get());
    try {
      session.initialize(/*keep_observations=*/false);
      session.run_to_end();
      if (interrupted()) outcome = {kExitInterrupted, interrupted_text()};
    } catch (...) {
      outcome = outcome_of(std::current_exception());
    }
    figures = session.figures();
    if (outcome.code == kExitOk) {
      try {
        replay->finish(end_ns);
      } catch (const UserError& e) {
        outcome = {kExitUserError, e.what()};
      }
    }
    if (outcome.code != kExitOk) log.error(outcome.error);
    session.shut_down(outcome.code == kExitOk);
  }
  const double wall_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  const fs::path summary = result.out_dir / "summary.json";
  write_summary(summary, cfg, figures, wall_s, outcome);
  nlohmann::json j = read_json_file(summary);
  nlohmann::json first = nlohmann::json::array();
  for (const auto& m : replay->first_mismatches())
    first.push_back({{"topic", m.topic}, {"cycle", m.cycle}, {"what", m.what}});
  const auto& end = replay->end();
  j["replay"] = {{"of", run_dir.string()},
                 {"recording", replay->path().string()},
                 {"compared", replay->compared()},
                 {"mismatches", replay->mismatches()},
                 {"first_mismatches", first},
                 {"blob_placeholders", replay->placeholders()},
                 {"recording_complete", replay->warnings().empty()},
                 {"live_exit_code", end.count("exit_code") ? std::stoi(end.at("exit_code")) : -1}};
  std::ofstream(summary) << j.dump(2) << "\n";

  std::ostringstream s;
  s << "replay: " << figures.cycles << " cycles, " << replay->compared()
    << " datapacks sent by the functions compared with the recording, " << replay->mismatches()
    << " mismatches";
  if (replay->placeholders() > 0)
    s << "; " << replay->placeholders()
      << " blobs were not recorded (no --record-blobs) and were replayed as zeros";
  if (replay->mismatches() == 0) {
    log.info(s.str());
  } else {
    log.error(s.str());
    for (const auto& m : replay->first_mismatches())
      log.error("  mismatch: " + m.topic + " at cycle " + std::to_string(m.cycle) + ": " + m.what);
  }
  log.info("replay folder: " + result.out_dir.string());
  result.code = outcome.code;
  result.mismatches = replay->mismatches();
  return result;
}

std::string text_of(const nlohmann::json& v) { return v.is_null() ? "-" : v.dump(); }

}  // namespace

int replay_run(const ReplayOptions& options) {
  ReplayResult r = replay(options, "replay");
  if (r.code != kExitOk) return r.code;
  return r.mismatches > 0 ? kExitReplayDiffers : kExitOk;
}

int score_run(const ReplayOptions& options) {
  ReplayResult r = replay(options, "rescore");
  if (r.code != kExitOk) return r.code;
  const fs::path live_file = fs::absolute(options.run_dir) / "summary.json";
  const nlohmann::json live = read_json_file(live_file);
  const nlohmann::json rescored = read_json_file(r.out_dir / "summary.json");
  std::vector<std::string> fields;
  for (auto it = rescored.begin(); it != rescored.end(); ++it)
    if (!coordinator_field(it.key())) fields.push_back(it.key());
  if (fields.empty()) {
    std::cerr << "error: the functions wrote no fields into summary.json in the replay ("
              << (r.out_dir / "summary.json").string()
              << "): nothing to score (no scoring function in the config?)\n";
    return kExitUserError;
  }
  // driving_score and its companions first, then the rest in name order.
  std::vector<std::string> order;
  for (const char* k : {"driving_score", "route_completion", "infraction_penalty", "infractions"})
    if (rescored.contains(k)) order.push_back(k);
  for (const auto& f : fields)
    if (std::find(order.begin(), order.end(), f) == order.end()) order.push_back(f);

  bool differs = false;
  std::printf("%-24s %-28s %-28s %s\n", "field", "live", "rescored", "identical");
  for (const auto& f : order) {
    const nlohmann::json a = live.contains(f) ? live[f] : nlohmann::json();
    const nlohmann::json& b = rescored[f];
    const bool same = live.contains(f) && a.dump() == b.dump();
    differs |= !same;
    std::string la = text_of(a), lb = text_of(b);
    if (la.size() > 28) la = la.substr(0, 25) + "...";
    if (lb.size() > 28) lb = lb.substr(0, 25) + "...";
    std::printf("%-24s %-28s %-28s %s\n", f.c_str(), la.c_str(), lb.c_str(),
                !live.contains(f) ? "no (not in the live summary)"
                : same            ? "yes"
                                  : "NO");
  }
  if (rescored.contains("driving_score")) {
    const auto& b = rescored["driving_score"];
    if (live.contains("driving_score") && live["driving_score"].is_number() && b.is_number()) {
      const double x = live["driving_score"].get<double>(), y = b.get<double>();
      uint64_t bx, by;
      std::memcpy(&bx, &x, 8);
      std::memcpy(&by, &y, 8);
      std::printf("driving_score is %s (live bits 0x%016llx, rescored 0x%016llx)\n",
                  bx == by ? "bit-identical to the live one" : "NOT bit-identical to the live one",
                  static_cast<unsigned long long>(bx), static_cast<unsigned long long>(by));
    } else {
      std::printf("driving_score: no live value in %s to compare with\n", live_file.c_str());
    }
  } else {
    std::printf("note: the functions wrote no driving_score\n");
  }
  if (r.mismatches > 0)
    std::printf("note: the replay's functions sent %llu datapacks that differ from the recording\n",
                static_cast<unsigned long long>(r.mismatches));
  return differs ? kExitReplayDiffers : kExitOk;
}

}  // namespace convoy::app
