// A map's <signal>s in the world: traffic lights and signs as catalog models on poles beside
// the road (facing the traffic they are for), stop lines and crosswalks as paint. A signal of
// a type the generator does not know is skipped with a warning naming it.
#pragma once

#include <string>

#include "opendrive/network.h"
#include "worldgen/catalog.h"
#include "worldgen/world_plan.h"

namespace convoy::worldgen {

enum class SignalKind {
  kTrafficLight,     // OpenDRIVE 1000001
  kPedestrianLight,  // 1000002
  kSign,             // stop, yield, no_entry, speed_limit, priority, warning
  kStopLine,         // 294 (DE) / a holding line
  kCrosswalk,        // a crosswalk marking given as a signal
  kArrow,            // an arrow painted on a lane (297 (DE), VIRES' SgRMArrow*)
  kUnknown,
};

struct SignalClass {
  SignalKind kind = SignalKind::kUnknown;
  std::string sign_type;  // for kSign; for kArrow its directions ("straight_right", "left")
  double value = 0;       // speed limits: km/h
};

// What a signal is, from its country, type, subtype, value, unit and name.
SignalClass classify_signal(const opendrive::Signal& sig);

// Adds every signal of the network to the plan (models, paint, warnings).
void place_signals(const opendrive::Network& net, const Catalog& catalog, WorldPlan& plan);

}  // namespace convoy::worldgen
