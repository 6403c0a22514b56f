// The data-transfer engine's file lines, MQTT payloads, broker addresses and topic checks.
// The NRP-Core messages (Dump.String, Dump.ArrayFloat, EngineGrpc.DataPackMessage) are built
// here as dynamic messages from NRP-Core 1.4's field layout (nrp-core-msgs), in a pool of their
// own: the test checks the engine's output against that layout, not against the .proto files
// the program links.
#include <google/protobuf/any.pb.h>
#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <memory>

#include "dump_format.h"
#include "mqtt_client.h"

namespace convoy::datatransfer {
namespace {

namespace gpb = google::protobuf;

constexpr const char* kDumpProto = R"pb(
  name: "test_dump.proto"
  package: "Dump"
  syntax: "proto3"
  message_type {
    name: "String"
    field { name: "string_stream" number: 5 type: TYPE_STRING label: LABEL_OPTIONAL }
  }
  message_type {
    name: "ArrayFloat"
    field { name: "float_stream" number: 5 type: TYPE_FLOAT label: LABEL_REPEATED }
    field { name: "dims" number: 6 type: TYPE_UINT32 label: LABEL_REPEATED }
  }
  message_type {
    name: "Mixed"
    field { name: "count" number: 1 type: TYPE_INT32 label: LABEL_OPTIONAL }
    field { name: "ratio" number: 2 type: TYPE_DOUBLE label: LABEL_OPTIONAL }
    field { name: "flag" number: 3 type: TYPE_BOOL label: LABEL_OPTIONAL }
    field { name: "label" number: 4 type: TYPE_STRING label: LABEL_OPTIONAL }
    field { name: "raw" number: 5 type: TYPE_BYTES label: LABEL_OPTIONAL }
    field { name: "values" number: 6 type: TYPE_FLOAT label: LABEL_REPEATED }
  }
  message_type {
    name: "Outer"
    field {
      name: "inner"
      number: 1
      type: TYPE_MESSAGE
      label: LABEL_OPTIONAL
      type_name: ".Dump.Mixed"
    }
  }
)pb";

constexpr const char* kEngineGrpcProto = R"pb(
  name: "test_engine_grpc.proto"
  package: "EngineGrpc"
  syntax: "proto3"
  dependency: "google/protobuf/any.proto"
  message_type {
    name: "DataPackIdentifier"
    field { name: "dataPackName" number: 1 type: TYPE_STRING label: LABEL_OPTIONAL }
    field { name: "dataPackType" number: 2 type: TYPE_STRING label: LABEL_OPTIONAL }
    field { name: "engineName" number: 3 type: TYPE_STRING label: LABEL_OPTIONAL }
  }
  message_type {
    name: "DataPackMessage"
    field {
      name: "dataPackId"
      number: 1
      type: TYPE_MESSAGE
      label: LABEL_OPTIONAL
      type_name: ".EngineGrpc.DataPackIdentifier"
    }
    field {
      name: "data"
      number: 2
      type: TYPE_MESSAGE
      label: LABEL_OPTIONAL
      type_name: ".google.protobuf.Any"
    }
  }
)pb";

class Messages : public ::testing::Test {
 protected:
  void SetUp() override {
    gpb::FileDescriptorProto any;
    gpb::Any::descriptor()->file()->CopyTo(&any);
    ASSERT_NE(pool_.BuildFile(any), nullptr);
    for (const char* text : {kDumpProto, kEngineGrpcProto}) {
      gpb::FileDescriptorProto file;
      ASSERT_TRUE(gpb::TextFormat::ParseFromString(text, &file));
      ASSERT_NE(pool_.BuildFile(file), nullptr);
    }
  }
  std::unique_ptr<gpb::Message> make(const std::string& type, const std::string& text) {
    const gpb::Descriptor* d = pool_.FindMessageTypeByName(type);
    EXPECT_NE(d, nullptr) << type;
    std::unique_ptr<gpb::Message> m(factory_.GetPrototype(d)->New());
    EXPECT_TRUE(gpb::TextFormat::ParseFromString(text, m.get())) << text;
    return m;
  }
  gpb::DescriptorPool pool_;
  gpb::DynamicMessageFactory factory_{&pool_};
};

