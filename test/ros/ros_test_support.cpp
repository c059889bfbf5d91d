#include "ros_test_support.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace nscd_test {

int runRosTestNode(int argc, char** argv, const char* name, const std::function<int()>& run) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, name);
  ros::NodeHandle nh;
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = run ? run() : RUN_ALL_TESTS();
  spinner.stop();
  ros::shutdown();
  return result;
}

const char* const kNode = "/nscd_sim_node";

std::string nodeTopic(const std::string& name) { return std::string(kNode) + "/" + name; }

std::string sceneParam() {
  std::string scene;
  ros::param::get("~scene", scene);
  return scene;
}

double yawOf(const geometry_msgs::Quaternion& q) {
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z));
}

}  // namespace nscd_test
