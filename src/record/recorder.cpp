#include "record/recorder.h"

#include "datapack/registry.h"
#include "record/datapack_codec.h"

namespace convoy::record {

namespace {
// JSON messages get a permissive JSON Schema, so that viewers that want one (Foxglove's
// panels) have it; the spec allows none for json.
constexpr const char* kJsonSchema =
    R"js({"type":"object","description":"a Convoy JSON datapack (docs/recording.md)"})js";
}  // namespace

Recorder::Recorder(const std::filesystem::path& path, bool record_blobs, const StringMap& metadata)
    : record_blobs_(record_blobs) {
  writer_.open(path, std::string("convoy ") + metadata.at("convoy_version"));
  writer_.write_metadata("convoy", metadata);
}

Recorder::~Recorder() { writer_.close(); }

uint16_t Recorder::channel(const std::string& engine, const std::string& name, bool to_engine,
                           const Encoded& enc) {
  auto key = std::make_tuple(engine, name, to_engine, static_cast<int>(enc.kind), enc.type);
  if (auto it = channels_.find(key); it != channels_.end()) return it->second;
  std::string schema_key = std::string(kind_name(enc.kind)) + '\0' +
                           (enc.kind == Kind::kProtobuf ? enc.type : std::string());
  uint16_t schema = 0;
  if (auto it = schemas_.find(schema_key); it != schemas_.end()) {
    schema = it->second;
  } else {
    switch (enc.kind) {
      case Kind::kProtobuf:
        schema = writer_.add_schema(enc.type, "protobuf",
                                    datapack::Registry::global().file_descriptor_set(enc.type));
        break;
      case Kind::kJson:
        schema = writer_.add_schema("convoy.JsonDataPack", "jsonschema", kJsonSchema);
        break;
      case Kind::kStub:
        schema = writer_.add_schema("convoy.BlobStub", "jsonschema", kJsonSchema);
        break;
      case Kind::kEmpty:
        schema = writer_.add_schema("convoy.EmptyDataPack", "jsonschema", kJsonSchema);
        break;
    }
    schemas_[schema_key] = schema;
  }
  StringMap meta = {{"engine", engine},
                    {"datapack", name},
                    {"type", enc.type},
                    {"kind", kind_name(enc.kind)},
                    {"direction", to_engine ? "to_engine" : "from_engine"}};
  std::string topic = engine + "/" + name + (to_engine ? "/in" : "");
  const std::string encoding = enc.kind == Kind::kProtobuf ? "protobuf" : "json";
  uint16_t id = writer_.add_channel(topic, encoding, schema, meta);
  channels_.emplace(std::move(key), id);
  return id;
}

void Recorder::write(const std::string& engine, const engine::DataPack& dp,
                     const datapack::BlobReader& blobs, bool to_engine, const std::string&,
                     uint64_t cycle, int64_t time_ns) {
  Encoded enc;
  try {
    enc = encode(dp, blobs, record_blobs_);
  } catch (const std::exception& e) {
    // A datapack the recording cannot hold must not end a run that works without it.
    if (skipped_++ == 0) first_skip_ = e.what();
    return;
  }
  const uint16_t ch = channel(engine, dp.id().name(), to_engine, enc);
  const auto t = static_cast<uint64_t>(time_ns);
  writer_.write_message(ch, static_cast<uint32_t>(cycle), t, t, enc.data);
}

void Recorder::from_engine(const std::string& engine, const engine::DataPack& dp,
                           const datapack::BlobReader& blobs, uint64_t cycle, int64_t time_ns) {
  write(engine, dp, blobs, false, "", cycle, time_ns);
}

void Recorder::to_engine(const std::string& engine, const engine::DataPack& dp,
                         const datapack::BlobReader& blobs, const loop::LoadedFunction& fn,
                         uint64_t cycle, int64_t time_ns) {
  write(engine, dp, blobs, true, fn.name, cycle, time_ns);
}

std::string Recorder::finish(const StringMap& end) {
  if (!writer_.is_open()) return "";
  writer_.write_metadata("convoy_end", end);
  return writer_.close();
}

}  // namespace convoy::record
