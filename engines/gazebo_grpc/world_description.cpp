#include "world_description.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <map>
#include <sdf/sdf.hh>
#include <sstream>
#include <stdexcept>

#include "camera_desc.h"
#include "lidar_desc.h"
#include "nav_desc.h"
#include "radar_desc.h"
#include "sdf_eigen.h"
#include "world_plugins.h"

namespace convoy::world {

namespace fs = std::filesystem;

namespace {

Rgba to_rgba(const ignition::math::Color& c) { return {c.R(), c.G(), c.B(), c.A()}; }

// Root::Load, with what libsdformat throws turned into an error naming the file: it throws
// std::invalid_argument for a bad version attribute (`<sdf version="x1.7">`, through
// ignition::math::SemanticVersion).
sdf::Errors load_sdf(sdf::Root& root, const fs::path& file, const sdf::ParserConfig& config) {
  try {
    return root.Load(file.string(), config);
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": libsdformat cannot read it: " + e.what());
  }
}

std::string format_errors(const sdf::Errors& errors, const fs::path& file) {
  std::ostringstream out;
  for (const auto& e : errors) {
    out << e.FilePath().value_or(file.string());
    if (e.LineNumber()) out << ":" << *e.LineNumber();
    out << ": " << e.Message() << "\n";
  }
  std::string s = out.str();
  if (!s.empty()) s.pop_back();
  return s;
}

std::vector<fs::path> model_paths(const fs::path& world_file) {
  std::vector<fs::path> dirs;
  for (const char* var : {"CONVOY_MODEL_PATH", "GAZEBO_MODEL_PATH", "SDF_PATH"}) {
    const char* v = std::getenv(var);
    if (!v) continue;
    std::stringstream ss(v);
    std::string item;
    while (std::getline(ss, item, ':'))
      if (!item.empty()) dirs.emplace_back(item);
  }
  dirs.push_back(world_file.parent_path());
  dirs.push_back(world_file.parent_path() / "models");
  // Models the build generates (e.g. road meshes from OpenDRIVE): <bin>/../share/convoy/models
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path().parent_path() / "share" / "convoy" / "models");
  return dirs;
}

// Resolves model://name/rest, file://, absolute and relative (to `base_dir`) URIs.
fs::path resolve_uri(const std::string& uri, const fs::path& base_dir,
                     const std::vector<fs::path>& paths) {
  const std::string model = "model://", file = "file://";
  if (uri.rfind(model, 0) == 0) {
    std::string rest = uri.substr(model.size());
    for (const auto& dir : paths) {
      if (fs::exists(dir / rest)) return fs::absolute(dir / rest);
    }
    return {};
  }
  std::string p = uri.rfind(file, 0) == 0 ? uri.substr(file.size()) : uri;
  fs::path path(p);
  if (path.is_relative()) path = base_dir / path;
  return fs::exists(path) ? fs::absolute(path) : fs::path{};
}

// A <max_contacts> value (0 and more; 0 keeps every contact, as no bound).
int checked_max_contacts(const fs::path& file, int value, const std::string& where) {
  if (value < 0) {
    throw std::runtime_error(file.string() + ": " + where + ": <max_contacts> is " +
                             std::to_string(value) + "; it must be 0 or more");
  }
  return value;
}

// Gazebo's stock script materials, for worlds that use them.
bool script_colour(const std::string& name, Rgba* out) {
  static const std::map<std::string, Rgba> colours = {
      {"Gazebo/White", {1, 1, 1, 1}},
      {"Gazebo/Black", {0.05f, 0.05f, 0.05f, 1}},
      {"Gazebo/Grey", {0.7f, 0.7f, 0.7f, 1}},
      {"Gazebo/DarkGrey", {0.35f, 0.35f, 0.35f, 1}},
      {"Gazebo/Red", {1, 0, 0, 1}},
      {"Gazebo/Green", {0, 1, 0, 1}},
      {"Gazebo/Blue", {0, 0, 1, 1}},
      {"Gazebo/Yellow", {1, 1, 0, 1}},
      {"Gazebo/Orange", {1, 0.5f, 0.05f, 1}},
      {"Gazebo/Purple", {1, 0, 1, 1}},
      {"Gazebo/Turquoise", {0, 1, 1, 1}},
      {"Gazebo/Wood", {0.6f, 0.4f, 0.2f, 1}},
      {"Gazebo/Asphalt", {0.2f, 0.2f, 0.2f, 1}},
      {"Gazebo/Road", {0.25f, 0.25f, 0.25f, 1}},
  };
  auto it = colours.find(name);
  if (it == colours.end()) return false;
  *out = it->second;
  return true;
}

