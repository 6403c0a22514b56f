// The datapack library: numpy headers, JSON and camera codecs over inline and shared-memory
// blobs (reading in place, writing in place), the copy counter, and the type registry.
#include <google/protobuf/descriptor.pb.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "convoy/datapacks.pb.h"
#include "datapack/camera.h"
#include "datapack/json.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "transport/blobs.h"

namespace convoy::datapack {
namespace {

View in(const engine::DataPack& dp) { return {dp, inline_blob_reader()}; }

uint64_t copies() { return large_copies().copies.load(); }

TEST(Ndarray, HeaderRoundTripsAndRejectsTruncation) {
  std::string body;
  const uint64_t shape[3] = {480, 736, 3};
  append_ndarray_header(&body, "|u1", shape);
  append_blob_index(&body, 7);
  NdarrayHeader h;
  std::string_view rest = parse_ndarray_header(body, &h);
  EXPECT_EQ(h.dtype, "|u1");
  EXPECT_EQ(h.shape, (std::vector<uint64_t>{480, 736, 3}));
  EXPECT_EQ(h.count(), 480u * 736 * 3);
  EXPECT_EQ(parse_blob_index(rest), 7u);
  for (size_t n = 0; n < body.size() - 4; ++n)
    EXPECT_THROW(parse_ndarray_header(std::string_view(body).substr(0, n), &h), std::runtime_error)
        << n;
  EXPECT_THROW(parse_blob_index("abc"), std::runtime_error);
  EXPECT_EQ(dtype_size("<f4"), 4u);
  EXPECT_EQ(dtype_size("|u1"), 1u);
  EXPECT_EQ(dtype_size("<U8"), 32u);
  EXPECT_EQ(dtype_size("|b1"), 1u);
  EXPECT_EQ(dtype_size("<c16"), 16u);
  for (const char* not_plain : {"|O8", "|O", "|V8", "<M8", "", "<f", "<f0", "xf4", "<f4x"})
    EXPECT_EQ(dtype_size(not_plain), 0u) << not_plain;
  NdarrayHeader forged{"<f8", {uint64_t{1} << 62, 1u << 4}};
  EXPECT_EQ(forged.count(), UINT64_MAX);
  EXPECT_TRUE(is_uint8("|u1"));
  EXPECT_FALSE(is_uint8("<f4"));
}

TEST(Json, ArraysGoInlineWhenSmallAndToABlobWhenLarge) {
  InlineBlobWriter writer;
  engine::DataPack dp;
  dp.mutable_id()->set_name("depth");
  Builder out(&dp, writer);
  std::vector<float> small(4, 1.5f), large(kLargeBlobBytes / 4, 2.5f);
  const uint64_t s1[1] = {small.size()}, s2[1] = {large.size()};
  write_json(out, {{"a", ndarray_json(out, "<f4", s1, {reinterpret_cast<char*>(small.data()), 16})},
                   {"b", ndarray_json(out, "<f4", s2,
                                      {reinterpret_cast<char*>(large.data()), large.size() * 4})},
                   {"n", 3}});
  EXPECT_EQ(dp.id().type(), "json");
  ASSERT_EQ(dp.blobs_size(), 1);  // only the large one
  const nlohmann::json j = read_json(in(dp));
  EXPECT_EQ(j["n"], 3);
  const NdarrayRef a = read_ndarray(in(dp), j["a"]);
  const NdarrayRef b = read_ndarray(in(dp), j["b"]);
  EXPECT_EQ(a.header.dtype, "<f4");
  ASSERT_EQ(a.data.size(), 16u);
  ASSERT_EQ(b.data.size(), large.size() * 4);
  float v;
  std::memcpy(&v, b.data.data() + 400, 4);
  EXPECT_EQ(v, 2.5f);
  EXPECT_THROW(read_ndarray(in(dp), j["n"]), std::runtime_error);
}

TEST(Json, MalformedAndWrongPayloadsNameTheDatapack) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("x");
  dp.mutable_id()->set_engine_name("e");
  dp.set_json_msgpack("\xc1");  // never used in MessagePack
  try {
    read_json(in(dp));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("datapack 'x' of engine 'e'"), std::string::npos)
        << e.what();
  }
  data::Joint joint;
  InlineBlobWriter writer;
  Builder out(&dp, writer);
  write_proto(out, joint);
  EXPECT_THROW(read_json(in(dp)), std::runtime_error);
  try {
    read_proto<data::Link>(in(dp));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("holds protobuf type convoy.data.Joint, not "
                                         "convoy.data.Link"),
              std::string::npos)
        << e.what();
  }
}

