#include <gtest/gtest.h>
#include <unistd.h>

#include <thread>

#include "transport/frame_socket.h"

namespace convoy::transport {
namespace {

TEST(FrameSocket, SmallAndLargeFramesArriveWhole) {
  int fds[2];
  make_socket_pair(fds);
  FrameSocket a(fds[0]), b(fds[1]);
  std::string big(5 << 20, 'x');
  big[12345] = 'y';
  std::thread writer([&] {
    ASSERT_TRUE(a.send("hello"));
    ASSERT_TRUE(a.send(""));
    ASSERT_TRUE(a.send(big));
    ASSERT_TRUE(a.send("after"));
  });
  std::string got;
  auto deadline = deadline_after(10);
  ASSERT_EQ(b.recv(&got, deadline), RecvStatus::kOk);
  EXPECT_EQ(got, "hello");
  ASSERT_EQ(b.recv(&got, deadline), RecvStatus::kOk);
  EXPECT_EQ(got, "");
  ASSERT_EQ(b.recv(&got, deadline), RecvStatus::kOk);
  EXPECT_EQ(got, big);
  ASSERT_EQ(b.recv(&got, deadline), RecvStatus::kOk);
  EXPECT_EQ(got, "after");
  writer.join();
}

TEST(FrameSocket, ClosedPeerIsReportedAtOnce) {
  int fds[2];
  make_socket_pair(fds);
  FrameSocket b(fds[1]);
  ::close(fds[0]);
  std::string got;
  EXPECT_EQ(b.recv(&got, Deadline::max()), RecvStatus::kClosed);
}

TEST(FrameSocket, DeadlineGivesTimeout) {
  int fds[2];
  make_socket_pair(fds);
  FrameSocket a(fds[0]), b(fds[1]);
  std::string got;
  auto t0 = SteadyClock::now();
  EXPECT_EQ(b.recv(&got, deadline_after(0.2)), RecvStatus::kTimeout);
  EXPECT_GE(SteadyClock::now() - t0, std::chrono::milliseconds(190));
}

}  // namespace
}  // namespace convoy::transport
