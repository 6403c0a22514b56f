#include "python/function_runtime.h"

#include "core/error.h"
#include "python/datapack_convert.h"
#include "python/live_module.h"
#include "transport/frame_socket.h"

namespace convoy::python {

// Executes `file` and returns every function it declares, status functions included.
std::vector<LoadedFunction> FunctionRuntime::execute(const std::string& name,
                                                     const std::filesystem::path& file) {
  std::vector<LoadedFunction> out;
  std::vector<py::object> pending;  // their callables, kept once the file has loaded
  try {
    py::module_ funcs = py::module_::import("nrp_core._functions");
    py::list registered = funcs.attr("_registered");
    registered.attr("clear")();
    load_module_from_file(file);
    py::object pf_class = funcs.attr("_Preprocessing");
    py::object status_class = funcs.attr("_Status");
    for (auto fn : py::list(funcs.attr("_registered"))) {
      LoadedFunction f;
      f.name = name;
      f.file = file;
      f.preprocessing = py::isinstance(fn, pf_class);
      f.status = py::isinstance(fn, status_class);
      f.engine = fn.attr("engine_name").cast<std::string>();
      f.runner_index = callables_.size() + out.size();
      for (auto in : py::list(fn.attr("inputs"))) {
        FunctionInput fi;
        fi.keyword = in.attr("keyword").cast<std::string>();
        const std::string kind = in.attr("kind").cast<std::string>();
        if (kind == "iteration") {
          fi.kind = loop::InputKind::kIteration;
        } else if (kind == "time") {
          fi.kind = loop::InputKind::kTime;
        } else {
          fi.datapack = in.attr("id").attr("dataPackName").cast<std::string>();
          fi.engine = in.attr("id").attr("engineName").cast<std::string>();
          fi.preprocessed = in.attr("preprocessed").cast<bool>();
        }
        f.inputs.push_back(fi);
      }
      out.push_back(std::move(f));
      pending.push_back(fn.attr("function"));
    }
    registered.attr("clear")();
  } catch (py::error_already_set& e) {
    throw UserError(file.string() + ": error while loading function '" + name + "':\n" +
                    format_exception(e));
  }
  for (auto& callable : pending) callables_.push_back(std::move(callable));
  return out;
}

std::vector<LoadedFunction> FunctionRuntime::load(const std::string& name,
                                                  const std::filesystem::path& file) {
  std::vector<LoadedFunction> out = execute(name, file);
  if (out.empty()) {
    throw UserError(file.string() +
                    ": declares no @TransceiverFunction or "
                    "@PreprocessingFunction (function '" +
                    name + "')");
  }
  for (const auto& f : out) {
    if (f.status) {
      throw UserError(file.string() + ": declares a @StatusFunction (function '" + name +
                      "'); a status function is configured under \"StatusFunction\", not in "
                      "DataPackProcessingFunctions");
    }
  }
  return out;
}

LoadedFunction FunctionRuntime::load_status(const std::string& name,
                                            const std::filesystem::path& file) {
  std::vector<LoadedFunction> out = execute(name, file);
  size_t status = 0;
  for (const auto& f : out) {
    if (!f.status) {
      throw UserError(file.string() + ": the StatusFunction file declares a " +
                      (f.preprocessing ? "@PreprocessingFunction" : "@TransceiverFunction") +
                      "; those are configured under DataPackProcessingFunctions");
    }
    ++status;
  }
  if (status != 1) {
    throw UserError(file.string() + ": the StatusFunction file must declare one @StatusFunction, " +
                    "it declares " + std::to_string(status));
  }
  return out.front();
}

void FunctionRuntime::begin_cycle() {
  if (py::len(shared_) > 0) shared_.clear();
}

py::object FunctionRuntime::input_object(const FunctionInput& in, const InputSource& src,
                                         const LoadedFunction& fn) {
  if (in.kind == loop::InputKind::kIteration) return py::int_(src.iteration);
  if (in.kind == loop::InputKind::kTime) return py::int_(src.time_ns);
  py::str key(in.engine + '\0' + in.datapack);
  if (in.preprocessed) {
    if (preprocessed_.contains(key)) {
      py::object obj = preprocessed_[key];
      if (by_reference_) return obj;
      return py::module_::import("copy").attr("deepcopy")(obj);
    }
    return py::module_::import("nrp_core._datapacks").attr("EmptyDataPack")(in.datapack, in.engine);
  }
  if (by_reference_ && shared_.contains(key)) return shared_[key];
  const engine::DataPack* dp = src.engine_datapack(in.engine, in.datapack);
  py::object obj;
  if (dp) {
    const datapack::BlobReader* reader = src.reader_for ? src.reader_for(in.engine) : nullptr;
    obj = to_python(datapack::View(*dp, reader ? *reader : datapack::inline_blob_reader()));
    if (src.updated && !src.updated(in.engine, in.datapack)) obj.attr("_updated") = false;
  } else {
    obj = py::module_::import("nrp_core._datapacks").attr("EmptyDataPack")(in.datapack, in.engine);
  }
  if (by_reference_) shared_[key] = obj;
  return obj;
}

py::object FunctionRuntime::call(const LoadedFunction& fn, const InputSource& src) {
  set_live_time(src.time_ns);  // what convoy_live.publish stamps its messages with
  try {
    py::dict kwargs;
    for (const auto& in : fn.inputs) kwargs[py::str(in.keyword)] = input_object(in, src, fn);
    py::object result = callables_.at(fn.runner_index)(**kwargs);
    if (fn.status) return result;  // checked by run_status()
    if (!py::isinstance<py::list>(result) && !py::isinstance<py::tuple>(result)) {
      throw FunctionError(fn.label() + " returned " + std::string(Py_TYPE(result.ptr())->tp_name) +
                          "; it must return a list of datapacks");
    }
    return result;
  } catch (py::error_already_set& e) {
    throw FunctionError(fn.label() + " raised:\n" + format_exception(e));
  } catch (const std::runtime_error& e) {
    if (dynamic_cast<const FunctionError*>(&e)) throw;
    throw FunctionError(fn.label() + ": " + e.what());
  }
}

void FunctionRuntime::run_transceiver(const LoadedFunction& fn, const InputSource& src,
                                      std::vector<engine::DataPack>* outputs) {
  py::object result = call(fn, src);
  for (auto item : result) {
    outputs->emplace_back();
    try {
      datapack::BlobWriter* writer = nullptr;
      if (src.writer_for && py::hasattr(item, "_id")) {
        writer = src.writer_for(item.attr("_id").attr("engineName").cast<std::string>());
      }
      datapack::Builder out(&outputs->back(), writer ? *writer : inline_writer_);
      from_python(item, out);
      if (const size_t bytes = outputs->back().ByteSizeLong();
          bytes > transport::kMaxMessageBytes) {
        const auto& id = outputs->back().id();
        throw std::length_error("datapack '" + id.name() + "' for engine '" + id.engine_name() +
                                "' is " + std::to_string(bytes) +
                                " bytes, more than one message may carry (" +
                                std::to_string(transport::kMaxMessageBytes) + " bytes)");
      }
    } catch (py::error_already_set& e) {
      throw FunctionError(fn.label() + ": " + format_exception(e));
    } catch (const std::exception& e) {
      throw FunctionError(fn.label() + ": " + e.what());
    }
  }
}

void FunctionRuntime::run_preprocessing(const LoadedFunction& fn, const InputSource& src) {
  py::object result = call(fn, src);
  for (auto item : result) {
    try {
      py::object id = item.attr("_id");
      std::string key = id.attr("engineName").cast<std::string>() + '\0' +
                        id.attr("dataPackName").cast<std::string>();
      preprocessed_[py::str(key)] = item;
    } catch (py::error_already_set& e) {
      throw FunctionError(fn.label() +
                          " returned something that is not a datapack: " + format_exception(e));
    }
  }
}

bool FunctionRuntime::run_status(const LoadedFunction& fn, const InputSource& src,
                                 std::vector<engine::DataPack>* observations) {
  py::object result = call(fn, src);
  const char* expected =
      "; it must return a tuple (done, [data]): done a bool, data a (possibly empty) list of "
      "RawData (e.g. JsonRawData) or datapacks";
  if ((!py::isinstance<py::tuple>(result) && !py::isinstance<py::list>(result)) ||
      py::len(result) != 2) {
    throw FunctionError(fn.label() + " returned " + py::repr(result).cast<std::string>() +
                        expected);
  }
  py::object done_obj = result[py::int_(0)];
  py::object data = result[py::int_(1)];
  const std::string done_type = Py_TYPE(done_obj.ptr())->tp_name;
  if (!PyBool_Check(done_obj.ptr()) && done_type != "numpy.bool_" && done_type != "bool_") {
    throw FunctionError(fn.label() + " returned a " + done_type + " as its done flag" + expected);
  }
  if (!py::isinstance<py::list>(data) && !py::isinstance<py::tuple>(data)) {
    throw FunctionError(fn.label() + " returned a " + Py_TYPE(data.ptr())->tp_name +
                        " as its data" + expected);
  }
  const bool done = PyObject_IsTrue(done_obj.ptr()) == 1;
  static py::object* raw_class =
      new py::object(py::module_::import("nrp_core._datapacks").attr("RawData"));
  static py::object* datapack_class =
      new py::object(py::module_::import("nrp_core._datapacks").attr("DataPack"));
  for (auto item : data) {
    const bool raw = py::isinstance(item, *raw_class);
    if (!raw && !py::isinstance(item, *datapack_class)) {
      throw FunctionError(fn.label() + " returned a " + Py_TYPE(item.ptr())->tp_name +
                          " in its data" + expected);
    }
    py::object value = item.attr("_data");
    if (value.is_none()) continue;  // an empty datapack: nothing to observe, as in NRP-Core
    observations->emplace_back();
    try {
      auto* id = observations->back().mutable_id();
      if (!raw) {
        id->set_name(item.attr("_id").attr("dataPackName").cast<std::string>());
        id->set_engine_name(item.attr("_id").attr("engineName").cast<std::string>());
      }
      datapack::Builder out(&observations->back(), inline_writer_);
      data_from_python(value, out);
    } catch (py::error_already_set& e) {
      throw FunctionError(fn.label() + ": " + format_exception(e));
    } catch (const std::exception& e) {
      throw FunctionError(fn.label() + ": " + e.what());
    }
  }
  return done;
}

void FunctionRuntime::reset() {
  if (py::len(preprocessed_) > 0) preprocessed_.clear();
  begin_cycle();
}

}  // namespace convoy::python
