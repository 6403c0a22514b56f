// The module convoy_live of the coordinator's interpreter: publish() without and with a live
// run, and what it refuses.
#include "python/live_module.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "python/interpreter.h"

namespace convoy::python {
namespace {

class LiveModuleTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { interpreter_ = new Interpreter(); }
  static void TearDownTestSuite() {
    delete interpreter_;
    interpreter_ = nullptr;
  }
  void TearDown() override { set_live_publisher(nullptr); }
  static py::object run(const std::string& expr) {
    py::dict scope;
    py::exec("import convoy_live", scope);
    return py::eval(expr, scope);
  }
  static Interpreter* interpreter_;
};
Interpreter* LiveModuleTest::interpreter_ = nullptr;

TEST_F(LiveModuleTest, WithoutALiveRunNothingIsSent) {
  EXPECT_FALSE(run("convoy_live.enabled()").cast<bool>());
  EXPECT_FALSE(run("convoy_live.publish('/convoy/metrics', {'driving_score': 1.0})").cast<bool>());
}

TEST_F(LiveModuleTest, ALiveRunGetsTheObjectAsJsonAtTheFunctionsTime) {
  std::vector<std::string> got;
  set_live_publisher([&](const std::string& topic, const std::string& json, int64_t t) {
    got.push_back(topic + " " + json + " " + std::to_string(t));
    return true;
  });
  set_live_time(1500);
  EXPECT_TRUE(run("convoy_live.enabled()").cast<bool>());
  EXPECT_TRUE(run("convoy_live.publish('/convoy/infractions', {'kind': 'red_light', 'time_s': 1.5, "
                  "'other': None, 'ok': True, 'list': (1, 2.5), 'nan': float('nan'), "
                  "'big': 2**70})")
                  .cast<bool>());
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0],
            "/convoy/infractions {\"big\":1.1805916207174113e+21,\"kind\":\"red_light\","
            "\"list\":[1,2.5],\"nan\":null,\"ok\":true,\"other\":null,\"time_s\":1.5} 1500");
}

TEST_F(LiveModuleTest, OtherTopicsAndObjectsAreRefused) {
  set_live_publisher([](const std::string&, const std::string&, int64_t) { return true; });
  for (const char* bad :
       {"convoy_live.publish('/convoy/log', {})", "convoy_live.publish('/convoy/metrics', [1, 2])",
        "convoy_live.publish('/convoy/metrics', {1: 2})",
        "convoy_live.publish('/convoy/metrics', {'x': object()})"}) {
    EXPECT_THROW(run(bad), py::error_already_set) << bad;
  }
}

}  // namespace
}  // namespace convoy::python