TEST(SecondsText, ExactAndShortest) {
  EXPECT_EQ(seconds_text(0), "0");
  EXPECT_EQ(seconds_text(10'000'000), "0.01");
  EXPECT_EQ(seconds_text(2'000'000'000), "2");
  EXPECT_EQ(seconds_text(1'234'000'001), "1.234000001");
  EXPECT_EQ(seconds_text(-5'000'000), "-0.005");
  // 30 steps of 1/30 s in ns are not a float's 1.0: the text is what the clock holds.
  EXPECT_EQ(seconds_text(999'999'990), "0.99999999");
}

TEST(Numbers, ShortestRoundTrip) {
  EXPECT_EQ(number_text(0.1), "0.1");
  EXPECT_EQ(number_text(0.1f), "0.1");
  EXPECT_EQ(number_text(1e-7), "1e-07");
  EXPECT_EQ(number_text(3.0), "3");
}

TEST(Csv, QuotesOnlyWhenNeeded) {
  EXPECT_EQ(csv_cell("plain text"), "plain text");
  EXPECT_EQ(csv_cell("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_cell("say \"hi\"\n"), "\"say \"\"hi\"\"\n\"");
}

TEST_F(Messages, DumpStringIsTimeThenText) {
  auto m = make("Dump.String", R"(string_stream: "hello, world")");
  EXPECT_EQ(proto_header(*m->GetDescriptor()), "");
  EXPECT_EQ(proto_line(*m, 20'000'000), "0.02,hello, world");
}

TEST_F(Messages, DumpArrayFloatOneRowUnlessTwoDims) {
  auto flat = make("Dump.ArrayFloat", "float_stream: [1, 2.5, -3] dims: [3]");
  EXPECT_EQ(proto_header(*flat->GetDescriptor()), "");
  EXPECT_EQ(proto_line(*flat, 10'000'000), "0.01,0,1,2.5,-3");
  auto none = make("Dump.ArrayFloat", "float_stream: [0.5]");
  EXPECT_EQ(proto_line(*none, 0), "0,0,0.5");
  auto three = make("Dump.ArrayFloat", "float_stream: [1, 2] dims: [1, 1, 2]");
  EXPECT_EQ(proto_line(*three, 0), "0,0,1,2");
}

TEST_F(Messages, DumpArrayFloatTwoDimsIsOneLinePerRow) {
  auto m = make("Dump.ArrayFloat", "float_stream: [1, 2, 3, 4, 5, 6] dims: [2, 3]");
  EXPECT_EQ(proto_line(*m, 1'000'000'000), "1,\n0,1,2,3\n1,4,5,6");
  // Too few values: the rest is empty; too many: cut.
  auto few = make("Dump.ArrayFloat", "float_stream: [1, 2, 3, 4] dims: [3, 2]");
  EXPECT_EQ(proto_line(*few, 0), "0,\n0,1,2\n1,3,4\n2");
  auto many = make("Dump.ArrayFloat", "float_stream: [1, 2, 3, 4, 5] dims: [2, 2]");
  EXPECT_EQ(proto_line(*many, 0), "0,\n0,1,2\n1,3,4");
  // Rows announced far beyond the values stop soon after them.
  auto huge = make("Dump.ArrayFloat", "float_stream: [1] dims: [4000000000, 1]");
  EXPECT_LT(proto_line(*huge, 0).size(), 20000u);
}

TEST_F(Messages, OtherMessagesHaveAHeaderAndOneColumnPerField) {
  auto m = make("Dump.Mixed",
                R"(count: -7 ratio: 0.25 flag: true label: "a,b" raw: "\x01\xff" values: [1, 2])");
  EXPECT_EQ(proto_header(*m->GetDescriptor()), "sim_time,count,ratio,flag,label,raw,values");
  EXPECT_EQ(proto_line(*m, 30'000'000), "0.03,-7,0.25,1,\"a,b\",01ff,[1 2]");
  auto empty = make("Dump.Mixed", "");
  EXPECT_EQ(proto_line(*empty, 0), "0,0,0,0,,,[]");
}

TEST_F(Messages, LargeBytesAreCountedNotDumped) {
  auto m = make("Dump.Mixed", "");
  const gpb::FieldDescriptor* raw = m->GetDescriptor()->FindFieldByName("raw");
  std::string hex;
  for (size_t i = 0; i < kMaxBytesInFile; ++i) hex += "01";
  m->GetReflection()->SetString(m.get(), raw, std::string(kMaxBytesInFile, '\x01'));
  EXPECT_EQ(proto_line(*m, 0), "0,0,0,0,," + hex + ",[]");
  m->GetReflection()->SetString(m.get(), raw, std::string(kMaxBytesInFile + 1, '\x01'));
  EXPECT_EQ(proto_line(*m, 0), "0,0,0,0,,<1025 bytes>,[]");
  m->GetReflection()->SetString(m.get(), raw, std::string(1'000'000, '\x02'));
  EXPECT_EQ(proto_line(*m, 0), "0,0,0,0,,<1000000 bytes>,[]");
  // Inside a message field: protobuf's one-line text form, the bytes cut.
  auto outer = make("Dump.Outer", "");
  outer->GetReflection()
      ->MutableMessage(outer.get(), outer->GetDescriptor()->field(0))
      ->CopyFrom(*m);
  const std::string line = proto_line(*outer, 0);
  EXPECT_LT(line.size(), 5 * kMaxBytesInFile) << line.substr(0, 200);
  EXPECT_EQ(line.substr(0, 15), "0,\"{raw: \"\"\\002") << line.substr(0, 200);
  EXPECT_EQ(line.find('\n'), std::string::npos);
}

TEST(Json, TimeThenCompactJson) {
  nlohmann::json v = {{"step", 3}, {"name", "a,b"}, {"xs", {1.5, 2}}};
  EXPECT_EQ(json_line(v, 50'000'000), R"(0.05,{"name":"a,b","step":3,"xs":[1.5,2]})");
  // Bytes that are not UTF-8 do not stop the dump.
  EXPECT_EQ(json_line(std::string("\xff"), 0), "0,\"\xEF\xBF\xBD\"");
}

TEST_F(Messages, DataPackMessageParsesAsNrpCoresLayout) {
  auto inner = make("Dump.String", R"(string_stream: "x")");
  const std::string bytes =
      datapack_message("dp", "datatransfer_engine", "Dump.String", inner->SerializeAsString());
  auto outer = make("EngineGrpc.DataPackMessage", "");
  ASSERT_TRUE(outer->ParseFromString(bytes));
  // The text printer expands the Any: its type_url names Dump.String, its value parses as one.
  EXPECT_EQ(outer->ShortDebugString(),
            "dataPackId { dataPackName: \"dp\" dataPackType: \"Dump.String\" engineName: "
            "\"datatransfer_engine\" } data { [type.googleapis.com/Dump.String] { string_stream: "
            "\"x\" } }");
}

TEST(JsonDataPackMessage, IdAndData) {
  EXPECT_EQ(
      json_datapack_message("dp", "dt", {{"a", 1}}).dump(),
      R"({"data":{"a":1},"datapackId":{"dataPackName":"dp","dataPackType":"json","engineName":"dt"}})");
}

TEST(BrokerAddress, Forms) {
  auto a = parse_broker_address("localhost:1883");
  EXPECT_EQ(a.host, "localhost");
  EXPECT_EQ(a.port, 1883);
  a = parse_broker_address("tcp://broker.example:2000");
  EXPECT_EQ(a.host, "broker.example");
  EXPECT_EQ(a.port, 2000);
  a = parse_broker_address("mqtt://10.0.0.1");
  EXPECT_EQ(a.host, "10.0.0.1");
  EXPECT_EQ(a.port, 1883);
  a = parse_broker_address("[::1]:1884");
  EXPECT_EQ(a.host, "::1");
  EXPECT_EQ(a.port, 1884);
  EXPECT_THROW(parse_broker_address("ws://localhost:9001"), std::invalid_argument);
  EXPECT_THROW(parse_broker_address("localhost:0"), std::invalid_argument);
  EXPECT_THROW(parse_broker_address("localhost:80x"), std::invalid_argument);
  EXPECT_THROW(parse_broker_address(":1883"), std::invalid_argument);
}

TEST(Topics, PublishableOnly) {
  EXPECT_EQ(topic_problem("nrp_simulation/0/data/a b"), "");
  EXPECT_NE(topic_problem("nrp_simulation/+/data"), "");
  EXPECT_NE(topic_problem("nrp_simulation/0/data/#"), "");
  EXPECT_NE(topic_problem(""), "");
  EXPECT_NE(topic_problem("bad\xff"), "");
}

TEST(Client, NothingListeningIsReportedAtOnce) {
  MqttClient client;
  // Port 1 on the loopback: nothing listens there.
  const std::string why = client.connect({"127.0.0.1", 1}, "t", std::chrono::seconds(5));
  EXPECT_NE(why, "");
  EXPECT_FALSE(client.connected());
  EXPECT_EQ(client.publish("a", "b", false), "not connected");
  EXPECT_EQ(client.close(std::chrono::milliseconds(10)), 0u);
}

}  // namespace
}  // namespace convoy::datatransfer
