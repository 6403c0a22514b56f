#include "core/two_way.h"

#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <thread>
#include <vector>

namespace {

TEST(TwoWay, EveryItemOnceWhateverTheSizeAndAlignment) {
  convoy::TwoWay split(1);
  for (size_t n : {0u, 1u, 2u, 3u, 17u, 4096u, 100001u}) {
    for (size_t align : {1u, 4u, 64u}) {
      std::vector<int> seen(n, 0);
      split.run(
          n,
          [&](size_t b, size_t e) {
            for (size_t i = b; i < e; ++i) ++seen[i];
          },
          align);
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i], 1) << "n " << n << " item " << i;
    }
  }
}

TEST(TwoWay, TheHalvesRunOnTwoThreadsWhenThereAreTwoCores) {
  if (std::thread::hardware_concurrency() < 2) GTEST_SKIP() << "one core";
  convoy::TwoWay split(1);
  std::atomic<int> callers{0};
  std::thread::id ids[2];
  split.run(2, [&](size_t b, size_t) {
    ids[b] = std::this_thread::get_id();
    ++callers;
  });
  EXPECT_EQ(callers.load(), 2);
  EXPECT_NE(ids[0], ids[1]);
  EXPECT_EQ(ids[1], std::this_thread::get_id());  // the second half runs on the caller
}

TEST(TwoWay, SmallLoopsStayOnTheCaller) {
  convoy::TwoWay split(100);
  int calls = 0;
  std::thread::id id;
  split.run(99, [&](size_t b, size_t e) {
    ++calls;
    id = std::this_thread::get_id();
    EXPECT_EQ(b, 0u);
    EXPECT_EQ(e, 99u);
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(id, std::this_thread::get_id());
}

TEST(TwoWay, ManyRunsInARowSumRight) {
  convoy::TwoWay split(1);
  std::vector<long> v(10000);
  std::iota(v.begin(), v.end(), 0);
  for (int k = 0; k < 2000; ++k) {
    std::vector<long> out(v.size());
    split.run(v.size(), [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) out[i] = v[i] * 2 + k;
    });
    ASSERT_EQ(out[9999], 9999 * 2 + k);
    ASSERT_EQ(out[0], k);
  }
}

}  // namespace
