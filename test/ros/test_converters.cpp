// Unit tests of the ROS message converters (no master needed).
#include <gtest/gtest.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <Eigen/Geometry>

#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/ros/converters.h"

using namespace btr;

TEST(Converters, TheUncertaintyEllipsoidHasTheCovariancesAxesAndDirections) {
  // Standard deviations 3, 1 and 2 mm along R's axes, R a turn of 30 deg about z.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  btr::Mat3 R;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  const btr::Vec3 sd(0.003, 0.001, 0.002);
  const btr::Mat3 cov = R * sd.cwiseAbs2().asDiagonal() * R.transpose();
  const auto mk = btr::ros_conv::to_ellipsoid_marker(btr::Vec3(0.1, 0.2, 0.3), cov, "world", "u", 0, 1, 1, 0, 0.5f);
  EXPECT_EQ(mk.type, visualization_msgs::Marker::SPHERE);
  EXPECT_DOUBLE_EQ(mk.pose.position.y, 0.2);
  // Eigenvalues ascending: 1, 2, 3 mm; each axis 2 sqrt(7.8147) sd.
  const double k = 2 * std::sqrt(7.8147);
  EXPECT_NEAR(mk.scale.x, k * 0.001, 1e-12);
  EXPECT_NEAR(mk.scale.y, k * 0.002, 1e-12);
  EXPECT_NEAR(mk.scale.z, k * 0.003, 1e-12);
  // The marker's z axis (the largest spread) is R's x axis, up to sign.
  const Eigen::Quaterniond q(mk.pose.orientation.w, mk.pose.orientation.x, mk.pose.orientation.y, mk.pose.orientation.z);
  EXPECT_NEAR(std::abs((q * btr::Vec3::UnitZ()).dot(R.col(0))), 1.0, 1e-9);
  EXPECT_NEAR(q.norm(), 1.0, 1e-12);
}

