// Why the node reads PointCloud2 with its own checked reader (ros/converters.cpp) instead of
// pcl::fromROSMsg: measured on Debian 12's PCL 1.13 / pcl_conversions, 2026-12-02.
//   g++ -std=c++17 -fsanitize=address -g bench/probes/pcl_from_ros_msg.cpp -I/usr/include/pcl-1.13 \
//       -I/usr/include/eigen3 -o /tmp/probe -lpcl_common -lroscpp_serialization -lrostime && /tmp/probe
// Seen: a FLOAT64 x/y/z cloud converts to points (0, 0, 0) with only a warning on stderr, and a
// cloud whose data is shorter than width x height x point_step is read past its end
// (AddressSanitizer: heap-buffer-overflow in fromPCLPointCloud2). Either would put wrong
// points into the registration, or crash the node, on a malformed message.
#include <pcl_conversions/pcl_conversions.h>
#include <pcl/point_types.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <cstdio>
int main(int argc, char**) {
  // FLOAT64 x y z, two points
  sensor_msgs::PointCloud2 m;
  m.height = 1; m.width = 2; m.point_step = 24; m.row_step = 48;
  for (int i = 0; i < 3; ++i) { sensor_msgs::PointField f; f.name = std::string(1, "xyz"[i]); f.offset = 8 * i; f.datatype = sensor_msgs::PointField::FLOAT64; f.count = 1; m.fields.push_back(f); }
  m.data.resize(48);
  double v[6] = {1, 2, 3, 4, 5, 6}; memcpy(m.data.data(), v, 48);
  pcl::PointCloud<pcl::PointXYZ> c;
  pcl::fromROSMsg(m, c);
  std::printf("FLOAT64 cloud: %zu points, first = %g %g %g (expected 1 2 3)\n", c.size(), c[0].x, c[0].y, c[0].z);
  // Data shorter than the layout says: 1000 x 1000 points, 48 bytes.
  for (int i = 0; i < 3; ++i) { m.fields[i].datatype = sensor_msgs::PointField::FLOAT32; m.fields[i].offset = 4 * i; }
  m.point_step = 12; m.width = 1000; m.height = 1000; m.row_step = 12000;
  pcl::PointCloud<pcl::PointXYZ> d;
  std::printf("short data: converting...\n"); fflush(stdout);
  pcl::fromROSMsg(m, d);
  std::printf("short data: %zu points, no error\n", d.size());
}
