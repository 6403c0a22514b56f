// Writes the generated seed corpora with the project's own writers:
//   fuzz_make_seeds SEED_DIR CONFIG.json...
// <SEED_DIR>/config: each config followed by `-o` overrides; datapack and python_codec:
// MessagePack of the configs and of numpy arrays (inline and in a blob), camera messages;
// proto: engine Requests / Replies / DataPacks carrying them, blobs inline and in shared memory.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "convoy/datapacks.pb.h"
#include "datapack/camera.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "fuzz_input.h"

namespace fs = std::filesystem;
using namespace convoy;

namespace {

void write(const fs::path& dir, const std::string& name, const std::string& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
}

std::string read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> blobs_of(const engine::DataPack& dp) {
  std::vector<std::string> out;
  for (const auto& b : dp.blobs()) out.push_back(b.inline_());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: fuzz_make_seeds SEED_DIR CONFIG.json...\n";
    return 2;
  }
  const fs::path dir = argv[1];
  std::vector<engine::DataPack> datapacks;
  datapack::InlineBlobWriter inline_writer;

  for (int i = 2; i < argc; ++i) {
    const std::string text = read(argv[i]);
    const std::string n = std::to_string(i - 2);
    write(dir / "config", "overrides_" + n,
          text + '\0' + "SimulationTimeout=2" + '\0' + "EngineConfigs/0/EngineTimestep=0.05" +
              '\0' + "EngineConfigs.0.EngineName=\"x\"");
    engine::DataPack dp;
    dp.mutable_id()->set_name("config_" + n);
    datapack::Builder b(&dp, inline_writer);
    datapack::write_json(b, nlohmann::json::parse(text));
    datapacks.push_back(dp);
  }

  {  // numpy arrays: a small one inline, a blob-sized one in a blob
    engine::DataPack dp;
    dp.mutable_id()->set_name("arrays");
    datapack::Builder b(&dp, inline_writer);
    const uint64_t small_shape[] = {2, 3};
    const std::string small(2 * 3 * 4, '\1');
    const uint64_t big_shape[] = {200, 200};
    const std::string big(200 * 200, '\2');
    nlohmann::json v = {{"small", datapack::ndarray_json(b, "<f4", small_shape, small)},
                        {"big", datapack::ndarray_json(b, "|u1", big_shape, big)},
                        {"list", {1, 2.5, "x", nullptr, true}}};
    datapack::write_json(b, v);
    datapacks.push_back(dp);
  }
  {  // camera frames: inline pixels, and pixels in a blob
    engine::DataPack dp;
    dp.mutable_id()->set_name("camera_small");
    datapack::Builder b(&dp, inline_writer);
    datapack::write_camera(b, 8, 6, 3, std::string(8 * 6 * 3, '\3'));
    datapacks.push_back(dp);
    engine::DataPack big;
    big.mutable_id()->set_name("camera_blob");
    datapack::Builder bb(&big, inline_writer);
    datapack::write_camera(bb, 120, 100, 3, std::string(120 * 100 * 3, '\4'));
    datapacks.push_back(big);
  }

  int k = 0;
  for (const auto& dp : datapacks) {
    const std::string name = dp.id().name();
    if (dp.has_json_msgpack()) {
      const std::string seed = fuzz::join_blobs(blobs_of(dp), dp.json_msgpack());
      write(dir / "datapack", name, seed);
      write(dir / "python_codec", name, seed);
    } else if (dp.has_proto()) {
      write(dir / "datapack", name, fuzz::join_blobs(blobs_of(dp), dp.proto().data()));
    }
    write(dir / "proto", "datapack_" + name, dp.SerializeAsString());
    ++k;
  }

  engine::Request step;
  for (const auto& dp : datapacks) *step.mutable_step()->add_inputs() = dp;
  step.mutable_step()->set_duration_ns(20'000'000);
  write(dir / "proto", "request_step", step.SerializeAsString());

  engine::Reply reply;
  reply.mutable_step()->set_time_ns(20'000'000);
  for (const auto& dp : datapacks) *reply.mutable_step()->add_outputs() = dp;
  // A frame in the sender's shared memory, as ShmBlobWriter describes it.
  engine::DataPack shm = datapacks.back();
  shm.mutable_id()->set_name("camera_shm");
  auto* blob = shm.mutable_blobs(0);
  blob->clear_inline_();
  blob->set_in_shm(true);
  blob->set_shm_offset(64);
  blob->set_size(1024);
  *reply.mutable_step()->add_outputs() = shm;
  write(dir / "proto", "reply_step", reply.SerializeAsString());
  write(dir / "proto", "datapack_camera_shm", shm.SerializeAsString());

  engine::Reply get;
  for (const auto& dp : datapacks) *get.mutable_get_datapacks()->add_datapacks() = dp;
  write(dir / "proto", "reply_get", get.SerializeAsString());
  std::cout << "seeds for " << k << " datapacks in " << dir << "\n";
  return 0;
}
