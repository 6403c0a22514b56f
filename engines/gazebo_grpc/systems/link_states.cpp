#include "systems/link_states.h"

#include "convoy/datapacks.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "physics_world.h"
#include "world_description.h"

namespace convoy::world {

void LinkStates::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  for (size_t m = 0; m < ctx.desc->models.size(); ++m) {
    const ModelDesc& model = ctx.desc->models[m];
    for (const auto& plugin : model.link_plugins) {
      for (const auto& link : model.links) {
        int index = ctx.physics->link_index(link.name);
        for (const std::string& n : {plugin + "::" + link.short_name, link.name}) {
          by_datapack_[n] = index;
          provided_.push_back({n, datapack::type_name<data::Link>(), static_cast<int>(m)});
        }
      }
    }
  }
}

void LinkStates::get_datapack(const std::string& name, datapack::Builder& out) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return;
  auto s = ctx_->physics->link_state(it->second);
  data::Link l;
  for (int k = 0; k < 3; ++k) l.add_position(static_cast<float>(s.position[k]));
  for (double v : {s.rotation.x(), s.rotation.y(), s.rotation.z(), s.rotation.w()})
    l.add_rotation(static_cast<float>(v));
  for (int k = 0; k < 3; ++k) l.add_linear_velocity(static_cast<float>(s.linear_velocity[k]));
  for (int k = 0; k < 3; ++k) l.add_angular_velocity(static_cast<float>(s.angular_velocity[k]));
  datapack::write_proto(out, l);
}

}  // namespace convoy::world
