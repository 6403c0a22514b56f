// traffic_pool_bench --flows: the pool fed a demand given as flows (what benchmarks/realism
// gives SUMO too), with a trajectory trace. A flow file has one flow a line,
// `from_edge,to_edge,vehicles_per_hour` ('#' starts a comment), edges named as netconvert
// names an OpenDRIVE road: "-R" is road R's lanes along s (negative ids), "R" those against
// it. Vehicle k of flow f departs at k * 3600 / vehicles_per_hour s (as SUMO's <flow
// vehsPerHour>), standing at the start of one of the entry road's lanes with a path to the exit
// road without lane changes along the roads of the shortest such path (in turn), waits while
// that start is not free, follows its route and leaves the map at the exit road's end.
#pragma once

#include <cstdint>
#include <string>

#include "traffic_pool/network.h"

namespace convoy::bench {

struct FlowRunOptions {
  std::string flows_path;  // the flow file
  std::string trace_path;  // CSV trace, empty: none
  double warmup_s = 300;   // simulated before the trace starts
  double seconds = 600;    // traced
  double dt = 0.05;
  int trace_every = 2;  // steps between trace rows
  uint64_t seed = 1;
};

// Runs it and prints a summary; throws std::runtime_error naming the file and line on bad
// input (an unknown edge, a flow with no path, a rate <= 0).
void run_flows(const traffic_pool::PoolNetwork& net, const FlowRunOptions& o);
// Prints each flow of the file as `from_edge,to_edge,vehicles_per_hour,yes,EDGES` when the pool
// can drive it (a path without lane changes; EDGES: the roads of the shortest such path, the
// route its vehicles take, space-separated) or `...,no`; throws only for malformed lines.
void print_routable(const traffic_pool::PoolNetwork& net, const std::string& flows_path);

}  // namespace convoy::bench
