#include "flow_run.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "traffic_pool/pool.h"

namespace convoy::bench {
namespace tp = traffic_pool;

namespace {

struct Flow {
  std::string from, to;  // edges
  double per_hour = 0;
  std::vector<std::pair<uint32_t, int>> starts;  // (entry pool lane, exit lane id) with a path
  std::vector<size_t> vehicles;                  // pool indices, in departure order
  std::string path;                              // edges of the starts' route
  size_t next = 0;                               // the next to depart
};

// Road id and lane sign of an edge name ("-R": negative lane ids).
std::pair<std::string, int> road_of(const std::string& edge) {
  if (!edge.empty() && edge[0] == '-') return {edge.substr(1), -1};
  return {edge, 1};
}

std::set<int> lane_ids(const tp::PoolNetwork& net, const std::string& edge) {
  const auto [road, sign] = road_of(edge);
  std::set<int> ids;
  for (const tp::PoolLane& l : net.lanes()) {
    if (l.road_id == road && l.junction < 0 && l.lane_id * sign > 0) ids.insert(l.lane_id);
  }
  return ids;
}

// The flow's (entry lane, exit lane) pairs that have a path without lane changes.
// The roads of a route outside junctions as edges ("-R" along s), space-separated.
std::string edges_of(const opendrive::LaneRoute& r) {
  std::string out, last;
  for (const opendrive::RouteSegment& seg : r.segments) {
    if (seg.junction != "-1") continue;
    const std::string e = (seg.lane_id < 0 ? "-" : "") + seg.road_id;
    if (e == last) continue;
    out += (out.empty() ? "" : " ") + e;
    last = e;
  }
  return out;
}

// The flow's (entry lane, exit lane) pairs with a path without lane changes along the roads of
// the shortest of them (f.path: what SUMO is given as the flow's route).
void find_starts(const tp::PoolNetwork& net, Flow& f, const std::string& where) {
  const opendrive::LaneGraph& g = net.graph();
  const std::set<int> from = lane_ids(net, f.from), to = lane_ids(net, f.to);
  if (from.empty() || to.empty()) {
    throw std::runtime_error(where + ": edge '" + (from.empty() ? f.from : f.to) +
                             "' has no driving lane on the map");
  }
  opendrive::RouteOptions opt;
  opt.lane_changes = false;
  const std::string from_road = road_of(f.from).first, to_road = road_of(f.to).first;
  std::vector<std::pair<std::string, std::pair<uint32_t, int>>> found;  // (path, start)
  double best = INFINITY;
  for (int a : from) {
    for (int b : to) {
      const auto r = g.route(from_road, a, to_road, b, opt);
      const uint32_t l = r ? net.pool_lane(g.entry_lane(from_road, a)) : tp::kNone;
      if (l == tp::kNone) continue;
      found.emplace_back(edges_of(*r), std::make_pair(l, b));
      if (r->length < best) best = r->length, f.path = found.back().first;
    }
  }
  for (const auto& [path, start] : found) {
    if (path == f.path) f.starts.push_back(start);
  }
  if (f.starts.empty()) {
    throw std::runtime_error(where + ": no path from edge '" + f.from + "' to edge '" + f.to +
                             "' without lane changes");
  }
}

std::vector<Flow> read_flows(const tp::PoolNetwork& net, const std::string& path,
                             bool check = true) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  std::vector<Flow> flows;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (const size_t c = line.find('#'); c != std::string::npos) line.resize(c);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::stringstream ss(line);
    Flow f;
    std::string rate;
    const std::string where = path + ":" + std::to_string(n);
    if (!std::getline(ss, f.from, ',') || !std::getline(ss, f.to, ',') || !std::getline(ss, rate)) {
      throw std::runtime_error(where + ": expected from_edge,to_edge,vehicles_per_hour");
    }
    f.per_hour = std::atof(rate.c_str());
    if (!(f.per_hour > 0)) throw std::runtime_error(where + ": vehicles_per_hour must be > 0");
    if (check) find_starts(net, f, where);
    flows.push_back(std::move(f));
  }
  if (flows.empty()) throw std::runtime_error(path + ": no flow");
  return flows;
}

