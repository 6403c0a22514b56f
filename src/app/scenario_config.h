// `convoy run --scenario FILE.xosc`: the scenario's default config, made in this process by
// python/convoy_scenario/make_config.py in the embedded interpreter (docs/scenarios.md,
// "Running a scenario"); the interpreter stays up for the run that follows, so the run's
// functions find the scenario already read.
#pragma once

#include <string>
#include <vector>

#include "app/simulation.h"

namespace convoy::app {

struct ScenarioRequest {
  std::string scenario;             // the .xosc
  std::string world;                // --world
  std::string ego;                  // --ego: a fragment, or "scenario"
  std::string scenery;              // --scenery
  std::vector<std::string> params;  // --scenario-param NAME=VALUE
  std::string perception;           // --perception: ground_truth (default) or sensors
};

// Writes RUN_DIR/scenario_config.json (creating the run folder, default
// ./runs/scenario_<stem>-<time>-<pid> or under $CONVOY_RUNS_DIR) and points `options` at it.
// Needs the embedded interpreter up. False after saying why on stderr.
bool prepare_scenario(const ScenarioRequest& request, RunOptions& options);

}  // namespace convoy::app
