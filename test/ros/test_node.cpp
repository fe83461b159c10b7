// rostest of the registration node (see node.test).
#include <gtest/gtest.h>
#include <diagnostic_msgs/DiagnosticStatus.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/transform_listener.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "breast_tumour_registration/Register.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/ros/converters.h"

namespace {

const char* kService = "/registration_node/register";

breast_tumour_registration::Register call(bool use_cloud, const std::string& preset = "") {
  breast_tumour_registration::Register srv;
  srv.request.use_latest_cloud = use_cloud;
  srv.request.preset = preset;
  EXPECT_TRUE(ros::service::call(kService, srv));
  return srv;
}

struct Publishers {
  ros::NodeHandle nh;
  ros::Publisher cloud = nh.advertise<sensor_msgs::PointCloud2>("/camera/depth/points", 5);
  ros::Publisher tf = nh.advertise<tf2_msgs::TFMessage>("/tf", 50);
};

Publishers& pubs() {
  static Publishers p;
  return p;
}

// Replays the bag: /tf and the clouds, with fresh stamps, at about 30 Hz.
void replay(const std::string& bag_path, double seconds) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::WallTime::now() < end && ros::ok()) {
    for (const rosbag::MessageInstance& m : view) {
      const ros::Time now = ros::Time::now();
      if (auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
        for (auto& t : tf->transforms) t.header.stamp = now;
        pubs().tf.publish(*tf);
      } else if (auto c = m.instantiate<sensor_msgs::PointCloud2>()) {
        c->header.stamp = now;
        ros::WallDuration(0.005).sleep();  // tf first
        pubs().cloud.publish(*c);
        ros::WallDuration(1.0 / 30).sleep();
      }
      if (ros::WallTime::now() >= end) break;
    }
  }
}

}  // namespace

TEST(RegistrationNode, ClearErrorBeforeAnyCloud) {
  ASSERT_TRUE(ros::service::waitForService(kService, ros::Duration(60)));
  const auto srv = call(true);
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("no depth cloud has been received"), std::string::npos) << srv.response.message;
}

TEST(RegistrationNode, BadCloudsAreRejectedAndTheNodeKeepsAnswering) {
  ASSERT_TRUE(ros::service::waitForService(kService, ros::Duration(60)));
  diagnostic_msgs::DiagnosticStatus last;
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticStatus>(
      "/registration_node/status", 10, [&](const diagnostic_msgs::DiagnosticStatus::ConstPtr& m) { last = *m; });
  ros::WallDuration(0.5).sleep();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  btr::Points empty(0, 3);
  btr::Points all_nan = btr::Points::Constant(12, 3, nan);
  btr::Points fine = btr::Points::Random(12, 3);
  struct Case {
    sensor_msgs::PointCloud2 msg;
    std::string expected;
  };
  // Issue 11: the two layouts that used to crash the node (SIGSEGV); the bag test after this
  // one shows it still registers.
  sensor_msgs::PointCloud2 far_z = btr::ros_conv::to_cloud(fine, 4, 3, "world");
  far_z.fields[2].offset = 1000000000u;
  sensor_msgs::PointCloud2 long_rows = btr::ros_conv::to_cloud(btr::Points::Random(100, 3), 10, 10, "world");
  long_rows.row_step = 100000000u;
  long_rows.data.resize(1200);
  std::vector<Case> cases = {{btr::ros_conv::to_cloud(empty, 0, 1, "world"), "empty point cloud"},
                             {btr::ros_conv::to_cloud(all_nan, 4, 3, "world"), "all NaN"},
                             {btr::ros_conv::to_cloud(fine, 4, 3, "no_such_frame"), "no transform"},
                             {far_z, "does not fit"},
                             {long_rows, "shorter than its layout"}};
  for (auto& c : cases) {
    c.msg.header.stamp = ros::Time::now();
    pubs().cloud.publish(c.msg);
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(3.0);
    while (ros::WallTime::now() < until && last.message.find(c.expected) == std::string::npos) ros::WallDuration(0.05).sleep();
    EXPECT_NE(last.message.find(c.expected), std::string::npos) << "status was: " << last.message;
    // Still alive and answering.
    EXPECT_TRUE(ros::service::exists(kService, false));
    const auto srv = call(true);
    EXPECT_FALSE(srv.response.success);
  }
}