// Found by fuzz/datapack: 10,000 nested one-item arrays (10 KB) overflowed the stack in
// nlohmann's MessagePack reader. Nesting up to kMaxJsonDepth levels still reads.
TEST(Json, DeepNestingIsRefusedNotOverflowingTheStack) {
  engine::DataPack dp;
  dp.mutable_id()->set_name("deep");
  dp.set_json_msgpack(std::string(100'000, '\x91') + '\xc0');
  try {
    read_json(in(dp));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("datapack 'deep': MessagePack nested deeper than 200"),
              std::string::npos)
        << e.what();
  }
  dp.set_json_msgpack(std::string(kMaxJsonDepth, '\x91') + '\xc0');
  nlohmann::json j = read_json(in(dp));
  for (int i = 0; i < kMaxJsonDepth; ++i) j = nlohmann::json(j.at(0));
  EXPECT_TRUE(j.is_null());
  dp.set_json_msgpack(std::string(kMaxJsonDepth + 1, '\x91') + '\xc0');
  EXPECT_THROW(read_json(in(dp)), std::runtime_error);
  dp.set_json_msgpack("\x92\x01");  // truncated
  EXPECT_THROW(read_json(in(dp)), std::runtime_error);
}

// A frame written into a shared-memory arena is filled in place and read in place: the only
// copy is the writer's own fill.
TEST(Camera, LargeFramesAreWrittenAndReadInPlaceInSharedMemory) {
  transport::ShmArena arena;
  arena.create("datapack_test", 8 << 20);
  transport::ShmBlobWriter writer(arena);
  transport::ShmBlobReader reader(&arena);
  engine::DataPack dp;
  dp.mutable_id()->set_name("camera");
  Builder out(&dp, writer);
  writer.next_message();
  const uint64_t before = copies();
  uint8_t* filled = nullptr;
  write_camera(out, 480, 736, 3, [&](std::span<uint8_t> dst) {
    ASSERT_EQ(dst.size(), 480u * 736 * 3);
    filled = dst.data();
    for (size_t i = 0; i < dst.size(); ++i) dst[i] = static_cast<uint8_t>(i % 251);
  });
  EXPECT_EQ(copies(), before);  // reserve + fill: no copy by the library
  ASSERT_TRUE(filled >= reinterpret_cast<uint8_t*>(arena.data()) &&
              filled < reinterpret_cast<uint8_t*>(arena.data()) + arena.size());
  EXPECT_EQ(dp.id().type(), "convoy.data.Camera");
  const CameraImage img = read_camera(View(dp, reader));
  EXPECT_EQ(img.width, 736u);
  EXPECT_EQ(img.height, 480u);
  EXPECT_EQ(img.depth, 3u);
  EXPECT_TRUE(img.in_shm);
  EXPECT_EQ(reinterpret_cast<const uint8_t*>(img.pixels.data()), filled);  // in place
  EXPECT_EQ(static_cast<uint8_t>(img.pixels[1000]), 1000 % 251);

  // Existing pixels are copied once, and counted.
  engine::DataPack dp2;
  Builder out2(&dp2, writer);
  writer.next_message();
  write_camera(out2, 480, 736, 3, img.pixels);
  EXPECT_EQ(copies(), before + 1);
}

TEST(Camera, SmallFramesTravelInlineAndSizesAreChecked) {
  InlineBlobWriter writer;
  engine::DataPack dp;
  Builder out(&dp, writer);
  write_camera(out, 2, 3, 1, std::string_view("abcdef"));
  EXPECT_EQ(dp.blobs_size(), 0);
  CameraImage img = read_camera(in(dp));
  EXPECT_EQ(img.pixels, "abcdef");
  EXPECT_THROW(write_camera(out, 2, 3, 3, std::string_view("abcdef")), std::runtime_error);
  data::Camera bad;
  bad.set_image_height(10);
  bad.set_image_width(10);
  bad.set_image_depth(3);
  bad.set_image_data("short");
  write_proto(out, bad);
  EXPECT_THROW(read_camera(in(dp)), std::runtime_error);
  bad.set_image_blob(5);  // no such blob
  write_proto(out, bad);
  EXPECT_THROW(read_camera(in(dp)), std::runtime_error);
  EXPECT_TRUE(read_camera(in(engine::DataPack())).pixels.empty());
}

TEST(SharedMemory, ABlobOutsideTheArenaIsRefused) {
  engine::DataPack dp;
  auto* b = dp.add_blobs();
  b->set_in_shm(true);
  b->set_shm_offset(~uint64_t{0} - 10);
  b->set_size(100);  // offset + size wraps around
  transport::ShmArena arena;
  arena.create("datapack_test2", 1 << 20);
  transport::ShmBlobReader reader(&arena);
  EXPECT_THROW(reader.get(dp, 0), std::runtime_error);
  EXPECT_THROW(inline_blob_reader().get(dp, 0), std::runtime_error);
  EXPECT_TRUE(reader.get(dp, 3).empty());
}

TEST(Registry, StandardTypesHaveNrpCoreClassNames) {
  const Registry& r = Registry::global();
  EXPECT_EQ(r.require("convoy.data.Camera").python_class, "GazeboCameraDataPack");
  EXPECT_EQ(r.require("convoy.data.Joint").python_class, "GazeboJointDataPack");
  EXPECT_EQ(r.require("convoy.data.Link").python_class, "GazeboLinkDataPack");
  EXPECT_EQ(type_name<data::Camera>(), "convoy.data.Camera");
  EXPECT_THROW(r.require("convoy.data.Nope"), std::invalid_argument);
}

TEST(Registry, TypesNamedAtRunTime) {
  Registry r;
  // Compiled into the program (protobuf's own well-known types are).
  const TypeInfo& t = r.add_by_name("google.protobuf.FileDescriptorSet");
  EXPECT_EQ(t.python_class, "GoogleProtobufFileDescriptorSetDataPack");
  EXPECT_THROW(r.add_by_name("no.such.Message"), std::invalid_argument);

  // Read from a .proto file, with an import.
  const auto dir = std::filesystem::temp_directory_path() / "convoy_registry_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "base.proto") << "syntax = \"proto3\";\npackage my_pkg;\n"
                                       "message Vec { float x = 1; float y = 2; }\n";
  std::ofstream(dir / "user.proto") << "syntax = \"proto3\";\npackage my_pkg;\n"
                                       "import \"base.proto\";\n"
                                       "message RoadUser { string name = 1; Vec pos = 2; }\n";
  r.import_proto(dir / "user.proto");
  const TypeInfo* u = r.find("my_pkg.RoadUser");
  ASSERT_NE(u, nullptr);
  EXPECT_EQ(u->python_class, "MyPkgRoadUserDataPack");
  EXPECT_EQ(r.add_by_name("my_pkg.RoadUser").name, "my_pkg.RoadUser");
  google::protobuf::FileDescriptorSet set;
  ASSERT_TRUE(set.ParseFromString(r.file_descriptor_set("my_pkg.RoadUser")));
  ASSERT_EQ(set.file_size(), 2);
  EXPECT_EQ(set.file(0).name(), "base.proto");  // dependencies first
  // A dynamic message of it goes through the codec like a compiled one.
  std::unique_ptr<google::protobuf::Message> m(u->prototype->New());
  m->GetReflection()->SetString(m.get(), u->descriptor->FindFieldByName("name"), "ped_1");
  InlineBlobWriter writer;
  engine::DataPack dp;
  Builder out(&dp, writer);
  write_proto(out, *m);
  EXPECT_EQ(dp.id().type(), "my_pkg.RoadUser");
  std::unique_ptr<google::protobuf::Message> back(u->prototype->New());
  read_proto(in(dp), back.get());
  EXPECT_EQ(back->GetReflection()->GetString(*back, u->descriptor->FindFieldByName("name")),
            "ped_1");

  std::ofstream(dir / "bad.proto") << "syntax = \"proto3\";\nmessage Broken { int32 = 1; }\n";
  try {
    r.import_proto(dir / "bad.proto");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bad.proto:2:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(r.import_proto(dir / "missing.proto"), std::invalid_argument);
}

}  // namespace
}  // namespace convoy::datapack