// One absent vehicle per departure of every flow over the run, ids "<flow>.<k>" as SUMO's.
std::vector<tp::VehicleSpec> flow_vehicles(std::vector<Flow>& flows, double end_s, uint64_t seed) {
  std::vector<tp::VehicleSpec> specs;
  for (size_t fi = 0; fi < flows.size(); ++fi) {
    Flow& f = flows[fi];
    const size_t n = static_cast<size_t>(std::ceil(end_s * f.per_hour / 3600));
    for (size_t k = 0; k < n; ++k) {
      tp::VehicleSpec v;
      v.id = 'f' + std::to_string(fi);  // (one + at a time: GCC 12 warns falsely otherwise)
      v.id += '.';
      v.id += std::to_string(k);
      v.seed = seed * 1000003 + specs.size();
      v.absent = true;
      v.to = std::make_pair(road_of(f.to).first, f.starts[k % f.starts.size()].second);
      f.vehicles.push_back(specs.size());
      specs.push_back(std::move(v));
    }
  }
  return specs;
}

void write_trace(std::FILE* out, const tp::Pool& pool, const tp::PoolNetwork& net, double t) {
  for (size_t i = 0; i < pool.size(); ++i) {
    if (!pool.present(i)) continue;
    const tp::PoolLane& l = net.lane(pool.lane(i));
    const char* junction = l.junction >= 0 ? net.junctions()[l.junction].id.c_str() : "";
    std::fprintf(out, "%.2f,%s,%s,%d,%u,%.3f,%.2f,%.3f,%.3f,%.2f,%s,%.2f,%.2f,%.2f\n", t,
                 pool.spec(i).id.c_str(), l.road_id.c_str(), l.lane_id, pool.lane(i), pool.s(i),
                 l.length, pool.speed(i), pool.acceleration(i), l.limit, junction, pool.x(i),
                 pool.y(i), pool.spec(i).length);
  }
}

}  // namespace

void run_flows(const tp::PoolNetwork& net, const FlowRunOptions& o) {
  std::vector<Flow> flows = read_flows(net, o.flows_path);
  const double end_s = o.warmup_s + o.seconds;
  tp::Pool pool(net, flow_vehicles(flows, end_s, o.seed));
  pool.set_leave_at_exits(true);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> trace(nullptr, &std::fclose);
  if (!o.trace_path.empty()) {
    trace.reset(std::fopen(o.trace_path.c_str(), "w"));
    if (!trace) throw std::runtime_error(o.trace_path + ": cannot be written");
    std::fprintf(trace.get(),
                 "t,id,road,lane,pool_lane,s,lane_length,speed,accel,limit,junction,x,y,"
                 "length\n");
  }
  std::set<std::pair<uint32_t, uint32_t>> touching;
  size_t collisions = 0, departed = 0, waiting_end = 0;
  const int steps = static_cast<int>(end_s / o.dt + 0.5);
  for (int k = 0; k < steps; ++k) {
    const double t = k * o.dt;
    for (Flow& f : flows) {  // the next departure of each flow, once it is due and free
      if (f.next >= f.vehicles.size() || f.next * 3600 / f.per_hour > t + 1e-9) continue;
      const uint32_t lane = f.starts[f.next % f.starts.size()].first;
      if (pool.enter(f.vehicles[f.next], lane)) ++f.next, ++departed;
    }
    pool.step(o.dt);
    std::set<std::pair<uint32_t, uint32_t>> now;
    for (const auto& p : pool.overlaps()) {
      if (!touching.count(p)) ++collisions;
      now.insert(p);
    }
    touching.swap(now);
    if (trace && pool.time() >= o.warmup_s - 1e-9 && (k + 1) % o.trace_every == 0) {
      write_trace(trace.get(), pool, net, pool.time());
    }
  }
  size_t present = 0;
  for (size_t i = 0; i < pool.size(); ++i) present += pool.present(i);
  for (const Flow& f : flows) {
    for (size_t n = f.next; n < f.vehicles.size(); ++n) {
      waiting_end += n * 3600 / f.per_hour <= end_s;
    }
  }
  std::printf(
      "flows %zu: departed %zu, on the map at the end %zu, arrived %zu, still waiting to "
      "depart %zu; lane changes %llu, junction entries %llu; collisions %zu\n",
      flows.size(), departed, present, departed - present, waiting_end,
      static_cast<unsigned long long>(pool.stats().lane_changes),
      static_cast<unsigned long long>(pool.stats().junction_entries), collisions);
}

void print_routable(const tp::PoolNetwork& net, const std::string& flows_path) {
  for (Flow& f : read_flows(net, flows_path, false)) {
    bool ok = true;
    try {
      find_starts(net, f, flows_path);
    } catch (const std::runtime_error&) {
      ok = false;
    }
    std::printf("%s,%s,%g,%s\n", f.from.c_str(), f.to.c_str(), f.per_hour,
                ok ? ("yes," + f.path).c_str() : "no");
  }
}

}  // namespace convoy::bench
