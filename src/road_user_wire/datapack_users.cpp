#include "road_user_wire/datapack_users.h"

#include <stdexcept>
#include <string>

#include "convoy/road_users.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"

namespace convoy::road_user_wire {

void for_each_user(const datapack::View& dp, const std::function<void(const UserFields&)>& visit) {
  const bool many = dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUsers>();
  const bool one = dp.is_proto() && dp.proto_type() == datapack::type_name<data::RoadUser>();
  if (!many && !one) {
    throw std::invalid_argument("expected convoy.data.RoadUsers or RoadUser, got " +
                                (dp.is_proto() ? dp.proto_type() : std::string("JSON")));
  }
  const engine::ProtoPayload& payload = dp.message().proto();
  std::string joined;  // only when some bytes travelled as blobs (none do in these messages)
  if (payload.blob_fields_size() > 0) joined = datapack::proto_bytes(dp);
  const std::string_view bytes = payload.blob_fields_size() > 0 ? joined : payload.data();
  UserFields u;
  const bool ok = many ? for_each_user(bytes, visit) : read_user(bytes, &u);
  if (!ok) throw std::invalid_argument("corrupt " + dp.proto_type());
  if (one) visit(u);
}

}  // namespace convoy::road_user_wire
