// Helpers for the world systems' tests: a WorldSystems (world_systems.h) on a world from
// tests/world/data or from SDF text, and datapacks in and out of it as the engine server
// moves them.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "datapack/json.h"
#include "datapack/proto.h"
#include "world_description.h"
#include "world_systems.h"

namespace convoy::world::testing {

inline std::string data_file(const std::string& name) {
  return std::string(CONVOY_TEST_DATA_DIR) + "/" + name;
}

// A world file written from SDF text into a fresh temporary folder (removed at exit).
inline std::filesystem::path write_world(const std::string& sdf) {
  struct Folders {
    std::vector<std::filesystem::path> made;
    ~Folders() {
      std::error_code ec;
      for (const auto& f : made) std::filesystem::remove_all(f, ec);
    }
  };
  static Folders folders;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("convoy-systems-test-" + std::string(info->test_suite_name()) + "-" + info->name() + "-" +
       std::to_string(::getpid()) + "-" + std::to_string(folders.made.size()));
  std::filesystem::create_directories(dir);
  folders.made.push_back(dir);
  const auto file = dir / "world.sdf";
  std::ofstream(file) << sdf;
  return file;
}

// A world of `file` run by an engine named "test".
inline std::unique_ptr<WorldSystems> make_world(const std::filesystem::path& file) {
  return std::make_unique<WorldSystems>(load_world(file), /*seed=*/0, "test");
}

// A datapack as a function sends it.
class Sent {
 public:
  explicit Sent(const std::string& name) { dp_.mutable_id()->set_name(name); }
  Sent& json(const nlohmann::json& value) {
    datapack::write_json(builder_, value);
    return *this;
  }
  Sent& proto(const google::protobuf::Message& m) {
    datapack::write_proto(builder_, m);
    return *this;
  }
  datapack::View view() const { return datapack::View(dp_, datapack::inline_blob_reader()); }

 private:
  engine::DataPack dp_;
  datapack::InlineBlobWriter blobs_;
  datapack::Builder builder_{&dp_, blobs_};
};

inline void send_json(WorldSystems& w, const std::string& name, const nlohmann::json& value) {
  Sent dp(name);
  w.set_datapack(dp.json(value).view());
}

inline void send_proto(WorldSystems& w, const std::string& name,
                       const google::protobuf::Message& m) {
  Sent dp(name);
  w.set_datapack(dp.proto(m).view());
}

// The datapack `name` the world gives; its payload unset if none.
class Got {
 public:
  Got(WorldSystems& w, const std::string& name) {
    dp_.mutable_id()->set_name(name);
    datapack::Builder out(&dp_, blobs_);
    w.get_datapack(name, out);
  }
  bool empty() const { return view().empty(); }
  nlohmann::json json() const { return datapack::read_json(view()); }
  template <typename M>
  M proto() const {
    return datapack::read_proto<M>(view());
  }
  datapack::View view() const { return datapack::View(dp_, datapack::inline_blob_reader()); }

 private:
  engine::DataPack dp_;
  datapack::InlineBlobWriter blobs_;
};

// The names of the datapacks provided.
inline std::vector<std::string> names(const std::vector<ProvidedDataPack>& provided) {
  std::vector<std::string> out;
  for (const auto& p : provided) out.push_back(p.name);
  return out;
}

// The message of the exception `f` throws ("" if none).
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

constexpr int64_t kMs = 1'000'000;

}  // namespace convoy::world::testing
