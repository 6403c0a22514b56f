#include "datapack/proto.h"

#include <google/protobuf/descriptor.h>

namespace convoy::datapack {

void write_proto(Builder& out, const google::protobuf::Message& message) {
  auto* dp = out.message();
  const std::string& type = message.GetDescriptor()->full_name();
  dp->mutable_id()->set_type(type);
  auto* payload = dp->mutable_proto();
  payload->set_type_name(type);
  message.SerializeToString(payload->mutable_data());
}

void read_proto(const View& in, google::protobuf::Message* message) {
  const std::string& want = message->GetDescriptor()->full_name();
  if (!in.is_proto() || in.proto_type() != want) {
    throw std::runtime_error(in.describe() + " holds " +
                             (in.is_proto()  ? "protobuf type " + in.proto_type()
                              : in.is_json() ? std::string("JSON")
                                             : std::string("nothing")) +
                             ", not " + want);
  }
  if (!message->ParseFromString(in.message().proto().data()))
    throw std::runtime_error(in.describe() + ": corrupt " + want);
}

}  // namespace convoy::datapack
