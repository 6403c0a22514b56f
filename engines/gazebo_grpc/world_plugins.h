// The model plugins the world description reads from SDF (internal to convoy_world):
// NRP joint controllers (PIDs), Convoy's brake plugin, the convoy_class annotation, the
// convoy_signal lamps and NRP link plugins. See world_description.h for their formats.
// Each reader throws std::runtime_error("<file>: <where>: <problem>"), where `where` is
// "model '<model>' plugin '<plugin>'".
#pragma once

#include <filesystem>
#include <sdf/Element.hh>
#include <string>
#include <vector>

#include "world_description.h"

namespace convoy::world {

// The attribute `name` of `e` as text, "" if it has none.
std::string attribute(const sdf::ElementPtr& e, const char* name);

// A joint controller's PIDs, one per child element <joint_name P I D Type Target IMax IMin/>;
// each joint must be one of `model`'s (scoped as `model_name`::joint_name).
std::vector<PidDesc> read_joint_controller(const sdf::ElementPtr& plugin,
                                           const std::string& model_name,
                                           const std::filesystem::path& file,
                                           const std::string& where, const ModelDesc& model);

// A ConvoyBrakePlugin named `name`: <abs>, <slip> and one brake per joint of `model`.
BrakePluginDesc read_brake_plugin(const sdf::ElementPtr& plugin, const std::string& name,
                                  const std::string& model_name, const std::filesystem::path& file,
                                  const std::string& where, const ModelDesc& model);

// A convoy_class plugin's <class>, one of known_classes().
std::string read_class(const sdf::ElementPtr& plugin, const std::filesystem::path& file,
                       const std::string& where);

// A convoy_signal plugin: its signal id and lamps, each a visual of `model`'s links.
SignalDesc read_signal(const sdf::ElementPtr& plugin, const std::filesystem::path& file,
                       const std::string& where, const ModelDesc& model);

// Reads every <plugin> of the model element `elem` into `model` (whose links and joints are
// read already), by its filename; plugins of other kinds are ignored. `model_name` is the
// model's scoped name, `file` the world (or model) file the errors name.
void read_plugins(const sdf::ElementPtr& elem, const std::string& model_name,
                  const std::filesystem::path& file, ModelDesc* model);

}  // namespace convoy::world
