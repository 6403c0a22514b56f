#include "datapack/nrp.h"

#include <map>
#include <stdexcept>

#include "convoy/datapacks.pb.h"
#include "datapack/camera.h"
#include "datapack/proto.h"
#include "nrp_protobuf/dump.pb.h"
#include "nrp_protobuf/enginetest.pb.h"
#include "nrp_protobuf/gazebo.pb.h"
#include "nrp_protobuf/nrpgenericproto.pb.h"
#include "nrp_protobuf/wrappers.pb.h"

namespace convoy::datapack {

namespace pb = google::protobuf;

namespace {

// Package name -> its file. Naming one message of each file links the file's generated code
// into every program (and so its descriptors into the generated pool, where Python's
// protobuf finds them).
const std::map<std::string, const pb::FileDescriptor*, std::less<>>& package_files() {
  static const auto* files = new std::map<std::string, const pb::FileDescriptor*, std::less<>>{
      {"Dump", Dump::String::descriptor()->file()},
      {"EngineTest", EngineTest::TestPayload::descriptor()->file()},
      {"Gazebo", Gazebo::Camera::descriptor()->file()},
      {"NrpGenericProto", NrpGenericProto::Image::descriptor()->file()},
      {"Wrappers", Wrappers::BoolValue::descriptor()->file()},
  };
  return *files;
}

const pb::FieldDescriptor* field(const pb::Message& m, const char* name) {
  const pb::FieldDescriptor* f = m.GetDescriptor()->FindFieldByName(name);
  if (!f) throw std::logic_error(m.GetDescriptor()->full_name() + " has no field " + name);
  return f;
}

uint32_t get_u32(const pb::Message& m, const char* name) {
  return m.GetReflection()->GetUInt32(m, field(m, name));
}

// Joint and Link have the same field numbers and types in both packages: the bytes of one
// are the bytes of the other.
void write_same_wire(Builder& out, const pb::Message& m, const std::string& type) {
  auto* dp = out.message();
  dp->mutable_id()->set_type(type);
  auto* payload = dp->mutable_proto();
  payload->set_type_name(type);
  payload->clear_blob_fields();
  m.SerializeToString(payload->mutable_data());
}

void read_same_wire(const View& in, pb::Message* m) {
  if (!m->ParseFromString(in.message().proto().data()))
    throw std::runtime_error(in.describe() + ": corrupt " + in.proto_type());
}

const std::string kCamera = "Gazebo.Camera", kJoint = "Gazebo.Joint", kLink = "Gazebo.Link";

}  // namespace

const std::vector<std::string>& nrp_packages() {
  static const auto* names = [] {
    auto* v = new std::vector<std::string>;
    for (const auto& [name, file] : package_files()) v->push_back(name);
    return v;
  }();
  return *names;
}

const pb::FileDescriptor* nrp_package_file(std::string_view package) {
  auto it = package_files().find(package);
  return it == package_files().end() ? nullptr : it->second;
}

void register_nrp_packages(Registry& registry) {
  for (const auto& [name, file] : package_files()) {
    for (int i = 0; i < file->message_type_count(); ++i) {
      const pb::Descriptor* d = file->message_type(i);
      registry.add(d, pb::MessageFactory::generated_factory()->GetPrototype(d));
    }
  }
}

std::string_view standard_type_of(std::string_view type) {
  if (type == kCamera) return type_name<data::Camera>();
  if (type == kJoint) return type_name<data::Joint>();
  if (type == kLink) return type_name<data::Link>();
  return {};
}

void write_message(Builder& out, const pb::Message& message) {
  const std::string& type = message.GetDescriptor()->full_name();
  if (type == kCamera) {
    const pb::Reflection* r = message.GetReflection();
    std::string scratch;
    const std::string& pixels =
        r->GetStringReference(message, field(message, "imageData"), &scratch);
    write_camera(out, get_u32(message, "imageHeight"), get_u32(message, "imageWidth"),
                 get_u32(message, "imageDepth"), pixels);
  } else if (type == kJoint) {
    write_same_wire(out, message, type_name<data::Joint>());
  } else if (type == kLink) {
    write_same_wire(out, message, type_name<data::Link>());
  } else {
    write_proto(out, message);
  }
}

void read_message(const View& in, pb::Message* message) {
  const std::string& type = message->GetDescriptor()->full_name();
  if (in.is_proto() && in.proto_type() != type && standard_type_of(type) == in.proto_type()) {
    if (type == kCamera) {
      const CameraImage img = read_camera(in);
      const pb::Reflection* r = message->GetReflection();
      message->Clear();
      r->SetUInt32(message, field(*message, "imageHeight"), img.height);
      r->SetUInt32(message, field(*message, "imageWidth"), img.width);
      r->SetUInt32(message, field(*message, "imageDepth"), img.depth);
      count_copy(img.pixels.size());
      r->SetString(message, field(*message, "imageData"), std::string(img.pixels));
    } else {
      read_same_wire(in, message);
    }
    return;
  }
  read_proto(in, message);
}

}  // namespace convoy::datapack
