// The computational graph as the FTILoop's DataPackProcessor ("cg"): NRP-Core 1.4's
// ComputationalGraphHandle outside slave mode, over the pure-Python graph of
// python/nrp_core/event_loop.
//
// load() executes the config's ComputationalGraph files (OutputDriven mode, ToEngine nodes
// computed only when their engine has finished a step). Each loop cycle, run_graph() pushes
// the due engines' datapacks into their FromEngine nodes ("<engine>_input"), sets the Clock
// node to the simulated time in ms and the Iteration node to the cycle, computes the graph and
// returns what the due engines' ToEngine nodes ("<engine>_output") hold. The graph's MQTT and
// ROS nodes use the process's active GraphClients (nrp_core.event_loop._clients), if any.
//
// Slave mode (SimulationLoop "EventLoop" with EngineConfigs, NRP-Core's ComputationalGraphHandle
// with slaveMode): when an EventLoop runs in the process (nrp_core.event_loop._loop
// .event_loop_graph()), load() takes its graph instead of loading the files, and run_graph(),
// called on the FTILoop's own thread, takes the GIL, hands the due engines' datapacks to the
// FromEngine nodes and sends what their ToEngine nodes hold; the EventLoop computes the graph.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"
#include "loop/function_runner.h"
#include "python/interpreter.h"

namespace convoy::python {

class GraphRuntime final : public loop::FunctionRunner {
 public:
  // Loads the graph from `files` (absolute, in order) and checks that its FromEngine and
  // ToEngine nodes name engines of `engines`. Throws UserError with the loader's message (a
  // missing file, a Python error, a node cycle, an unknown node or port, an unknown engine).
  void load(const std::vector<std::filesystem::path>& files, const std::filesystem::path& base_dir,
            const std::vector<std::string>& engines);

  // The datapacks the graph reads: (engine, datapack name), engines in `engines` order.
  std::vector<std::pair<std::string, std::string>> requested() const { return requested_; }
  // "computational graph (a.py, b.py)", for messages.
  const std::string& label() const { return label_; }
  // The graph is an EventLoop's (see above).
  bool slave() const { return slave_; }

  void begin_cycle() override {}
  // A graph has no transceiver or preprocessing functions: these throw std::logic_error.
  void run_preprocessing(const loop::LoadedFunction& fn, const loop::InputSource& src) override;
  void run_transceiver(const loop::LoadedFunction& fn, const loop::InputSource& src,
                       std::vector<engine::DataPack>* outputs) override;
  // Throws FunctionError naming the node that failed (with its Python traceback).
  void run_graph(const std::vector<std::string>& due_engines, const loop::InputSource& src,
                 std::vector<engine::DataPack>* outputs) override;

 private:
  void check_engines(const std::vector<std::string>& engines);
  py::list get_datapacks(const std::string& engine, const py::list& names);
  void send_datapacks(const std::string& engine, const py::list& datapacks);

  std::string label_;
  bool slave_ = false;
  py::object graph_, link_, step_;
  py::object source_, sink_;  // the FTIStep's DataPackSource and DataPackSink
  py::object empty_class_;    // nrp_core._datapacks.EmptyDataPack
  std::vector<std::pair<std::string, std::string>> requested_;
  // During run_graph(): where the sink's datapacks go.
  const loop::InputSource* src_ = nullptr;
  std::vector<engine::DataPack>* outputs_ = nullptr;
  datapack::InlineBlobWriter inline_writer_;  // for engines without a blob writer
};

}  // namespace convoy::python
