// SimulationLoop "EventLoop" (NRP-Core 1.4's EventLoopSimManager): the computational graph
// runs in real time, a cycle every EventLoop.Timestep, until EventLoop.Timeout wall seconds (0:
// until interrupted; SimulationTimeout is not used, as in NRP-Core). The loop itself is
// Python's (nrp_core.event_loop.EventLoopRun); here: the order of things and the exit codes.
//
// With EngineConfigs, as in NRP-Core, the engines' FTILoop runs beside it on another thread,
// unpaced (as fast as the engines step) until the EventLoop ends; its DataPackProcessor is the
// EventLoop's graph in slave mode (python/graph_runtime.h): after each of its cycles the due
// engines' datapacks go into their FromEngine nodes and the ToEngine nodes' datapacks go to
// them; the EventLoop computes the graph on its own clock. The engines start after the graph
// is loaded and the ExternalProcesses started; an engine that fails ends the run (exit 3).
//
//   MQTTNode     the graph's MQTT client (nrp_core/event_loop/_mqtt.py); mosquitto is started
//                for the run when no broker answers at a local MQTTBroker (log:
//                logs/mosquitto.log) and stopped with it. Exported to the run's processes as
//                $CONVOY_MQTT_BROKER (the asynchronous engines use it when their config has no
//                MQTTConfig.MQTTBroker).
//   ROSNode      the graph's ROS node (RospyInterface).
//   ExternalProcesses  started after the graph is loaded, stopped after the loop.
#pragma once

#include <pybind11/pybind11.h>

#include <filesystem>

#include "app/run_log.h"
#include "app/session.h"
#include "config/simulation_config.h"

namespace convoy::app {

// With the interpreter up. A bad MQTTNode, ROSNode or graph file: exit 2; a node that raises
// while the loop runs: exit 4; an interrupt: 130.
Outcome run_event_loop(const config::SimulationConfig& cfg, const std::filesystem::path& run_dir,
                       RunLog& log, LoopFigures* figures, bool quiet);

// The MQTTNode client and ROSNode node of an FTILoop whose graph uses them ("DataPackProcessor":
// "cg"; NRP-Core connects them in any loop): made active for the graph the Session then loads,
// closed (and a mosquitto or rosmaster started for them stopped) on destruction. Throws
// UserError naming the key (a broker that cannot be reached, no ROS master and none startable).
// With the interpreter up and the GIL held.
class GraphClients {
 public:
  GraphClients(const config::SimulationConfig& cfg, const std::filesystem::path& log_dir,
               RunLog& log);
  ~GraphClients();
  GraphClients(const GraphClients&) = delete;
  GraphClients& operator=(const GraphClients&) = delete;

 private:
  pybind11::object clients_;
};

}  // namespace convoy::app
