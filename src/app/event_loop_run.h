// SimulationLoop "EventLoop" (NRP-Core 1.4's EventLoopSimManager) for a config without
// engines: the computational graph runs in real time, a cycle every EventLoop.Timestep, until
// EventLoop.Timeout wall seconds (0: until interrupted; SimulationTimeout is not used, as in
// NRP-Core). The loop itself is Python's (nrp_core.event_loop.EventLoopRun); here: the order
// of things and the exit codes.
//
//   MQTTNode     the graph's MQTT client (nrp_core/event_loop/_mqtt.py); mosquitto is started
//                for the run when no broker answers at a local MQTTBroker (log:
//                logs/mosquitto.log) and stopped with it. Exported to the run's processes as
//                $CONVOY_MQTT_BROKER (the asynchronous engines use it when their config has no
//                MQTTConfig.MQTTBroker).
//   ROSNode      the graph's ROS node (RospyInterface).
//   ExternalProcesses  started after the graph is loaded, stopped after the loop.
#pragma once

#include <filesystem>

#include "app/run_log.h"
#include "app/session.h"
#include "config/simulation_config.h"

namespace convoy::app {

// With the interpreter up. A bad MQTTNode, ROSNode or graph file: exit 2; a node that raises
// while the loop runs: exit 4; an interrupt: 130.
Outcome run_event_loop(const config::SimulationConfig& cfg, const std::filesystem::path& run_dir,
                       RunLog& log, LoopFigures* figures);

}  // namespace convoy::app
