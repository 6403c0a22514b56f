// Master URI parsing and the local-host decision (engines/ros_bridge/master_uri.h).
#include "master_uri.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace convoy::ros_bridge {
namespace {

TEST(RosMasterUri, ParsesHostAndPort) {
  const MasterUri uri = parse_master_uri("http://127.0.0.1:11411/");
  EXPECT_EQ(uri.host, "127.0.0.1");
  EXPECT_EQ(uri.port, 11411);
  EXPECT_EQ(uri.text, "http://127.0.0.1:11411/");
}

TEST(RosMasterUri, DefaultPortAndNoScheme) {
  EXPECT_EQ(parse_master_uri("http://robot").port, 11311);
  const MasterUri bare = parse_master_uri("robot.lab:12000");
  EXPECT_EQ(bare.host, "robot.lab");
  EXPECT_EQ(bare.port, 12000);
}

TEST(RosMasterUri, Ipv6InBrackets) {
  const MasterUri uri = parse_master_uri("http://[::1]:11500");
  EXPECT_EQ(uri.host, "::1");
  EXPECT_EQ(uri.port, 11500);
}

TEST(RosMasterUri, RejectsBadUris) {
  for (const char* bad :
       {"https://host:1", "http://:11311", "http://host:abc", "http://host:0", "http://host:70000",
        "http://host:", "http://host:1/path", "http://[::1:11311", ""}) {
    EXPECT_THROW(parse_master_uri(bad), std::invalid_argument) << bad;
  }
}

TEST(RosMasterUri, ChoosesConfigThenEnvThenDefault) {
  EXPECT_EQ(choose_master_uri("http://a:1", "http://b:2").source, "MasterURI");
  const MasterUri env = choose_master_uri("", "http://b:2");
  EXPECT_EQ(env.source, "ROS_MASTER_URI");
  EXPECT_EQ(env.host, "b");
  const MasterUri fallback = choose_master_uri("", nullptr);
  EXPECT_EQ(fallback.source, "default");
  EXPECT_EQ(fallback.text, "http://localhost:11311");
  EXPECT_EQ(choose_master_uri("", "").source, "default");
}

TEST(RosMasterUri, ErrorNamesTheSource) {
  try {
    choose_master_uri("", "ftp://x");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ROS_MASTER_URI"), std::string::npos) << e.what();
  }
}

TEST(RosMasterUri, LocalHosts) {
  for (const char* local : {"localhost", "LOCALHOST", "127.0.0.1", "127.1.2.3", "::1", "0.0.0.0",
                            "vm", "VM", "vm.example.org"}) {
    EXPECT_TRUE(is_local_host(local, "vm")) << local;
  }
  EXPECT_TRUE(is_local_host("vm", "vm.example.org"));
  for (const char* remote : {"10.255.255.1", "robot", "vm2", "vm.a.org", "128.0.0.1"}) {
    EXPECT_FALSE(is_local_host(remote, "vm.b.org")) << remote;
  }
  EXPECT_FALSE(is_local_host("robot", ""));
}

}  // namespace
}  // namespace convoy::ros_bridge
