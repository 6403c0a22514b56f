#include "live/run_control.h"

namespace convoy::live {

namespace {

using json = nlohmann::json;

constexpr size_t kInfractionsKept = 1000;  // for a viewer that connects late

ChannelInfo json_channel(const char* topic, const char* schema_name, const json& schema) {
  return {0, topic, "json", schema_name, schema.dump(), "jsonschema"};
}

const json kControlSchema = {
    {"type", "object"},
    {"properties", {{"command", {{"type", "string"}, {"enum", {"pause", "resume", "step"}}}}}},
    {"required", {"command"}}};
const json kStatusSchema = {
    {"type", "object"},
    {"properties", {{"paused", {{"type", "boolean"}}}, {"time_ns", {{"type", "integer"}}}}}};
const json kMetricsSchema = {{"type", "object"},
                             {"properties",
                              {{"time_ns", {{"type", "integer"}}},
                               {"driving_score", {{"type", "number"}}},
                               {"route_completion", {{"type", "number"}}},
                               {"infraction_penalty", {{"type", "number"}}}}}};
const json kInfractionSchema = {{"type", "object"},
                                {"properties",
                                 {{"time_s", {{"type", "number"}}},
                                  {"kind", {{"type", "string"}}},
                                  {"time_ns", {{"type", "integer"}}}}}};

std::shared_ptr<const std::string> shared(std::string s) {
  return std::make_shared<const std::string>(std::move(s));
}

}  // namespace

ControlCommand parse_control(std::string_view payload) {
  ControlCommand c;
  const json msg = json::parse(payload, nullptr, /*allow_exceptions=*/false);
  if (msg.is_discarded()) {
    c.error = std::string(kControlTopic) + ": not JSON";
    return c;
  }
  if (!msg.is_object() || !msg.contains("command") || !msg["command"].is_string()) {
    c.error = std::string(kControlTopic) +
              ": expected {\"command\": \"pause\" | \"resume\" | \"step\"}, got " +
              msg.dump(-1, ' ', false, json::error_handler_t::replace).substr(0, 200);
    return c;
  }
  const std::string command = msg["command"].get<std::string>();
  if (command == "pause") {
    c.kind = ControlCommand::Kind::kPause;
  } else if (command == "resume") {
    c.kind = ControlCommand::Kind::kResume;
  } else if (command == "step") {
    c.kind = ControlCommand::Kind::kStep;
  } else {
    c.error = std::string(kControlTopic) + ": unknown command \"" + command.substr(0, 100) +
              "\" (pause, resume or step)";
  }
  return c;
}

std::string run_status_json(bool paused, int64_t time_ns) {
  return json{{"paused", paused}, {"time_ns", time_ns}}.dump();
}

RunControl::RunControl(LiveServer& server, loop::PauseGate& gate) : server_(server), gate_(gate) {
  status_ = server_.add_channel(json_channel(kStatusTopic, "convoy.Status", kStatusSchema), 1);
  metrics_ = server_.add_channel(json_channel(kMetricsTopic, "convoy.Metrics", kMetricsSchema), 1);
  infractions_ = server_.add_channel(
      json_channel(kInfractionsTopic, "convoy.Infraction", kInfractionSchema), kInfractionsKept);
  // The first status, for the first subscribers: running at 0.
  server_.publish(status_, 0, shared(run_status_json(false, 0)));
  gate_.set_listener([this](bool paused, int64_t time_ns) {
    server_.publish(status_, static_cast<uint64_t>(std::max<int64_t>(time_ns, 0)),
                    shared(run_status_json(paused, time_ns)));
  });
  server_.accept_client_topic(kControlTopic, "json",
                              [this](std::string_view payload) { return on_control(payload); });
}

RunControl::~RunControl() {
  server_.accept_client_topic(kControlTopic, "json", nullptr);
  gate_.set_listener(nullptr);
}

std::string RunControl::on_control(std::string_view payload) {
  const ControlCommand c = parse_control(payload);
  switch (c.kind) {
    case ControlCommand::Kind::kPause:
      gate_.pause();
      break;
    case ControlCommand::Kind::kResume:
      gate_.resume();
      break;
    case ControlCommand::Kind::kStep:
      gate_.step();
      break;
    case ControlCommand::Kind::kInvalid:
      return c.error;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  ++commands_;
  return "";
}

bool RunControl::publish(const std::string& topic, const std::string& text, int64_t time_ns) {
  json msg = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!msg.is_object()) return false;
  const uint64_t t = static_cast<uint64_t>(std::max<int64_t>(time_ns, 0));
  std::lock_guard<std::mutex> lock(mutex_);
  if (topic == kMetricsTopic) {
    latest_metrics_.update(msg);
    latest_metrics_["time_ns"] = time_ns;
    server_.publish(metrics_, t, shared(latest_metrics_.dump()));
  } else if (topic == kInfractionsTopic) {
    if (!msg.contains("time_ns")) msg["time_ns"] = time_ns;
    server_.publish(infractions_, t, shared(msg.dump()));
  } else {
    return false;
  }
  ++published_;
  return true;
}

uint64_t RunControl::commands() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return commands_;
}

uint64_t RunControl::published() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return published_;
}

}  // namespace convoy::live
