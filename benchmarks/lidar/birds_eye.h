// A bird's-eye PNG of one LiDAR scan: the sensor at the centre, its +x up, `metres_per_pixel`
// scale; returns coloured by class (ground truth), unlabelled ones (the road) in grey by
// intensity, spurious weather returns in cyan.
#pragma once

#include <string>
#include <vector>

#include "lidar/point_cloud.h"

namespace convoy::lidar_bench {

// class_of[label] is the class name of ground-truth label `label` ("" for none).
void write_birds_eye(const std::string& path, const lidar::PointCloud& cloud,
                     const std::vector<std::string>& class_of, int size = 1000,
                     double metres_per_pixel = 0.08);

}  // namespace convoy::lidar_bench