class Loader {
 public:
  explicit Loader(const fs::path& file) : file_(file), paths_(model_paths(file)) {}

  Shape shape(const sdf::Geometry* g, const std::string& where) {
    Shape s;
    switch (g->Type()) {
      case sdf::GeometryType::BOX:
        s.kind = Shape::kBox;
        s.size = to_eigen(g->BoxShape()->Size());
        break;
      case sdf::GeometryType::CYLINDER:
        s.kind = Shape::kCylinder;
        s.size = {g->CylinderShape()->Radius(), g->CylinderShape()->Radius(),
                  g->CylinderShape()->Length()};
        break;
      case sdf::GeometryType::SPHERE:
        s.kind = Shape::kSphere;
        s.size = Eigen::Vector3d::Constant(g->SphereShape()->Radius());
        break;
      case sdf::GeometryType::PLANE:
        s.kind = Shape::kPlane;
        s.size = {g->PlaneShape()->Size().X(), g->PlaneShape()->Size().Y(), 0};
        s.normal = to_eigen(g->PlaneShape()->Normal()).normalized();
        break;
      case sdf::GeometryType::MESH: {
        s.kind = Shape::kMesh;
        const sdf::Mesh* m = g->MeshShape();
        fs::path base =
            m->FilePath().empty() ? file_.parent_path() : fs::path(m->FilePath()).parent_path();
        s.mesh = resolve_uri(m->Uri(), base, paths_);
        if (s.mesh.empty()) {
          throw std::runtime_error(file_.string() + ": " + where + ": mesh '" + m->Uri() +
                                   "' not found (model path: $CONVOY_MODEL_PATH, "
                                   "$GAZEBO_MODEL_PATH, $SDF_PATH)");
        }
        s.scale = to_eigen(m->Scale());
        break;
      }
      case sdf::GeometryType::HEIGHTMAP: {
        s.kind = Shape::kHeightmap;
        const sdf::Heightmap* h = g->HeightmapShape();
        fs::path base =
            h->FilePath().empty() ? file_.parent_path() : fs::path(h->FilePath()).parent_path();
        s.mesh = resolve_uri(h->Uri(), base, paths_);
        if (s.mesh.empty()) {
          throw std::runtime_error(file_.string() + ": " + where + ": heightmap '" + h->Uri() +
                                   "' not found");
        }
        s.size = to_eigen(h->Size());
        s.position = to_eigen(h->Position());
        break;
      }
      default:
        throw std::runtime_error(file_.string() + ": " + where +
                                 ": unsupported geometry (box, cylinder, sphere, plane, mesh and "
                                 "heightmap are)");
    }
    return s;
  }

  Material material(const sdf::Material* m, const std::string& where) {
    Material out;
    if (!m) return out;
    out.has_material = true;
    out.ambient = to_rgba(m->Ambient());
    out.diffuse = to_rgba(m->Diffuse());
    out.specular = to_rgba(m->Specular());
    out.emissive = to_rgba(m->Emissive());
    Rgba c;
    if (!m->ScriptName().empty() && script_colour(m->ScriptName(), &c)) {
      out.diffuse = c;
      out.ambient = c;
    }
    if (const sdf::Pbr* pbr = m->PbrMaterial()) {
      for (auto type : {sdf::PbrWorkflowType::METAL, sdf::PbrWorkflowType::SPECULAR}) {
        const sdf::PbrWorkflow* wf = pbr->Workflow(type);
        if (wf && !wf->AlbedoMap().empty()) {
          out.texture = resolve_uri(wf->AlbedoMap(), fs::path(m->FilePath()).parent_path(), paths_);
          if (out.texture.empty()) {
            throw std::runtime_error(file_.string() + ": " + where + ": texture '" +
                                     wf->AlbedoMap() + "' not found");
          }
        }
      }
    }
    return out;
  }

