// The datapack type names: one registry of the protobuf messages datapacks may carry.
//
// A protobuf datapack carries its message's full name ("convoy.data.Camera") in
// DataPackId.type and ProtoPayload.type_name. Adding a protobuf datapack type is its
// message in a proto/convoy/*.proto file plus one line in standard_types.cpp. Types can
// also be named at run time (NRP-Core's ProtobufPackages): messages compiled into the
// program, or read from .proto files with import_proto().
//
// The Python bridge derives the Python class of every registered type from here: its
// datapack class name, and its message class, built from the file descriptors.
#pragma once

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace convoy::datapack {

struct TypeInfo {
  std::string name;  // full protobuf name
  // The nrp_core.data.nrp_protobuf class of its datapacks ("GazeboCameraDataPack"); by
  // default NRP-Core's rule: the package's parts capitalised, the message name, "DataPack".
  std::string python_class;
  // python_class was given at registration: when two types share a class name (the standard
  // convoy.data.Camera and NRP-Core's Gazebo.Camera), Python's name lookup takes this one.
  bool named_class = false;
  const google::protobuf::Descriptor* descriptor = nullptr;
  const google::protobuf::Message* prototype = nullptr;
};

class Registry {
 public:
  // The process's registry, holding the standard types (standard_types.cpp).
  static Registry& global();

  // Registers message type M under its full name.
  template <typename M>
  const TypeInfo& add(std::string python_class = {}) {
    return add(M::descriptor(), &M::default_instance(), std::move(python_class));
  }
  const TypeInfo& add(const google::protobuf::Descriptor* descriptor,
                      const google::protobuf::Message* prototype, std::string python_class = {});
  // Registers a type named at run time: a message compiled into this program or read by
  // import_proto(). Throws std::invalid_argument naming it when there is no such message.
  const TypeInfo& add_by_name(const std::string& full_name);
  // Reads a .proto file (and its imports, looked up in `include_dirs` and next to it) and
  // registers all its messages. Throws std::invalid_argument naming file and line on errors.
  void import_proto(const std::filesystem::path& file,
                    const std::vector<std::filesystem::path>& include_dirs = {});

  const TypeInfo* find(std::string_view name) const;
  // Throws std::invalid_argument naming the type when it is not registered.
  const TypeInfo& require(std::string_view name) const;
  std::vector<const TypeInfo*> all() const;

  // The serialized FileDescriptorSet of a type's file and everything it imports, dependencies
  // first: what a Python protobuf pool needs to build the message class.
  std::string file_descriptor_set(std::string_view name) const;

  static std::string default_python_class(const google::protobuf::Descriptor* descriptor);

  Registry();
  ~Registry();

 private:
  struct Imported;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, std::unique_ptr<TypeInfo>> types_;
  std::unique_ptr<Imported> imported_;
};

// Full name of message type M ("convoy.data.Camera").
template <typename M>
const std::string& type_name() {
  return M::descriptor()->full_name();
}

void register_standard_types(Registry& registry);

}  // namespace convoy::datapack
