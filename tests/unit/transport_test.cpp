#include <gtest/gtest.h>
#include <unistd.h>

#include <stdexcept>
#include <thread>

#include "transport/blobs.h"
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

// A header announcing more than kMaxMessageBytes ends the stream at once: no allocation of
// gigabytes, no waiting for bytes that will never come.
TEST(FrameSocket, OversizedFrameHeaderEndsTheStream) {
  int fds[2];
  make_socket_pair(fds);
  FrameSocket b(fds[1]);
  const size_t len = kMaxMessageBytes + 1;
  const unsigned char header[4] = {
      static_cast<unsigned char>(len), static_cast<unsigned char>(len >> 8),
      static_cast<unsigned char>(len >> 16), static_cast<unsigned char>(len >> 24)};
  ASSERT_EQ(::write(fds[0], header, 4), 4);
  std::string got;
  EXPECT_EQ(b.recv(&got, deadline_after(2.0)), RecvStatus::kClosed);
  EXPECT_TRUE(got.empty());
  ::close(fds[0]);
}

engine::DataPack named(const std::string& name) {
  engine::DataPack dp;
  dp.mutable_id()->set_name(name);
  dp.mutable_id()->set_engine_name("cam_engine");
  return dp;
}

// The large blobs of one message must fit in half the arena; one that does not is an error
// naming the datapack, not a message as large as the blob.
TEST(ShmBlobWriter, BlobLargerThanTheArenaHalfIsRefused) {
  ShmArena arena;
  arena.create("transport_test", 1 << 20);  // halves of 512 KiB
  ShmBlobWriter writer(arena);
  writer.next_message();
  engine::DataPack dp = named("huge");
  uint32_t index = 0;
  try {
    writer.reserve(&dp, (512 << 10) + 1, &index);
    FAIL() << "a blob larger than the arena half was accepted";
  } catch (const std::length_error& e) {
    EXPECT_NE(std::string(e.what()).find("datapack 'huge' of engine 'cam_engine': a blob of "
                                         "524289 bytes does not fit in the shared-memory arena"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(dp.blobs_size(), 0);

  // A blob filling the half exactly fits; a second large one in the same message does not.
  dp = named("first");
  auto span = writer.reserve(&dp, 512 << 10, &index);
  EXPECT_EQ(span.size(), size_t{512} << 10);
  EXPECT_TRUE(dp.blobs(0).in_shm());
  engine::DataPack second = named("second");
  EXPECT_THROW(writer.reserve(&second, 64 << 10, &index), std::length_error);
  // Small blobs still go in the message.
  EXPECT_EQ(writer.reserve(&second, 100, &index).size(), 100u);
  EXPECT_FALSE(second.blobs(0).in_shm());
  // The next message has the other half.
  writer.next_message();
  engine::DataPack third = named("third");
  EXPECT_EQ(writer.reserve(&third, 300 << 10, &index).size(), size_t{300} << 10);
  EXPECT_TRUE(third.blobs(0).in_shm());
}

}  // namespace
}  // namespace convoy::transport
