#include "python/function_runtime.h"

#include "core/error.h"
#include "python/datapack_convert.h"
#include "transport/frame_socket.h"

namespace convoy::python {

std::vector<LoadedFunction> FunctionRuntime::load(const std::string& name,
                                                  const std::filesystem::path& file) {
  std::vector<LoadedFunction> out;
  std::vector<py::object> pending;  // their callables, kept once the file has loaded
  try {
    py::module_ funcs = py::module_::import("nrp_core._functions");
    py::list registered = funcs.attr("_registered");
    registered.attr("clear")();
    load_module_from_file(file);
    py::object pf_class = funcs.attr("_Preprocessing");
    for (auto fn : py::list(funcs.attr("_registered"))) {
      LoadedFunction f;
      f.name = name;
      f.file = file;
      f.preprocessing = py::isinstance(fn, pf_class);
      f.engine = fn.attr("engine_name").cast<std::string>();
      f.runner_index = callables_.size() + out.size();
      for (auto in : py::list(fn.attr("inputs"))) {
        FunctionInput fi;
        fi.keyword = in.attr("keyword").cast<std::string>();
        fi.datapack = in.attr("id").attr("dataPackName").cast<std::string>();
        fi.engine = in.attr("id").attr("engineName").cast<std::string>();
        fi.preprocessed = in.attr("preprocessed").cast<bool>();
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
  if (out.empty()) {
    throw UserError(file.string() +
                    ": declares no @TransceiverFunction or "
                    "@PreprocessingFunction (function '" +
                    name + "')");
  }
  for (auto& callable : pending) callables_.push_back(std::move(callable));
  return out;
}

void FunctionRuntime::begin_cycle() {
  if (py::len(shared_) > 0) shared_.clear();
}

py::object FunctionRuntime::input_object(const FunctionInput& in, const InputSource& src,
                                         const LoadedFunction& fn) {
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
  try {
    py::dict kwargs;
    for (const auto& in : fn.inputs) kwargs[py::str(in.keyword)] = input_object(in, src, fn);
    py::object result = callables_.at(fn.runner_index)(**kwargs);
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

}  // namespace convoy::python