  // A link of the model `model_name`, its pose in the world (the model at `model_world`).
  LinkDesc link(const sdf::Link* l, const Eigen::Isometry3d& model_world,
                const std::string& model_name) {
    LinkDesc ld;
    ld.short_name = l->Name();
    ld.name = model_name + "::" + l->Name();
    std::string where = "link '" + ld.name + "'";
    ignition::math::Pose3d pose;
    auto errors = l->SemanticPose().Resolve(pose);
    if (!errors.empty()) throw std::runtime_error(format_errors(errors, file_));
    ld.pose = model_world * to_eigen(pose);
    const auto& inertial = l->Inertial();
    ld.mass = inertial.MassMatrix().Mass();
    if (!(ld.mass > 0)) {
      throw std::runtime_error(file_.string() + ": " + where + ": mass must be > 0");
    }
    Eigen::Isometry3d inertial_pose = to_eigen(inertial.Pose());
    ld.com = inertial_pose.translation();
    const auto& moi = inertial.MassMatrix().Moi();
    Eigen::Matrix3d I;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) I(r, c) = moi(r, c);
    ld.inertia = inertial_pose.linear() * I * inertial_pose.linear().transpose();
    if (auto e = l->Element(); e && e->HasElement("gravity")) ld.gravity = e->Get<bool>("gravity");
    for (uint64_t c = 0; c < l->CollisionCount(); ++c)
      ld.collisions.push_back(collision(l->CollisionByIndex(c), where));
    for (uint64_t v = 0; v < l->VisualCount(); ++v)
      ld.visuals.push_back(visual(l->VisualByIndex(v), where));
    for (uint64_t s = 0; s < l->SensorCount(); ++s) {
      const sdf::Sensor* sensor = l->SensorByIndex(s);
      if (is_lidar_sensor(sensor))
        ld.lidars.push_back(lidar_desc(sensor, model_name, l->Name(), file_));
      if (is_nav_sensor(sensor))
        ld.nav_sensors.push_back(nav_desc(sensor, model_name, l->Name(), file_));
      if (is_radar_sensor(sensor))
        ld.radars.push_back(radar_desc(sensor, model_name, l->Name(), file_));
      if (is_odometry_sensor(sensor))
        ld.odometers.push_back(odometry_desc(sensor, model_name, l->Name(), file_));
      if (!is_camera_sensor(sensor)) continue;
      ld.cameras.push_back(camera_desc(sensor, model_name, l->Name(), file_));
    }
    return ld;
  }

  // A collision of the link `where` ("link '<model>::<link>'").
  CollisionDesc collision(const sdf::Collision* col, const std::string& where) {
    CollisionDesc cd;
    cd.name = col->Name();
    ignition::math::Pose3d cp;
    col->SemanticPose().Resolve(cp);
    cd.pose = to_eigen(cp);
    cd.shape = shape(col->Geom(), where + " collision '" + col->Name() + "'");
    if (auto e = col->Element()) {
      auto s = e->FindElement("surface");
      auto f = s ? s->FindElement("friction") : nullptr;
      auto o = f ? f->FindElement("ode") : nullptr;
      if (o && o->HasElement("mu")) cd.mu = o->Get<double>("mu");
      if (e->HasElement("max_contacts"))
        cd.max_contacts = checked_max_contacts(file_, e->Get<int>("max_contacts"),
                                               where + " collision '" + col->Name() + "'");
    }
    return cd;
  }

  // A visual of the link `where`.
  VisualDesc visual(const sdf::Visual* vis, const std::string& where) {
    VisualDesc vd;
    vd.name = vis->Name();
    ignition::math::Pose3d vp;
    vis->SemanticPose().Resolve(vp);
    vd.pose = to_eigen(vp);
    vd.shape = shape(vis->Geom(), where + " visual '" + vis->Name() + "'");
    vd.material = material(vis->Material(), where + " visual '" + vis->Name() + "'");
    vd.cast_shadows = vis->CastShadows();
    return vd;
  }

  // A camera sensor of the link named `link_name` (scoped).
  JointDesc::Type joint_type(const sdf::Joint* j, const std::string& where) {
    switch (j->Type()) {
      case sdf::JointType::REVOLUTE:
        return JointDesc::kRevolute;
      case sdf::JointType::CONTINUOUS:
        return JointDesc::kContinuous;
      case sdf::JointType::PRISMATIC:
        return JointDesc::kPrismatic;
      case sdf::JointType::FIXED:
        return JointDesc::kFixed;
      case sdf::JointType::BALL:
        return JointDesc::kBall;
      case sdf::JointType::UNIVERSAL:
        return JointDesc::kUniversal;
      default:
        throw std::runtime_error(file_.string() + ": " + where + ": unsupported joint type");
    }
  }

  // A joint of the model `model_name` (at `model_world`), its pose in the world.
  JointDesc joint(const sdf::Joint* j, const Eigen::Isometry3d& model_world,
                  const std::string& model_name) {
    JointDesc jd;
    jd.short_name = j->Name();
    jd.name = model_name + "::" + j->Name();
    jd.type = joint_type(j, "joint '" + jd.name + "'");
    auto scoped = [&](const std::string& link) {
      return link == "world" ? link : model_name + "::" + link;
    };
    jd.parent = scoped(j->ParentLinkName());
    jd.child = scoped(j->ChildLinkName());
    ignition::math::Pose3d jp;
    auto errors = j->SemanticPose().Resolve(jp, "__model__");
    if (!errors.empty()) throw std::runtime_error(format_errors(errors, file_));
    jd.pose = model_world * to_eigen(jp);
    for (unsigned a = 0; a < 2; ++a) {
      const sdf::JointAxis* axis = j->Axis(a);
      if (!axis) continue;
      AxisDesc ad;
      ignition::math::Vector3d xyz;
      auto axis_errors = axis->ResolveXyz(xyz, "__model__");
      if (!axis_errors.empty()) throw std::runtime_error(format_errors(axis_errors, file_));
      // model frame -> joint frame
      Eigen::Matrix3d r_model_joint = to_eigen(jp).linear();
      ad.xyz = (r_model_joint.transpose() * to_eigen(xyz)).normalized();
      ad.lower = axis->Lower();
      ad.upper = axis->Upper();
      ad.damping = axis->Damping();
      ad.friction = axis->Friction();
      ad.effort = axis->Effort();
      ad.velocity = axis->MaxVelocity();
      jd.axes.push_back(ad);
    }
    return jd;
  }

  // The model `m` as `name` at `model_world`, then its nested models.
  void model(const sdf::Model* m, const Eigen::Isometry3d& model_world, const std::string& name,
             WorldDesc* world) {
    ModelDesc md;
    md.name = name;
    md.is_static = m->Static();
    if (auto e = m->Element(); e && !e->FilePath().empty()) md.source = fs::absolute(e->FilePath());
    for (uint64_t i = 0; i < m->LinkCount(); ++i)
      md.links.push_back(link(m->LinkByIndex(i), model_world, name));
    for (uint64_t i = 0; i < m->JointCount(); ++i)
      md.joints.push_back(joint(m->JointByIndex(i), model_world, name));
    read_plugins(m->Element(), name, file_, &md);
    world->models.push_back(std::move(md));
    for (uint64_t i = 0; i < m->ModelCount(); ++i) {
      const sdf::Model* nested = m->ModelByIndex(i);
      ignition::math::Pose3d np;
      nested->SemanticPose().Resolve(np);
      model(nested, model_world * to_eigen(np), name + "::" + nested->Name(), world);
    }
  }

  sdf::ParserConfig config() const {
    sdf::ParserConfig cfg;
    auto paths = paths_;
    // Only a find callback: sdformat's own URI path list stops at the first folder, even
    // when the model is not in it.
    cfg.SetFindCallback([paths](const std::string& uri) -> std::string {
      const std::string scheme = "model://";
      std::string rest = uri.rfind(scheme, 0) == 0 ? uri.substr(scheme.size()) : uri;
      for (const auto& dir : paths) {
        if (fs::exists(dir / rest)) return (dir / rest).string();
      }
      return "";
    });
    return cfg;
  }

  const fs::path& file() const { return file_; }

 private:
  fs::path file_;
  std::vector<fs::path> paths_;
};

}  // namespace