TEST(Converters, OrganizedCloudKeepsItsLayoutOrDropsNaN) {
  Points P(6, 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  P << 0, 0, 1, 1, 0, 1, nan, nan, nan, 0, 1, 1, 1, 1, 1, 2, 1, 1;
  const auto msg = ros_conv::to_cloud(P, 3, 2, "camera");
  EXPECT_EQ(msg.header.frame_id, "camera");
  const auto keep = ros_conv::from_cloud(msg, true);
  EXPECT_TRUE(keep.organized);
  EXPECT_EQ(keep.points.rows(), 6);
  EXPECT_EQ(keep.finite, 5);
  EXPECT_TRUE(std::isnan(keep.points(2, 0)));
  EXPECT_DOUBLE_EQ(keep.points(5, 0), 2.0);
  const auto drop = ros_conv::from_cloud(msg, false);
  EXPECT_FALSE(drop.organized);
  EXPECT_EQ(drop.points.rows(), 5);
  EXPECT_TRUE(drop.points.allFinite());
}

TEST(Converters, Float64FieldsAndMalformedClouds) {
  sensor_msgs::PointCloud2 msg;
  sensor_msgs::PointCloud2Modifier mod(msg);
  mod.setPointCloud2Fields(3, "x", 1, sensor_msgs::PointField::FLOAT64, "y", 1, sensor_msgs::PointField::FLOAT64, "z", 1,
                           sensor_msgs::PointField::FLOAT64);
  mod.resize(2);
  sensor_msgs::PointCloud2Iterator<double> x(msg, "x"), y(msg, "y"), z(msg, "z");
  *x = 0.25; *y = -0.5; *z = 1.0;
  ++x; ++y; ++z;
  *x = 1.0; *y = 2.0; *z = 3.0;
  const auto c = ros_conv::from_cloud(msg, false);
  ASSERT_EQ(c.points.rows(), 2);
  EXPECT_DOUBLE_EQ(c.points(0, 1), -0.5);
  sensor_msgs::PointCloud2 no_xyz;
  try {
    ros_conv::from_cloud(no_xyz, false);
    ADD_FAILURE() << "a cloud without x, y, z must be rejected";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no x, y, z fields"), std::string::npos);
  }
  sensor_msgs::PointCloud2 truncated = msg;
  truncated.data.resize(10);
  EXPECT_THROW(ros_conv::from_cloud(truncated, false), InputError);
}

// Issue 11: clouds whose layout points outside their data used to be read unchecked (SIGSEGV
// in the node). Each is now an InputError that says what is wrong.
TEST(Converters, LayoutsThatPointOutsideTheDataAreRefused) {
  sensor_msgs::PointCloud2 msg;
  sensor_msgs::PointCloud2Modifier mod(msg);
  mod.setPointCloud2FieldsByString(1, "xyz");
  mod.resize(100);
  msg.width = 10;
  msg.height = 10;
  msg.row_step = msg.width * msg.point_step;
  ASSERT_NO_THROW(ros_conv::from_cloud(msg, true));
  auto expect_refused = [](const sensor_msgs::PointCloud2& m, const std::string& what) {
    try {
      ros_conv::from_cloud(m, true);
      ADD_FAILURE() << "accepted a cloud that should be refused: " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  sensor_msgs::PointCloud2 far_z = msg;
  far_z.fields[2].offset = 1000000000u;
  expect_refused(far_z, "field 'z' (offset 1000000000) does not fit");
  sensor_msgs::PointCloud2 long_rows = msg;
  long_rows.row_step = 100000000u;
  long_rows.data.resize(1200);
  expect_refused(long_rows, "is shorter than its layout");
  sensor_msgs::PointCloud2 short_rows = msg;
  short_rows.row_step = msg.point_step * 5;
  expect_refused(short_rows, "row_step");
  sensor_msgs::PointCloud2 big_endian = msg;
  big_endian.is_bigendian = true;
  expect_refused(big_endian, "big-endian");
  sensor_msgs::PointCloud2 huge = msg;  // width x height far beyond the data: refused before allocating
  huge.width = 4000000000u;
  huge.height = 4000000000u;
  huge.row_step = huge.width * 16ull > 0xffffffffull ? 0xffffffffu : huge.width * 16u;
  expect_refused(huge, "shorter than");
  sensor_msgs::PointCloud2 no_count = msg;
  no_count.fields[0].count = 0;
  expect_refused(no_count, "field 'x'");
  // Fuzz finding: zero width, 10 001 rows and no data formed a pointer off an empty buffer
  // (UBSan). A cloud without points is an empty result, as the node's empty-cloud check expects.
  sensor_msgs::PointCloud2 no_width = msg;
  no_width.width = 0;
  no_width.height = 10001;
  no_width.row_step = 24;
  no_width.data.clear();
  for (const bool keep_nan : {false, true}) {
    const auto empty = ros_conv::from_cloud(no_width, keep_nan);
    EXPECT_EQ(empty.points.rows(), 0);
    EXPECT_EQ(empty.finite, 0);
  }
}

TEST(Converters, MeshMarkerAndTransformRoundTrips) {
  const SurfaceMesh s = make_icosphere(Vec3(0.1, 0.2, 0.3), 0.01, 1);
  const shape_msgs::Mesh m = ros_conv::to_mesh(s);
  const SurfaceMesh back = ros_conv::from_mesh(m);
  EXPECT_EQ(back.F, s.F);
  EXPECT_LT((back.V - s.V).cwiseAbs().maxCoeff(), 1e-15);
  const auto mk = ros_conv::to_marker(s, "world", "tumour", 3, 1, 0, 0, 1);
  EXPECT_EQ(mk.points.size(), static_cast<size_t>(3 * s.F.rows()));
  EXPECT_EQ(mk.type, visualization_msgs::Marker::TRIANGLE_LIST);
  Rigid T = Rigid::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Vec3(0.1, -0.2, 0.75);
  EXPECT_LT((ros_conv::from_transform(ros_conv::to_transform(T)).matrix() - T.matrix()).norm(), 1e-12);
  // A quaternion off unit length (rounding in a publisher) still gives a rotation; a zero one is refused.
  geometry_msgs::Transform scaled = ros_conv::to_transform(T);
  scaled.rotation.x *= 1.001, scaled.rotation.y *= 1.001, scaled.rotation.z *= 1.001, scaled.rotation.w *= 1.001;
  EXPECT_LT((ros_conv::from_transform(scaled).matrix() - T.matrix()).norm(), 1e-12);
  geometry_msgs::Transform zero;
  zero.rotation.w = 0;
  EXPECT_THROW(ros_conv::from_transform(zero), InputError);
  shape_msgs::Mesh bad = m;
  bad.triangles[0].vertex_indices[1] = 100000;
  EXPECT_THROW(ros_conv::from_mesh(bad), InputError);
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
