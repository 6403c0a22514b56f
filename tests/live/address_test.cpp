#include "live/address.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace convoy::live {
namespace {

TEST(ListenAddress, ParsesPortHostAndIpv6) {
  auto a = parse_listen_address("8765");
  EXPECT_EQ(a.host, "127.0.0.1");
  EXPECT_EQ(a.port, 8765);
  a = parse_listen_address("0.0.0.0:80");
  EXPECT_EQ(a.host, "0.0.0.0");
  EXPECT_EQ(a.port, 80);
  a = parse_listen_address("[::1]:9000");
  EXPECT_EQ(a.host, "::1");
  EXPECT_EQ(a.text(), "[::1]:9000");
  EXPECT_EQ(parse_listen_address("localhost:0").port, 0);
}

TEST(ListenAddress, RefusesWhatIsNotHostPort) {
  for (const char* bad :
       {"", "abc", "127.0.0.1:", ":80", "65536", "1:2:3", "[::1]", "[::1]x80", "80x", "-1"}) {
    try {
      parse_listen_address(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--live"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("[HOST:]PORT"), std::string::npos) << e.what();
    }
  }
}

TEST(ListenAddress, KnowsLoopbackHosts) {
  EXPECT_TRUE(is_loopback_host("localhost"));
  EXPECT_TRUE(is_loopback_host("127.0.0.1"));
  EXPECT_TRUE(is_loopback_host("127.1.2.3"));
  EXPECT_TRUE(is_loopback_host("::1"));
  EXPECT_FALSE(is_loopback_host("0.0.0.0"));
  EXPECT_FALSE(is_loopback_host("192.168.1.2"));
  EXPECT_FALSE(is_loopback_host("::"));
  EXPECT_FALSE(is_loopback_host("example.org"));
}

TEST(ListenAddress, NonLoopbackNeedsInsecure) {
  const auto a = parse_listen_address("0.0.0.0:8765");
  try {
    check_listen_policy(a, false);
    ADD_FAILURE() << "accepted 0.0.0.0 without --insecure";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("--live 0.0.0.0:8765 is not a loopback address"), std::string::npos) << m;
    EXPECT_NE(m.find("--insecure"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(check_listen_policy(a, true));
  EXPECT_NO_THROW(check_listen_policy(parse_listen_address("8765"), false));
}

}  // namespace
}  // namespace convoy::live
