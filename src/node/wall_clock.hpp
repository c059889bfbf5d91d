// Wall-clock helpers of the node: the steady clock it paces and rates against,
// and a throttle for log messages. (ROS_*_THROTTLE follows ros::Time, which
// stands still while a paused simulation drives /clock.)
#pragma once

#include <chrono>

namespace nscd_node {

using SteadyClock = std::chrono::steady_clock;

inline double seconds(SteadyClock::duration d) { return std::chrono::duration<double>(d).count(); }

inline SteadyClock::duration wallDuration(double s) {
  return std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(s));
}

// At most one message per period of wall time.
class WallThrottle {
 public:
  bool ready(double period) {
    const auto now = SteadyClock::now();
    if (fired_ && seconds(now - last_) < period) return false;
    fired_ = true;
    last_ = now;
    return true;
  }

 private:
  bool fired_ = false;
  SteadyClock::time_point last_;
};

}  // namespace nscd_node
