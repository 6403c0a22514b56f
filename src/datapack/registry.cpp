#include "datapack/registry.h"

#include <google/protobuf/compiler/importer.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>

#include <cctype>
#include <functional>
#include <set>
#include <stdexcept>

namespace convoy::datapack {

namespace pb = google::protobuf;

namespace {
class ImportErrors final : public pb::compiler::MultiFileErrorCollector {
 public:
  void AddError(const std::string& file, int line, int column,
                const std::string& message) override {
    if (!text.empty()) text += "\n";
    text +=
        file + ":" + std::to_string(line + 1) + ":" + std::to_string(column + 1) + ": " + message;
  }
  std::string text;
};
}  // namespace

// .proto files read at run time, and the dynamic messages of their types.
struct Registry::Imported {
  pb::compiler::DiskSourceTree tree;
  ImportErrors errors;
  pb::compiler::Importer importer{&tree, &errors};
  pb::DynamicMessageFactory factory{importer.pool()};
  std::set<std::string> mapped;
};

Registry::Registry() = default;
Registry::~Registry() = default;

Registry& Registry::global() {
  static Registry* r = [] {
    auto* reg = new Registry;
    register_standard_types(*reg);
    return reg;
  }();
  return *r;
}

std::string Registry::default_python_class(const pb::Descriptor* d) {
  std::string out;
  bool upper = true;
  for (char c : d->file()->package()) {
    if (c == '.' || c == '_') {
      upper = true;
      continue;
    }
    out += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    upper = false;
  }
  return out + d->name() + "DataPack";
}

const TypeInfo& Registry::add(const pb::Descriptor* descriptor, const pb::Message* prototype,
                              std::string python_class) {
  std::lock_guard lock(mutex_);
  auto& slot = types_[descriptor->full_name()];
  if (!slot) slot = std::make_unique<TypeInfo>();
  slot->name = descriptor->full_name();
  slot->named_class = !python_class.empty();
  slot->python_class = python_class.empty() ? default_python_class(descriptor) : python_class;
  slot->descriptor = descriptor;
  slot->prototype = prototype;
  return *slot;
}

const TypeInfo& Registry::add_by_name(const std::string& full_name) {
  if (const TypeInfo* t = find(full_name)) return *t;
  if (const pb::Descriptor* d =
          pb::DescriptorPool::generated_pool()->FindMessageTypeByName(full_name))
    return add(d, pb::MessageFactory::generated_factory()->GetPrototype(d));
  if (imported_) {
    if (const pb::Descriptor* d = imported_->importer.pool()->FindMessageTypeByName(full_name))
      return add(d, imported_->factory.GetPrototype(d));
  }
  throw std::invalid_argument("no protobuf message type '" + full_name +
                              "' is compiled into Convoy or imported from a .proto file");
}

void Registry::import_proto(const std::filesystem::path& file,
                            const std::vector<std::filesystem::path>& include_dirs) {
  std::lock_guard lock(mutex_);
  if (!imported_) imported_ = std::make_unique<Imported>();
  auto& im = *imported_;
  const std::filesystem::path dir = std::filesystem::absolute(file).parent_path();
  for (const auto& p : include_dirs) {
    if (im.mapped.insert(p.string()).second) im.tree.MapPath("", p.string());
  }
  if (im.mapped.insert(dir.string()).second) im.tree.MapPath("", dir.string());
  im.errors.text.clear();
  const pb::FileDescriptor* fd = im.importer.Import(file.filename().string());
  if (!fd) {
    throw std::invalid_argument(
        file.string() + ": cannot read protobuf definitions" +
        (im.errors.text.empty() ? std::string(" (no such file?)") : ":\n" + im.errors.text));
  }
  std::function<void(const pb::Descriptor*)> add_message = [&](const pb::Descriptor* d) {
    auto& slot = types_[d->full_name()];
    if (!slot) {
      slot = std::make_unique<TypeInfo>();
      slot->name = d->full_name();
      slot->python_class = default_python_class(d);
      slot->descriptor = d;
      slot->prototype = im.factory.GetPrototype(d);
    }
    for (int i = 0; i < d->nested_type_count(); ++i) add_message(d->nested_type(i));
  };
  for (int i = 0; i < fd->message_type_count(); ++i) add_message(fd->message_type(i));
}

const TypeInfo* Registry::find(std::string_view name) const {
  std::lock_guard lock(mutex_);
  auto it = types_.find(std::string(name));
  return it == types_.end() ? nullptr : it->second.get();
}

const TypeInfo& Registry::require(std::string_view name) const {
  if (const TypeInfo* t = find(name)) return *t;
  throw std::invalid_argument("protobuf datapack type '" + std::string(name) +
                              "' is not registered (see src/datapack/registry.h)");
}

std::vector<const TypeInfo*> Registry::all() const {
  std::lock_guard lock(mutex_);
  std::vector<const TypeInfo*> out;
  for (const auto& [name, t] : types_) out.push_back(t.get());
  return out;
}

std::string Registry::file_descriptor_set(std::string_view name) const {
  const TypeInfo& t = require(name);
  pb::FileDescriptorSet set;
  std::set<std::string> done;
  std::function<void(const pb::FileDescriptor*)> visit = [&](const pb::FileDescriptor* f) {
    if (!done.insert(f->name()).second) return;
    for (int i = 0; i < f->dependency_count(); ++i) visit(f->dependency(i));
    f->CopyTo(set.add_file());
  };
  visit(t.descriptor->file());
  return set.SerializeAsString();
}

}  // namespace convoy::datapack
