#include "python/live_module.h"

#include <pybind11/embed.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace convoy::python {
namespace {

namespace py = pybind11;

LivePublisher& publisher(PublisherSlot slot) {
  static LivePublisher p[2];
  return p[static_cast<int>(slot)];
}
bool any_publisher() {
  return publisher(PublisherSlot::kLive) || publisher(PublisherSlot::kRecording);
}
int64_t g_time_ns = 0;

// A Python value as JSON: dict (string keys), list, tuple, str, bool, int, float (NaN and
// infinities as null), None, and numpy scalars (.item()). Throws py::type_error otherwise.
nlohmann::json to_json(py::handle obj, int depth = 0) {
  if (depth > 64) throw py::value_error("convoy_live.publish: the object is nested too deeply");
  if (obj.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(obj)) return obj.cast<bool>();
  if (py::isinstance<py::int_>(obj)) {
    try {
      return obj.cast<int64_t>();
    } catch (const py::cast_error&) {
      return obj.cast<double>();
    }
  }
  if (py::isinstance<py::float_>(obj)) {
    const double v = obj.cast<double>();
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
  }
  if (py::isinstance<py::str>(obj)) return obj.cast<std::string>();
  if (py::isinstance<py::dict>(obj)) {
    nlohmann::json out = nlohmann::json::object();
    for (auto [k, v] : py::reinterpret_borrow<py::dict>(obj)) {
      if (!py::isinstance<py::str>(k))
        throw py::type_error("convoy_live.publish: dict keys must be strings, got " +
                             std::string(py::str(py::type::of(k).attr("__name__"))));
      out[k.cast<std::string>()] = to_json(v, depth + 1);
    }
    return out;
  }
  if (py::isinstance<py::list>(obj) || py::isinstance<py::tuple>(obj)) {
    nlohmann::json out = nlohmann::json::array();
    for (auto v : obj) out.push_back(to_json(v, depth + 1));
    return out;
  }
  if (py::hasattr(obj, "item") && py::hasattr(obj, "dtype"))
    return to_json(obj.attr("item")(), depth + 1);
  throw py::type_error("convoy_live.publish: cannot send a " +
                       std::string(py::str(py::type::of(obj).attr("__name__"))) + " as JSON");
}

}  // namespace

void set_live_publisher(LivePublisher p, PublisherSlot slot) { publisher(slot) = std::move(p); }
void set_live_time(int64_t time_ns) { g_time_ns = time_ns; }

}  // namespace convoy::python

PYBIND11_EMBEDDED_MODULE(convoy_live, m) {
  namespace py = pybind11;
  using convoy::python::kInfractionsTopic;
  using convoy::python::kMetricsTopic;
  m.doc() =
      "Sends JSON objects to the viewers of a live run (convoy run --live) and into its "
      "recording (--record): /convoy/metrics (summary fields, merged into the latest) and "
      "/convoy/infractions (one event each).";
  m.attr("TOPICS") = py::make_tuple(kMetricsTopic, kInfractionsTopic);
  m.def(
      "enabled", [] { return convoy::python::any_publisher(); },
      "True in a live or recorded run: publish() sends.");
  m.def(
      "publish",
      [](const std::string& topic, py::handle obj) {
        if (topic != kMetricsTopic && topic != kInfractionsTopic)
          throw py::value_error("convoy_live.publish: topic must be " + std::string(kMetricsTopic) +
                                " or " + kInfractionsTopic + ", got '" + topic + "'");
        if (!py::isinstance<py::dict>(obj))
          throw py::type_error("convoy_live.publish: the message must be a dict, got " +
                               std::string(py::str(py::type::of(obj).attr("__name__"))));
        using convoy::python::PublisherSlot;
        if (!convoy::python::any_publisher()) return false;
        const std::string text = convoy::python::to_json(obj).dump();
        bool sent = false;
        for (PublisherSlot slot : {PublisherSlot::kLive, PublisherSlot::kRecording}) {
          auto& p = convoy::python::publisher(slot);
          if (p && p(topic, text, convoy::python::g_time_ns)) sent = true;
        }
        return sent;
      },
      py::arg("topic"), py::arg("obj"),
      "Sends the dict `obj` (JSON-serialisable) on `topic`; False when the run is neither live nor "
      "recorded.");
}
