#include "world_plugins.h"

#include <cmath>
#include <stdexcept>

namespace convoy::world {

namespace fs = std::filesystem;

namespace {

bool has_joint(const ModelDesc& model, const std::string& scoped) {
  bool known = false;
  for (const auto& jd : model.joints) known |= jd.name == scoped;
  return known;
}

std::string text_of(const sdf::ElementPtr& e) {
  return e->GetValue() ? e->GetValue()->GetAsString() : "";
}

// A brake plugin's number: all of `text` a finite double, else an error naming `what`.
double brake_number(const std::string& text, const std::string& what, const fs::path& file,
                    const std::string& where) {
  try {
    size_t used = 0;
    double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument(text);
    return v;
  } catch (const std::exception&) {
    throw std::runtime_error(file.string() + ": " + where + ": " + what + " '" + text +
                             "' is not a number");
  }
}

// One brake of a ConvoyBrakePlugin: the element <joint_name MaxTorque="..."/>.
BrakeDesc read_brake(const sdf::ElementPtr& j, const std::string& model_name, const fs::path& file,
                     const std::string& where, const ModelDesc& model) {
  const std::string tag = j->GetName();
  BrakeDesc b;
  b.joint = model_name + "::" + tag;
  if (!has_joint(model, b.joint))
    throw std::runtime_error(file.string() + ": " + where + ": unknown joint '" + tag + "'");
  const std::string t = attribute(j, "MaxTorque");
  if (!t.empty()) b.max_torque = brake_number(t, "joint '" + tag + "': MaxTorque", file, where);
  if (!(b.max_torque > 0))
    throw std::runtime_error(file.string() + ": " + where + ": joint '" + tag +
                             "': MaxTorque must be > 0");
  return b;
}

}  // namespace

std::string attribute(const sdf::ElementPtr& e, const char* name) {
  auto a = e->GetAttribute(name);
  return a ? a->GetAsString() : "";
}

std::vector<PidDesc> read_joint_controller(const sdf::ElementPtr& plugin,
                                           const std::string& model_name, const fs::path& file,
                                           const std::string& where, const ModelDesc& model) {
  std::vector<PidDesc> pids;
  for (auto j = plugin->GetFirstElement(); j; j = j->GetNextElement()) {
    PidDesc pid;
    pid.joint = model_name + "::" + j->GetName();
    if (!has_joint(model, pid.joint)) {
      throw std::runtime_error(file.string() + ": " + where + ": unknown joint '" + j->GetName() +
                               "'");
    }
    auto num = [&](const char* key, double def) {
      std::string v = attribute(j, key);
      if (v.empty()) return def;
      try {
        return std::stod(v);
      } catch (const std::exception&) {
        throw std::runtime_error(file.string() + ": " + where + ": joint '" + j->GetName() +
                                 "': " + key + "='" + v + "' is not a number");
      }
    };
    pid.p = num("P", 0);
    pid.i = num("I", 0);
    pid.d = num("D", 0);
    pid.target = num("Target", 0);
    pid.i_max = num("IMax", 0);
    pid.i_min = num("IMin", 0);
    std::string type = attribute(j, "Type");
    if (type != "position" && type != "velocity") {
      throw std::runtime_error(file.string() + ": " + where + ": joint '" + j->GetName() +
                               "': Type must be position or velocity, got '" + type + "'");
    }
    pid.velocity = type == "velocity";
    pids.push_back(pid);
  }
  return pids;
}

BrakePluginDesc read_brake_plugin(const sdf::ElementPtr& plugin, const std::string& name,
                                  const std::string& model_name, const fs::path& file,
                                  const std::string& where, const ModelDesc& model) {
  BrakePluginDesc bp;
  bp.name = name;
  for (auto j = plugin->GetFirstElement(); j; j = j->GetNextElement()) {
    const std::string tag = j->GetName();
    if (tag == "abs") {
      const std::string v = text_of(j);
      if (v != "true" && v != "false" && v != "1" && v != "0")
        throw std::runtime_error(file.string() + ": " + where +
                                 ": <abs> must be true or false, got '" + v + "'");
      bp.abs = v == "true" || v == "1";
    } else if (tag == "slip") {
      bp.slip = brake_number(text_of(j), "<slip>", file, where);
      if (!(bp.slip > 0 && bp.slip < 1))
        throw std::runtime_error(file.string() + ": " + where + ": <slip> must be in (0, 1)");
    } else {
      bp.brakes.push_back(read_brake(j, model_name, file, where, model));
    }
  }
  return bp;
}

std::string read_class(const sdf::ElementPtr& plugin, const fs::path& file,
                       const std::string& where) {
  std::string cls = plugin->HasElement("class") ? plugin->Get<std::string>("class") : "";
  if (!is_known_class(cls)) {
    std::string all;
    for (const auto& c : known_classes()) all += (all.empty() ? "" : ", ") + c;
    throw std::runtime_error(file.string() + ": " + where + ": <class> '" + cls +
                             "' is not one of " + all);
  }
  return cls;
}

SignalDesc read_signal(const sdf::ElementPtr& plugin, const fs::path& file,
                       const std::string& where, const ModelDesc& model) {
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(file.string() + ": " + where + ": " + what);
  };
  SignalDesc s;
  for (auto e = plugin->GetFirstElement(); e; e = e->GetNextElement()) {
    const std::string text = text_of(e);
    if (e->GetName() == "signal") {
      s.id = text;
    } else if (e->GetName() == "lamp") {
      LampDesc lamp;
      lamp.colour = attribute(e, "colour");
      lamp.visual = text;
      if (lamp.colour != "red" && lamp.colour != "yellow" && lamp.colour != "green")
        fail("<lamp> '" + text + "': colour '" + lamp.colour +
             "' is not one of red, yellow, green");
      for (const auto& other : s.lamps)
        if (other.colour == lamp.colour) fail("two " + lamp.colour + " lamps");
      for (const auto& link : model.links)
        for (const auto& v : link.visuals)
          if (lamp.link.empty() && v.name == lamp.visual) lamp.link = link.name;
      if (lamp.link.empty()) fail("<lamp> '" + text + "' is no visual of the model's links");
      s.lamps.push_back(lamp);
    }
  }
  if (s.id.empty()) fail("no <signal> id");
  return s;
}

void read_plugins(const sdf::ElementPtr& elem, const std::string& model_name, const fs::path& file,
                  ModelDesc* model) {
  if (!elem->HasElement("plugin")) return;
  for (auto p = elem->GetElement("plugin"); p; p = p->GetNextElement("plugin")) {
    std::string name = attribute(p, "name"), filename = attribute(p, "filename");
    std::string where = "model '" + model_name + "' plugin '" + name + "'";
    if (filename.find("JointController") != std::string::npos) {
      model->joint_plugins.emplace_back(name,
                                        read_joint_controller(p, model_name, file, where, *model));
    } else if (filename.find("ConvoyBrakePlugin") != std::string::npos) {
      model->brake_plugins.push_back(read_brake_plugin(p, name, model_name, file, where, *model));
    } else if (filename == "convoy_class") {
      model->cls = read_class(p, file, where);
    } else if (filename == "convoy_signal") {
      model->signals.push_back(read_signal(p, file, where, *model));
    } else if (filename.find("LinkController") != std::string::npos ||
               filename.find("LinkPlugin") != std::string::npos) {
      model->link_plugins.push_back(name);
    }
  }
}

}  // namespace convoy::world
