// transport/local_rpc.h: calls as frames on a Unix socket.
#include "transport/local_rpc.h"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "transport/frame_socket.h"

namespace convoy::transport {
namespace {

namespace fs = std::filesystem;

fs::path socket_path() {
  const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
  return fs::temp_directory_path() /
         ("convoy_local_rpc_" + std::string(test->name()) + "_" + std::to_string(::getpid()));
}

int connect_to(const fs::path& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// The reply to one call: {status, payload}.
std::pair<int, std::string> call(FrameSocket& s, uint8_t method, const std::string& request) {
  EXPECT_TRUE(s.send(std::string(1, static_cast<char>(method)) + request));
  std::string reply;
  EXPECT_EQ(s.recv(&reply, deadline_after(10)), RecvStatus::kOk);
  if (reply.empty()) return {-1, ""};
  return {static_cast<uint8_t>(reply[0]), reply.substr(1)};
}

LocalReply echo(uint8_t method, const std::string& request) {
  if (method == 9) throw std::runtime_error("method 9 throws");
  if (method == 7) return {5, "no such thing: " + request};  // NOT_FOUND
  return {0, std::to_string(method) + ":" + request};
}

TEST(LocalRpc, CallsAreAnsweredInOrderAndErrorsCarryTheirStatus) {
  const fs::path path = socket_path();
  LocalRpcServer server(path.string(), echo);
  FrameSocket s(connect_to(path));
  ASSERT_GE(s.fd(), 0);
  EXPECT_EQ(call(s, 1, "step"), (std::pair<int, std::string>{0, "1:step"}));
  EXPECT_EQ(call(s, 4, std::string("a\0b", 3)),
            (std::pair<int, std::string>{0, std::string("4:a\0b", 5)}));
  EXPECT_EQ(call(s, 7, "x"), (std::pair<int, std::string>{5, "no such thing: x"}));
  EXPECT_EQ(call(s, 9, ""), (std::pair<int, std::string>{13, "method 9 throws"}));
  for (int i = 0; i < 1000; ++i)
    ASSERT_EQ(call(s, 2, std::to_string(i)).second, "2:" + std::to_string(i));
  // An empty frame has no method byte.
  ASSERT_TRUE(s.send(""));
  std::string reply;
  ASSERT_EQ(s.recv(&reply, deadline_after(10)), RecvStatus::kOk);
  EXPECT_EQ(static_cast<uint8_t>(reply[0]), 3);
}

TEST(LocalRpc, AClientThatLeavesMakesWayForTheNext) {
  const fs::path path = socket_path();
  LocalRpcServer server(path.string(), echo);
  {
    FrameSocket first(connect_to(path));
    EXPECT_EQ(call(first, 1, "a").second, "1:a");
  }
  FrameSocket second(connect_to(path));
  EXPECT_EQ(call(second, 1, "b").second, "1:b");
}

TEST(LocalRpc, AStaleSocketFileIsReplacedAndTheFileGoesWithTheServer) {
  const fs::path path = socket_path();
  std::ofstream(path) << "left by a process that is gone";
  {
    LocalRpcServer server(path.string(), echo);
    EXPECT_TRUE(fs::is_socket(path));
    FrameSocket s(connect_to(path));
    EXPECT_EQ(call(s, 0, "").second, "0:");
  }
  EXPECT_FALSE(fs::exists(path));
}

TEST(LocalRpc, APathThatCannotBeListenedAtIsNamed) {
  try {
    LocalRpcServer server("/no/such/folder/sim.sock", echo);
    FAIL() << "listened at a folder that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/folder/sim.sock"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(LocalRpcServer(std::string(200, 'x'), echo), std::runtime_error);
}

TEST(LocalRpc, TheThreadWrapperRunsAroundTheServingThread) {
  const fs::path path = socket_path();
  std::atomic<int> wrapped{0};
  {
    LocalRpcServer server(path.string(), echo, [&](const std::function<void()>& body) {
      wrapped = 1;
      body();
      wrapped = 2;
    });
    FrameSocket s(connect_to(path));
    EXPECT_EQ(call(s, 1, "x").second, "1:x");
    EXPECT_EQ(wrapped.load(), 1);
  }
  EXPECT_EQ(wrapped.load(), 2);
}

}  // namespace
}  // namespace convoy::transport