TEST(RegistrationNode, ReplayedBagGivesTheTumourWithinThreeMillimetresThePoseWithinHalfAMillimetreAndTfFrames) {
  ros::NodeHandle pnh("~");
  std::string bag, truth_file;
  ASSERT_TRUE(pnh.getParam("bag", bag));
  ASSERT_TRUE(pnh.getParam("truth", truth_file));
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  breast_tumour_registration::Register srv;
  bool ok = false;
  for (int attempt = 0; attempt < 20 && !ok; ++attempt) {
    replay(bag, 1.0);
    srv = call(true);
    ok = srv.response.success;
  }
  ASSERT_TRUE(ok) << srv.response.message;
  std::printf("%s\n", srv.response.message.c_str());
  const YAML::Node truth = YAML::LoadFile(truth_file);
  ASSERT_FALSE(srv.response.result.tumours.empty());
  EXPECT_EQ(srv.response.result.header.frame_id, "world");
  for (const auto& t : srv.response.result.tumours) {
    const auto c = truth["tumour_centroids"][t.name].as<std::vector<double>>();
    const double e = std::hypot(t.centroid.point.x - c[0], t.centroid.point.y - c[1], t.centroid.point.z - c[2]);
    // The fast preset on this coarse 9 mm phantom, from one live scan, gave 0.2 to 2.2 mm
    // over 20 runs (the error depends on which noisy cloud is the latest; see the README).
    std::printf("tumour %s: centroid error %.2f mm\n", t.name.c_str(), e * 1e3);
    EXPECT_LT(e, 3e-3) << t.name << " centroid error " << e * 1e3 << " mm";
  }
  // The tracked alignment and the tumour frames are on tf.
  EXPECT_TRUE(buffer.canTransform("world", "breast_model", ros::Time(0), ros::Duration(5.0)));
  EXPECT_TRUE(buffer.canTransform("world", "tumour_" + srv.response.result.tumours[0].name, ros::Time(0), ros::Duration(5.0)));
  const auto pose = truth["patient_pose"].as<std::vector<double>>();  // x y z [m] roll pitch yaw [deg]
  // Tracking from 1 mm depth noise after about a second of clouds (the mean of the last 10
  // poses) is within issue 4's 0.5 deg and 0.5 mm of the true pose.
  const auto tf = buffer.lookupTransform("world", "breast_model", ros::Time(0));
  const auto& q = tf.transform.rotation;
  const Eigen::Quaterniond tracked(q.w, q.x, q.y, q.z);
  const Eigen::Quaterniond truth_q(
      btr::rigid_from_rpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(pose[3], pose[4], pose[5]) * M_PI / 180).linear());
  const double rot_deg = tracked.angularDistance(truth_q) * 180 / M_PI;
  const double trans = std::hypot(tf.transform.translation.x - pose[0], tf.transform.translation.y - pose[1],
                                  tf.transform.translation.z - pose[2]);
  std::printf("tracked pose: %.3f deg and %.3f mm from the truth\n", rot_deg, trans * 1e3);
  {
    const auto& m = srv.response.result.model_to_working.transform;
    const Eigen::Quaterniond used(m.rotation.w, m.rotation.x, m.rotation.y, m.rotation.z);
    std::printf("pose used by the registration: %.3f deg and %.3f mm from the truth\n",
                used.angularDistance(truth_q) * 180 / M_PI,
                1e3 * std::hypot(m.translation.x - pose[0], m.translation.y - pose[1], m.translation.z - pose[2]));
  }
  EXPECT_LT(rot_deg, 0.5);
  EXPECT_LT(trans, 0.5e-3);
}