std::vector<ModelDesc> load_model(const fs::path& file, const std::string& name,
                                  const Eigen::Isometry3d& pose) {
  fs::path mf = fs::absolute(file);
  if (!fs::exists(mf)) throw std::runtime_error(mf.string() + ": model file not found");
  Loader model_loader(mf);
  sdf::Root mroot;
  auto merrors = load_sdf(mroot, mf, model_loader.config());
  if (!merrors.empty()) throw std::runtime_error(format_errors(merrors, mf));
  if (!mroot.Model()) throw std::runtime_error(mf.string() + ": no <model> in the file");
  WorldDesc w;
  model_loader.model(mroot.Model(), pose, name.empty() ? mroot.Model()->Name() : name, &w);
  return std::move(w.models);
}

WorldDesc load_world(const fs::path& file_in, const std::vector<ModelInsert>& extra) {
  fs::path file = fs::absolute(file_in);
  if (!fs::exists(file)) throw std::runtime_error(file.string() + ": world file not found");
  Loader loader(file);
  sdf::Root root;
  sdf::Errors errors = load_sdf(root, file, loader.config());
  if (!errors.empty()) throw std::runtime_error(format_errors(errors, file));
  if (root.WorldCount() == 0) throw std::runtime_error(file.string() + ": no <world> in the file");
  const sdf::World* w = root.WorldByIndex(0);
  WorldDesc world;
  world.file = file;
  world.name = w->Name();
  world.gravity = to_eigen(w->Gravity());
  world.geo = geo_origin(w, file);
  if (w->PhysicsCount() > 0) {
    const sdf::Physics* physics = w->PhysicsByIndex(0);
    world.max_step_size = physics->MaxStepSize();
    if (physics->Element() && physics->Element()->HasElement("max_contacts"))
      world.max_contacts =
          checked_max_contacts(file, physics->Element()->Get<int>("max_contacts"), "<physics>");
  }
  if (const sdf::Scene* scene = w->Scene()) {
    world.ambient = to_rgba(scene->Ambient());
    world.background = to_rgba(scene->Background());
    world.shadows = scene->Shadows();
  }
  if (auto e = w->Element(); e && e->HasElement("plugin")) {
    for (auto p = e->GetElement("plugin"); p; p = p->GetNextElement("plugin")) {
      auto fn = p->GetAttribute("filename");
      std::string f = fn ? fn->GetAsString() : "";
      if (f.find("WorldPlugin") != std::string::npos ||
          f.find("CommunicationPlugin") != std::string::npos)
        world.world_plugin = true;
    }
  }
  for (uint64_t i = 0; i < w->LightCount(); ++i) {
    const sdf::Light* l = w->LightByIndex(i);
    LightDesc ld;
    ld.name = l->Name();
    ld.type = l->Type() == sdf::LightType::POINT  ? LightDesc::kPoint
              : l->Type() == sdf::LightType::SPOT ? LightDesc::kSpot
                                                  : LightDesc::kDirectional;
    ignition::math::Pose3d lp;
    l->SemanticPose().Resolve(lp);
    Eigen::Isometry3d pose = to_eigen(lp);
    ld.position = pose.translation();
    ld.direction = (pose.linear() * to_eigen(l->Direction())).normalized();
    ld.diffuse = to_rgba(l->Diffuse());
    ld.specular = to_rgba(l->Specular());
    ld.range = l->AttenuationRange();
    ld.constant = l->ConstantAttenuationFactor();
    ld.linear = l->LinearAttenuationFactor();
    ld.quadratic = l->QuadraticAttenuationFactor();
    world.lights.push_back(ld);
  }
  for (uint64_t i = 0; i < w->ModelCount(); ++i) {
    const sdf::Model* m = w->ModelByIndex(i);
    ignition::math::Pose3d mp;
    m->SemanticPose().Resolve(mp);
    loader.model(m, to_eigen(mp), m->Name(), &world);
  }
  for (const auto& insert : extra) {
    for (auto& m : load_model(insert.file, insert.name, insert.pose))
      world.models.push_back(std::move(m));
  }
  return world;
}

}  // namespace convoy::world
