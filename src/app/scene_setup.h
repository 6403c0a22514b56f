// The scene of a run for the live server and the recording (scene/): the map the config
// names, loaded once per file in the process (both use it), the ego's route and the world
// engines. A map that cannot be read is a warning: the run and its scene go on without it.
#pragma once

#include <memory>
#include <vector>

#include "app/run_log.h"
#include "config/simulation_config.h"
#include "loop/engine_handle.h"
#include "scene/scene_map.h"
#include "scene/scene_state.h"

namespace convoy::app {

struct SceneSetup {
  std::shared_ptr<const scene::SceneMap> map;  // null: no map found or readable
  scene::SceneOptions options;
};

SceneSetup scene_setup(const config::SimulationConfig& cfg, RunLog& log);

// The road users the scene shows that the functions may not read, for the loop to ask for
// anyway (loop::FtiLoop::also_want): each world engine's (EngineType gazebo_grpc) egos'
// `<model>::road_user` (its ego_state: EgoModels, by default every moving model with a joint
// controller) and each vehicle_agent's and pedestrian_agent's state (StateDataPack). The names
// are what the engines registered at Initialize (loop::EngineHandle::registered): their
// RoadUser datapacks. None for an engine that registered none (a replay's).
std::vector<engine::DataPackId> scene_datapacks(const std::vector<loop::EngineHandle*>& engines);

}  // namespace convoy::app
