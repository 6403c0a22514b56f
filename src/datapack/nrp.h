// NRP-Core's message set (proto/nrp_protobuf): its packages, under the names NRP-Core's
// ProtobufPackages uses, and how its Gazebo messages travel.
//
// Every package is compiled into Convoy and registered in every process
// (register_standard_types), so that transceiver and status functions find their classes
// (DumpStringDataPack, EngineTestTestPayloadRawData...) whatever the engines' config says.
//
// Gazebo.Camera / Joint / Link are NRP-Core's names of Convoy's standard messages
// (convoy.data.Camera / Joint / Link). A datapack holding one is written as the standard type
// (write_message), and either form is read into it (read_message): the world engine, the
// detector and TFs (GazeboCameraDataPack, numpy image) see one type, and a frame travels in a
// blob, in shared memory between local processes.
#pragma once

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>

#include <string>
#include <string_view>
#include <vector>

#include "datapack/datapack.h"
#include "datapack/registry.h"

namespace convoy::datapack {

// The package names, sorted: "Dump", "EngineTest", "Gazebo", "NrpGenericProto", "Wrappers".
const std::vector<std::string>& nrp_packages();
// The .proto file of a package; nullptr if there is no such package.
const google::protobuf::FileDescriptor* nrp_package_file(std::string_view package);
// Registers the messages of every package.
void register_nrp_packages(Registry& registry);

// The standard type a Gazebo message travels as ("convoy.data.Camera" for "Gazebo.Camera"),
// or "" for any other type.
std::string_view standard_type_of(std::string_view type);

// The datapack form of any message: a Gazebo message as its standard type, any other by
// write_proto. The camera's pixels are copied once, into the outgoing blob.
void write_message(Builder& out, const google::protobuf::Message& message);
// Reads a datapack into `message`: a Gazebo message also from its standard type, any other
// by read_proto (whose errors it throws).
void read_message(const View& in, google::protobuf::Message* message);

}  // namespace convoy::datapack
