// NRP-Core's message set in the datapack library: large bytes fields as blobs (in shared
// memory, in place, one copy each way), the order of a repeated bytes field kept, bad blob
// references refused, the Gazebo messages as the standard types, the packages registered
// and in step with the python_grpc schema.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <type_traits>

#include "convoy/datapacks.pb.h"
#include "datapack/camera.h"
#include "datapack/nrp.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "nrp_protobuf/dump.pb.h"
#include "nrp_protobuf/enginetest.pb.h"
#include "nrp_protobuf/gazebo.pb.h"
#include "nrp_protobuf/nrpgenericproto.pb.h"
#include "nrp_protobuf/wrappers.pb.h"
#include "transport/blobs.h"

namespace convoy::datapack {
namespace {

uint64_t copies() { return large_copies().copies.load(); }

std::string pattern(size_t n, int seed) {
  std::string s(n, '\0');
  for (size_t i = 0; i < n; ++i) s[i] = static_cast<char>((i * 7 + seed) % 251);
  return s;
}

struct Shm {
  Shm() {
    arena.create("nrp_messages_test", 16 << 20);
    writer.next_message();
  }
  transport::ShmArena arena;
  transport::ShmBlobWriter writer{arena};
  transport::ShmBlobReader reader{&arena};
  bool inside(const void* p) const {
    auto* c = static_cast<const char*>(p);
    return c >= arena.data() && c < arena.data() + arena.size();
  }
};

TEST(NrpMessages, LargeBytesFieldsTravelAsBlobsInSharedMemory) {
  Shm shm;
  NrpGenericProto::Image img;
  img.set_height(480);
  img.set_width(736);
  img.set_step(736 * 3);
  img.set_type(NrpGenericProto::RGB8);
  img.set_data(pattern(480 * 736 * 3, 1));
  engine::DataPack dp;
  dp.mutable_id()->set_name("image");
  Builder out(&dp, shm.writer);
  const uint64_t before = copies();
  write_proto(out, img);
  EXPECT_EQ(copies(), before + 1);  // into the arena
  EXPECT_EQ(dp.id().type(), "NrpGenericProto.Image");
  ASSERT_EQ(dp.proto().blob_fields_size(), 1);
  EXPECT_EQ(dp.proto().blob_fields(0).field(), 6u);
  EXPECT_LT(dp.proto().data().size(), 64u);  // the pixels are not in the payload
  ASSERT_EQ(dp.blobs_size(), 1);
  EXPECT_TRUE(dp.blobs(0).in_shm());
  bool in_shm = false;
  View view(dp, shm.reader);
  EXPECT_TRUE(shm.inside(view.blob(0, &in_shm).data()));
  EXPECT_TRUE(in_shm);

  NrpGenericProto::Image back;
  read_proto(view, &back);
  EXPECT_EQ(copies(), before + 2);  // out of the arena into the message
  EXPECT_EQ(back.SerializeAsString(), img.SerializeAsString());
}

TEST(NrpMessages, SmallValuesStayInThePayload) {
  InlineBlobWriter writer;
  Wrappers::BytesValue v;
  v.set_value(pattern(kLargeBlobBytes - 1, 2));
  engine::DataPack dp;
  Builder out(&dp, writer);
  write_proto(out, v);
  EXPECT_EQ(dp.blobs_size(), 0);
  EXPECT_EQ(dp.proto().blob_fields_size(), 0);
  EXPECT_EQ(dp.proto().data(), v.SerializeAsString());
}

TEST(NrpMessages, RepeatedBytesKeepTheirOrderInline) {
  InlineBlobWriter writer;  // a remote engine: blobs inline in the message
  NrpGenericProto::ArrayBytes a;
  a.add_array("head");
  a.add_array(pattern(100000, 3));
  a.add_array("");
  a.add_array(pattern(kLargeBlobBytes, 4));
  a.add_array("tail");
  a.add_shape(5);
  engine::DataPack dp;
  Builder out(&dp, writer);
  write_proto(out, a);
  ASSERT_EQ(dp.proto().blob_fields_size(), 2);
  EXPECT_EQ(dp.proto().blob_fields(0).index(), 1u);
  EXPECT_EQ(dp.proto().blob_fields(1).index(), 3u);
  EXPECT_FALSE(dp.blobs(0).in_shm());
  NrpGenericProto::ArrayBytes back;
  read_proto(View(dp, inline_blob_reader()), &back);
  EXPECT_EQ(back.SerializeAsString(), a.SerializeAsString());
}

// proto_bytes: what a program that does not know the type (the data-transfer engine, say)
// gets: the message's bytes with the blobs put back, parsing as the message.
TEST(NrpMessages, ProtoBytesPutBlobsBackWithoutTheType) {
  Shm shm;
  NrpGenericProto::Image img;  // a singular bytes field (6) before nothing, after four others
  img.set_height(2);
  img.set_width(3);
  img.set_data(pattern(100000, 8));
  img.set_isbigendian(true);
  NrpGenericProto::ArrayBytes a;  // large elements among small ones, and an empty one
  a.add_array("head");
  a.add_array(pattern(50000, 9));
  a.add_array("");
  a.add_array(pattern(kLargeBlobBytes, 10));
  a.add_shape(4);
  for (const google::protobuf::Message* m : {static_cast<google::protobuf::Message*>(&img),
                                             static_cast<google::protobuf::Message*>(&a)}) {
    engine::DataPack dp;
    Builder out(&dp, shm.writer);
    write_proto(out, *m);
    ASSERT_GT(dp.proto().blob_fields_size(), 0);
    const std::string bytes = proto_bytes(View(dp, shm.reader));
    std::unique_ptr<google::protobuf::Message> back(m->New());
    ASSERT_TRUE(back->ParseFromString(bytes));
    EXPECT_EQ(back->SerializeAsString(), m->SerializeAsString()) << m->GetTypeName();
  }
  // Without blobs: the payload as it is.
  Wrappers::BytesValue small;
  small.set_value("abc");
  engine::DataPack dp;
  Builder out(&dp, shm.writer);
  write_proto(out, small);
  EXPECT_EQ(proto_bytes(View(dp, shm.reader)), small.SerializeAsString());
  // A missing blob names the datapack.
  Wrappers::BytesValue v;
  v.set_value(pattern(100000, 11));
  engine::DataPack big;
  big.mutable_id()->set_name("bytes");
  Builder bout(&big, shm.writer);
  write_proto(bout, v);
  big.mutable_proto()->mutable_blob_fields(0)->set_blob(5);
  try {
    proto_bytes(View(big, shm.reader));
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'bytes'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("missing blob"), std::string::npos) << e.what();
  }
}

TEST(NrpMessages, BadBlobReferencesAreRefused) {
  InlineBlobWriter writer;
  Wrappers::BytesValue v;
  v.set_value(pattern(100000, 5));
  engine::DataPack dp;
  dp.mutable_id()->set_name("bytes");
  Builder out(&dp, writer);
  write_proto(out, v);
  Wrappers::BytesValue back;
  auto expect_error = [&](const engine::DataPack& bad, const char* needle) {
    try {
      read_proto(View(bad, inline_blob_reader()), &back);
      ADD_FAILURE() << "no error for " << needle;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bytes"), std::string::npos) << e.what();
    }
  };
  engine::DataPack bad = dp;
  bad.mutable_proto()->mutable_blob_fields(0)->set_blob(7);
  expect_error(bad, "missing blob");
  bad = dp;
  bad.mutable_proto()->mutable_blob_fields(0)->set_field(9);
  expect_error(bad, "no bytes field");
  NrpGenericProto::ArrayBytes a;
  a.add_array(pattern(100000, 6));
  engine::DataPack adp;
  Builder aout(&adp, writer);
  write_proto(aout, a);
  adp.mutable_proto()->mutable_blob_fields(0)->set_index(3);
  NrpGenericProto::ArrayBytes aback;
  EXPECT_THROW(read_proto(View(adp, inline_blob_reader()), &aback), std::runtime_error);
}

TEST(NrpMessages, GazeboCameraTravelsAsTheStandardCamera) {
  Shm shm;
  Gazebo::Camera cam;
  cam.set_imagewidth(736);
  cam.set_imageheight(480);
  cam.set_imagedepth(3);
  cam.set_imagedata(pattern(736 * 480 * 3, 7));
  engine::DataPack dp;
  Builder out(&dp, shm.writer);
  const uint64_t before = copies();
  write_message(out, cam);
  EXPECT_EQ(copies(), before + 1);
  EXPECT_EQ(dp.id().type(), "convoy.data.Camera");
  const CameraImage img = read_camera(View(dp, shm.reader));
  EXPECT_EQ(img.width, 736u);
  EXPECT_EQ(img.height, 480u);
  EXPECT_TRUE(img.in_shm);
  EXPECT_EQ(img.pixels, cam.imagedata());

  Gazebo::Camera back;
  read_message(View(dp, shm.reader), &back);
  EXPECT_EQ(copies(), before + 2);
  EXPECT_EQ(back.SerializeAsString(), cam.SerializeAsString());
  // A wrong size is an error naming the datapack, not a short frame.
  cam.set_imagedepth(4);
  dp.mutable_id()->set_name("cam");
  EXPECT_THROW(write_message(out, cam), std::runtime_error);
}

TEST(NrpMessages, GazeboJointAndLinkAreTheStandardBytes) {
  InlineBlobWriter writer;
  Gazebo::Link link;
  for (float v : {1.f, 2.f, 3.f}) link.add_position(v);
  for (float v : {4.f, 5.f, 6.f}) link.add_linearvelocity(v);
  engine::DataPack dp;
  Builder out(&dp, writer);
  write_message(out, link);
  EXPECT_EQ(dp.id().type(), "convoy.data.Link");
  const auto std_link = read_proto<data::Link>(View(dp, inline_blob_reader()));
  EXPECT_EQ(std_link.linear_velocity(1), 5.f);
  Gazebo::Link back;
  read_message(View(dp, inline_blob_reader()), &back);
  EXPECT_EQ(back.SerializeAsString(), link.SerializeAsString());

  data::Joint joint;
  joint.set_effort(2.5f);
  write_proto(out, joint);
  Gazebo::Joint gj;
  read_message(View(dp, inline_blob_reader()), &gj);
  EXPECT_EQ(gj.effort(), 2.5f);
  // Another type is still an error.
  Dump::String s;
  EXPECT_THROW(read_message(View(dp, inline_blob_reader()), &s), std::runtime_error);
}

TEST(NrpMessages, PackagesAreRegisteredAndMatchTheEngineSchema) {
  const Registry& r = Registry::global();
  for (const char* type : {"Dump.String", "Dump.ArrayFloat", "EngineTest.TestPayload",
                           "Wrappers.BoolValue", "Wrappers.BytesValue", "NrpGenericProto.Image",
                           "NrpGenericProto.ArrayInt32", "Gazebo.Camera", "Gazebo.Model"})
    EXPECT_NE(r.find(type), nullptr) << type;
  EXPECT_EQ(r.require("Dump.String").python_class, "DumpStringDataPack");
  EXPECT_EQ(r.require("NrpGenericProto.ArraySInt64").python_class,
            "NrpGenericProtoArraySInt64DataPack");
  EXPECT_EQ(r.require("EngineTest.TestPayload").python_class, "EngineTestTestPayloadDataPack");
  EXPECT_EQ(r.require("Gazebo.Model").python_class, "GazeboModelDataPack");
  EXPECT_TRUE(r.require("convoy.data.Camera").named_class);
  EXPECT_FALSE(r.require("Gazebo.Camera").named_class);
  EXPECT_EQ(standard_type_of("Gazebo.Camera"), "convoy.data.Camera");
  EXPECT_EQ(standard_type_of("Dump.String"), "");
  EXPECT_EQ(nrp_package_file("Nope"), nullptr);

  std::ifstream f(CONVOY_SOURCE_DIR "/engines/python_grpc/schema.json");
  ASSERT_TRUE(f.good());
  const auto schema = nlohmann::json::parse(f);
  const auto names =
      schema["properties"]["ProtobufPackages"]["items"]["enum"].get<std::vector<std::string>>();
  EXPECT_EQ(names, nrp_packages());
}

// The bytes NRP-Core 1.4 writes for these messages (nrp-core-msgs' .proto files, encoded by
// hand): the same field numbers, wire types and enum values.
std::string bytes(std::initializer_list<int> b) {
  std::string s;
  for (int c : b) s.push_back(static_cast<char>(c));
  return s;
}

TEST(NrpMessages, WireFormatIsNrpCore14s) {
  EngineTest::TestPayload payload;
  static_assert(std::is_same_v<decltype(payload.integer()), uint32_t>);
  payload.set_integer(41);
  payload.set_str("ab");
  EXPECT_EQ(payload.SerializeAsString(), bytes({0x08, 41, 0x12, 2, 'a', 'b'}));

  NrpGenericProto::Image img;
  img.set_height(2);
  img.set_width(3);
  img.set_step(9);
  img.set_type(NrpGenericProto::BGR16);
  img.set_isbigendian(true);
  img.set_data("x");
  EXPECT_EQ(img.SerializeAsString(),
            bytes({0x08, 2, 0x10, 3, 0x18, 9, 0x20, 5, 0x28, 1, 0x32, 1, 'x'}));
  EXPECT_EQ(NrpGenericProto::OTHER, 0);
  EXPECT_EQ(NrpGenericProto::MONO8, 7);
  EXPECT_EQ(NrpGenericProto::MONO16, 8);
  EXPECT_EQ(NrpGenericProto::BAYER_GRBG16, 16);
  EXPECT_EQ(NrpGenericProto::IMAGE_TYPE_MAX, 16);

  NrpGenericProto::ArraySInt32 a;
  a.add_array(-1);
  a.add_shape(1);
  EXPECT_EQ(a.SerializeAsString(), bytes({0x0a, 1, 1, 0x12, 1, 1}));  // zigzag -1 = 1

  Gazebo::Model model;
  model.add_position(1.0f);
  model.add_angularvelocity(1.0f);
  EXPECT_EQ(model.SerializeAsString(),
            bytes({0x0a, 4, 0, 0, 0x80, 0x3f, 0x22, 4, 0, 0, 0x80, 0x3f}));

  Wrappers::FloatValue f;
  f.set_value(1.0f);
  EXPECT_EQ(f.SerializeAsString(), bytes({0x0d, 0, 0, 0x80, 0x3f}));
}

}  // namespace
}  // namespace convoy::datapack