TEST(RegistrationNode, UncertaintyOnRequestAndAWrongValueIsNamed) {
  breast_tumour_registration::Register srv;
  srv.request.use_latest_cloud = false;  // the scene's own supine surface
  srv.request.uncertainty = "linear";
  ASSERT_TRUE(ros::service::call(kService, srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  ASSERT_FALSE(srv.response.result.tumours.empty());
  for (const auto& t : srv.response.result.tumours) {
    EXPECT_TRUE(t.has_uncertainty) << t.name;
    EXPECT_GT(t.radius_95, 0.0) << t.name;
    for (int a = 0; a < 3; ++a) EXPECT_GE(t.centroid_covariance[4 * a], 0.0) << t.name;  // the diagonal
    EXPECT_DOUBLE_EQ(t.centroid_covariance[1], t.centroid_covariance[3]) << t.name;  // symmetric
  }
  srv.request.uncertainty = "bogus";
  ASSERT_TRUE(ros::service::call(kService, srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("uncertainty"), std::string::npos) << srv.response.message;
  // Sampling: the sampled radius and a margin shell per tumour, vertex for vertex the registered
  // surface grown outwards; a sample count below 2 is named.
  srv.request.uncertainty = "sampling";
  srv.request.samples = 2;
  ASSERT_TRUE(ros::service::call(kService, srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NE(srv.response.result.uncertainty_note.find("sampled: 2 samples"), std::string::npos)
      << srv.response.result.uncertainty_note;
  for (const auto& t : srv.response.result.tumours) {
    EXPECT_TRUE(t.has_sampled_uncertainty) << t.name;
    EXPECT_GT(t.radius_95_sampled, 0.0) << t.name;
    EXPECT_LT(t.radius_95_sampled, 0.05) << t.name;  // metres: not a unit slip
    ASSERT_EQ(t.margin_shell.vertices.size(), t.mesh.vertices.size()) << t.name;
    ASSERT_EQ(t.margin_shell.triangles.size(), t.mesh.triangles.size()) << t.name;
    double moved = 0;
    for (size_t v = 0; v < t.mesh.vertices.size(); ++v)
      moved = std::max(moved, std::hypot(t.margin_shell.vertices[v].x - t.mesh.vertices[v].x,
                                         t.margin_shell.vertices[v].y - t.mesh.vertices[v].y,
                                         t.margin_shell.vertices[v].z - t.mesh.vertices[v].z));
    EXPECT_GT(moved, 0.0) << t.name;
  }
  srv.request.samples = 1;
  ASSERT_TRUE(ros::service::call(kService, srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("'samples'"), std::string::npos) << srv.response.message;
  srv.request.samples = 0;
  // Without the field, none is computed.
  srv.request.uncertainty = "";
  ASSERT_TRUE(ros::service::call(kService, srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  for (const auto& t : srv.response.result.tumours) EXPECT_FALSE(t.has_uncertainty);
}

// Run by bad_parameter*.test only (node.test filters it out): a node started with a
// parameter out of range, or of the wrong type, keeps running and answers with the
// parameter's name (~expected: the text the answer must hold).
TEST(RegistrationNodeBadParameter, KeepsRunningAndNamesTheParameter) {
  ASSERT_TRUE(ros::service::waitForService(kService, ros::Duration(60)));
  std::string expected = "~smoothing_clouds";
  ros::NodeHandle("~").getParam("expected", expected);
  for (int i = 0; i < 2; ++i) {
    const auto srv = call(false);
    EXPECT_FALSE(srv.response.success);
    EXPECT_NE(srv.response.message.find("invalid parameter"), std::string::npos) << srv.response.message;
    EXPECT_NE(srv.response.message.find(expected), std::string::npos) << srv.response.message;
    pubs().cloud.publish(sensor_msgs::PointCloud2());  // an empty cloud in between: still alive
    ros::WallDuration(0.2).sleep();
  }
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "btr_node_rostest");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  pubs();
  return RUN_ALL_TESTS();
}
