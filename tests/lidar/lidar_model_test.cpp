// LidarModel: validation naming the field, and the SDF parser (lidar, gpu_lidar, ray).
#include "lidar/lidar_model.h"

#include <gtest/gtest.h>

#include <sdf/sdf.hh>
#include <string>

using namespace convoy::lidar;

namespace {

// The <sensor> element of a one-link model holding `sensor_xml`.
sdf::ElementPtr sensor_element(const std::string& sensor_xml) {
  const std::string xml =
      "<?xml version='1.0'?><sdf version='1.7'><model name='m'>"
      "<link name='l'>" +
      sensor_xml + "</link></model></sdf>";
  sdf::SDFPtr doc(new sdf::SDF());
  sdf::init(doc);
  sdf::Errors errors;
  EXPECT_TRUE(sdf::readString(xml, doc, errors)) << (errors.empty() ? "" : errors[0].Message());
  return doc->Root()->GetElement("model")->GetElement("link")->GetElement("sensor");
}

const char* kVelodyne = R"(
  <sensor name='velodyne' type='gpu_lidar'>
    <update_rate>10</update_rate>
    <lidar>
      <scan>
        <horizontal><samples>1024</samples><resolution>1</resolution>
          <min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle></horizontal>
        <vertical><samples>32</samples><resolution>1</resolution>
          <min_angle>-0.5236</min_angle><max_angle>0.2618</max_angle></vertical>
      </scan>
      <range><min>0.5</min><max>120</max><resolution>0.01</resolution></range>
      <noise><type>gaussian</type><mean>0.0</mean><stddev>0.02</stddev></noise>
    </lidar>
  </sensor>)";

std::string error_of(const LidarModel& m) {
  try {
    m.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

LidarModel good() {
  LidarModel m;
  m.horizontal = {360, 1, -M_PI, M_PI};
  m.vertical = {16, 1, -0.26, 0.26};
  m.range_min = 0.5;
  m.range_max = 100;
  return m;
}

}  // namespace

TEST(LidarModel, ParsesGpuLidar) {
  const LidarModel m = parse_lidar(sensor_element(kVelodyne));
  EXPECT_EQ(m.horizontal.samples, 1024);
  EXPECT_EQ(m.vertical.samples, 32);
  EXPECT_NEAR(m.horizontal.min_angle, -3.14159, 1e-9);
  EXPECT_NEAR(m.vertical.max_angle, 0.2618, 1e-9);
  EXPECT_DOUBLE_EQ(m.range_min, 0.5);
  EXPECT_DOUBLE_EQ(m.range_max, 120);
  EXPECT_DOUBLE_EQ(m.range_resolution, 0.01);
  EXPECT_TRUE(m.gaussian_noise);
  EXPECT_DOUBLE_EQ(m.noise_stddev, 0.02);
  EXPECT_DOUBLE_EQ(m.update_rate, 10);
  EXPECT_EQ(m.rays(), 32 * 1024);
}

TEST(LidarModel, ParsesLegacyRay) {
  const LidarModel m = parse_lidar(sensor_element(R"(
    <sensor name='laser' type='ray'><update_rate>20</update_rate><ray>
      <scan><horizontal><samples>181</samples><min_angle>-1.57</min_angle>
        <max_angle>1.57</max_angle></horizontal></scan>
      <range><min>0.1</min><max>30</max></range></ray></sensor>)"));
  EXPECT_EQ(m.horizontal.samples, 181);
  EXPECT_EQ(m.vertical.samples, 1);
  EXPECT_DOUBLE_EQ(m.range_max, 30);
  EXPECT_FALSE(m.gaussian_noise);
  EXPECT_DOUBLE_EQ(m.update_rate, 20);
}

TEST(LidarModel, RejectsOtherSensors) {
  try {
    parse_lidar(sensor_element("<sensor name='c' type='camera'><camera/></sensor>"));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("camera"), std::string::npos) << e.what();
  }
}

TEST(LidarModel, BadParametersNameTheField) {
  EXPECT_EQ(error_of(good()), "");
  LidarModel m = good();
  m.horizontal.samples = 0;
  EXPECT_EQ(error_of(m), "<lidar><scan><horizontal><samples>: must be at least 1, got 0");
  m = good();
  m.vertical.samples = 0;
  EXPECT_NE(error_of(m).find("<vertical><samples>"), std::string::npos);
  m = good();
  m.range_min = -1;
  EXPECT_EQ(error_of(m), "<lidar><range><min>: must be >= 0, got -1");
  m = good();
  m.range_max = -5;
  EXPECT_NE(error_of(m).find("<lidar><range><max>"), std::string::npos) << error_of(m);
  m = good();
  m.horizontal.min_angle = 1, m.horizontal.max_angle = 0.5;
  EXPECT_NE(error_of(m).find("<horizontal><min_angle>: must not exceed <max_angle>"),
            std::string::npos)
      << error_of(m);
  m = good();
  m.noise_stddev = -0.1;
  EXPECT_NE(error_of(m).find("<noise><stddev>"), std::string::npos);
  m = good();
  m.update_rate = -1;
  EXPECT_NE(error_of(m).find("<update_rate>"), std::string::npos);
}

TEST(LidarModel, ParserRejectsZeroSamplesAndInvertedRange) {
  std::string xml = kVelodyne;
  xml.replace(xml.find("<samples>32"), 11, "<samples>0");
  try {
    parse_lidar(sensor_element(xml));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("<vertical><samples>"), std::string::npos) << e.what();
  }
  xml = kVelodyne;
  xml.replace(xml.find("<max>120"), 8, "<max>0.2");
  try {
    parse_lidar(sensor_element(xml));
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("<range><max>"), std::string::npos) << e.what();
  }
}

TEST(LidarModel, AngleLayout) {
  ScanAxis a{5, 1, -1, 1};
  EXPECT_DOUBLE_EQ(a.angle(0), -1);
  EXPECT_DOUBLE_EQ(a.angle(2), 0);
  EXPECT_DOUBLE_EQ(a.angle(4), 1);
  ScanAxis one{1, 1, 0.3, 0.7};
  EXPECT_DOUBLE_EQ(one.angle(0), 0.3);
}
