#include "python/graph_runtime.h"

#include <optional>
#include <set>
#include <stdexcept>

#include "core/error.h"
#include "python/datapack_convert.h"
#include "python/live_module.h"
#include "transport/frame_socket.h"

namespace convoy::python {

namespace fs = std::filesystem;

namespace {

// The message of a Python exception: a ComputationalGraphError's own text (it names the file
// or node and carries the user's traceback), else the whole traceback.
std::string message_of(py::error_already_set& e) {
  try {
    py::object cge = py::module_::import("nrp_core.event_loop").attr("ComputationalGraphError");
    if (e.matches(cge)) return py::str(e.value()).cast<std::string>();
  } catch (...) {
  }
  return format_exception(e);
}

std::string names(const std::vector<std::string>& list) {
  std::string out;
  for (const auto& s : list) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

void GraphRuntime::load(const std::vector<fs::path>& files, const fs::path& base_dir,
                        const std::vector<std::string>& engines) {
  std::vector<std::string> file_names;
  py::list py_files;
  for (const auto& f : files) {
    file_names.push_back(f.filename().string());
    py_files.append(f.string());
  }
  label_ = "computational graph (" + names(file_names) + ")";
  try {
    py::module_ el = py::module_::import("nrp_core.event_loop");
    empty_class_ = py::module_::import("nrp_core._datapacks").attr("EmptyDataPack");
    graph_ = py::module_::import("nrp_core.event_loop._loop").attr("event_loop_graph")();
    slave_ = !graph_.is_none();
    if (slave_) {
      link_ = el.attr("EngineLink")(graph_);
    } else {
      py::object transports =
          py::module_::import("nrp_core.event_loop._clients").attr("active_transports")();
      graph_ = el.attr("load_computational_graph")(py_files, py::arg("transports") = transports,
                                                   py::arg("base_dir") = base_dir.string(),
                                                   py::arg("fti_loop") = true);
      link_ = el.attr("EngineLink")(graph_);
      step_ = el.attr("FTIStep")(graph_, link_, transports.attr("ros"));
    }
    py::object ns = py::module_::import("types").attr("SimpleNamespace");
    source_ = ns(py::arg("get_datapacks") =
                     py::cpp_function([this](const std::string& engine, const py::list& names) {
                       return get_datapacks(engine, names);
                     }));
    sink_ = ns(py::arg("send_datapacks") =
                   py::cpp_function([this](const std::string& engine, const py::list& dps) {
                     send_datapacks(engine, dps);
                   }));
  } catch (py::error_already_set& e) {
    throw UserError(label_ + ": " + message_of(e));
  }
  check_engines(engines);
}

void GraphRuntime::check_engines(const std::vector<std::string>& engines) {
  const std::set<std::string> known(engines.begin(), engines.end());
  auto check = [&](const char* attr, const char* kind) {
    for (auto item : py::dict(link_.attr(attr))) {
      const std::string engine = item.first.cast<std::string>();
      if (known.count(engine)) continue;
      const std::string node = item.second.attr("id").cast<std::string>();
      throw UserError(label_ + ": " + kind + " node \"" + node + "\" names engine \"" + engine +
                      "\", which is not in EngineConfigs (engines: " + names(engines) + ")");
    }
  };
  check("inputs", "FromEngine");
  check("outputs", "ToEngine");
  requested_.clear();
  for (const auto& engine : engines) {
    for (auto name : py::list(link_.attr("requested")(engine)))
      requested_.emplace_back(engine, name.cast<std::string>());
  }
}

void GraphRuntime::run_preprocessing(const loop::LoadedFunction& fn, const loop::InputSource&) {
  throw std::logic_error(fn.label() + ": no preprocessing function runs with a graph");
}

void GraphRuntime::run_transceiver(const loop::LoadedFunction& fn, const loop::InputSource&,
                                   std::vector<engine::DataPack>*) {
  throw std::logic_error(fn.label() + ": no transceiver function runs with a graph");
}

py::list GraphRuntime::get_datapacks(const std::string& engine, const py::list& names) {
  py::list out;
  for (auto item : names) {
    const std::string name = item.cast<std::string>();
    const engine::DataPack* dp = src_->engine_datapack(engine, name);
    if (!dp) {
      out.append(empty_class_(name, engine));
      continue;
    }
    const datapack::BlobReader* reader = src_->reader_for ? src_->reader_for(engine) : nullptr;
    // Slave mode: the EventLoop reads the datapack in a later cycle, so images are copied.
    py::object obj =
        to_python(datapack::View(*dp, reader ? *reader : datapack::inline_blob_reader()),
                  slave_ ? ImageAccess::kCopy : ImageAccess::kView);
    if (src_->updated && !src_->updated(engine, name)) obj.attr("_updated") = false;
    out.append(obj);
  }
  return out;
}

void GraphRuntime::send_datapacks(const std::string& engine, const py::list& datapacks) {
  datapack::BlobWriter* writer = src_->writer_for ? src_->writer_for(engine) : nullptr;
  for (auto item : datapacks) {
    outputs_->emplace_back();
    datapack::Builder out(&outputs_->back(), writer ? *writer : inline_writer_);
    from_python(item, out);
    if (const size_t bytes = outputs_->back().ByteSizeLong(); bytes > transport::kMaxMessageBytes) {
      const auto& id = outputs_->back().id();
      throw std::length_error("datapack '" + id.name() + "' for engine '" + id.engine_name() +
                              "' is " + std::to_string(bytes) +
                              " bytes, more than one message may carry (" +
                              std::to_string(transport::kMaxMessageBytes) + " bytes)");
    }
  }
}

void GraphRuntime::run_graph(const std::vector<std::string>& due_engines,
                             const loop::InputSource& src, std::vector<engine::DataPack>* outputs) {
  std::optional<py::gil_scoped_acquire> gil;
  if (slave_) gil.emplace();   // on the FTILoop's thread, beside the EventLoop's
  set_live_time(src.time_ns);  // what convoy_live.publish stamps its messages with
  src_ = &src;
  outputs_ = outputs;
  try {
    py::list due;
    for (const auto& e : due_engines) due.append(e);
    if (slave_) {
      link_.attr("update_from_engines")(source_, due);
      link_.attr("send_to_engines")(sink_, due);
    } else {
      step_.attr("step")(source_, sink_, due, src.time_ns / 1'000'000, src.iteration);
    }
  } catch (py::error_already_set& e) {
    src_ = nullptr;
    throw FunctionError(label_ + ": " + message_of(e));
  } catch (const std::exception& e) {
    src_ = nullptr;
    throw FunctionError(label_ + ": " + e.what());
  }
  src_ = nullptr;
  outputs_ = nullptr;
}

}  // namespace convoy::python
