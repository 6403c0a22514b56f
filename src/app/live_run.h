// The live server of a standalone run (`convoy run --live [HOST:]PORT`): a live::LiveServer
// with a live::LiveTap on the loop and the coordinator's log on /convoy/log. Started before
// the engines, so that a port in use or an address refused ends the run before anything
// starts; finished after the loop, with each client's figures for the log and summary.json.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>

#include "app/run_log.h"
#include "app/simulation.h"
#include "config/simulation_config.h"
#include "live/live_tap.h"
#include "live/run_control.h"
#include "live/server.h"
#include "loop/pause_gate.h"

namespace convoy::app {

class LiveRun {
 public:
  // Throws UserError naming --live and the address (not loopback without --insecure, port in
  // use, no such address).
  LiveRun(const RunOptions& options, const config::SimulationConfig& cfg, RunLog& log);
  ~LiveRun();
  loop::DataPackTap* tap() { return tap_.get(); }
  // Where the viewers pause the loop (/convoy/control).
  loop::PauseGate* gate() { return &gate_; }
  // Closes the connections once their queues are sent (at most 1 s), logs what each client
  // got and lost; summary.json's "live".
  nlohmann::json finish();

 private:
  RunLog& log_;
  std::unique_ptr<live::LiveServer> server_;
  std::unique_ptr<live::LiveTap> tap_;  // after the server: goes first
  loop::PauseGate gate_;
  std::unique_ptr<live::RunControl> control_;
  bool finished_ = false;
  nlohmann::json figures_;
};

}  // namespace convoy::app
