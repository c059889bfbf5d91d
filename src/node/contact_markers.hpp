// RViz markers for contacts and clearance joints. Built only while someone
// subscribes to ~contact_markers; every array starts with DELETEALL so markers
// of contacts that opened disappear.
#pragma once

#include <string>
#include <vector>

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include "nscd_sim/simulator.hpp"

namespace nscd_node {

struct MarkerStyle {
  std::string frame = "world";  // the world frame: every marker is in it
  double force_scale = 0.01;    // arrow length per newton (m/N)
  double size = 0.01;           // contact-point sphere diameter (m); arrows are thinner
  double ecc_scale = 50;        // magnification of clearance-joint eccentricities
  // Labels (the named contact's or clearance joint's name and force) beside the
  // force arrows and the eccentricity rings; text height (m), 0: 3 * size.
  bool labels = false;
  double label_size = 0;
  // When set, the eccentricity rings and arrows, and the labels, are drawn in the
  // plane z = marker_z (world): above the parts, so a top-down view shows them.
  bool have_marker_z = false;
  double marker_z = 0;
};

// The names the labels show: per model contact pair and per clearance joint
// (ContactReport::source indexes one or the other).
struct MarkerNames {
  std::vector<std::string> contacts;
  std::vector<std::string> clearance;
};

// A clearance joint's state as the eccentricity marker draws it, in the world frame.
struct EccentricityView {
  nscd::Vec3 center = nscd::Vec3::Zero();  // bearing centre
  nscd::Vec3 axis = nscd::Vec3::UnitZ();   // bearing axis (unit)
  nscd::Vec3 ref = nscd::Vec3::UnitX();    // origin of the angle (unit, orthogonal to axis)
  double radial = 0;  // radial clearance c_r (m)
  double ecc = 0;     // eccentricity / c_r (0 centred, 1 touching)
  double angle = 0;   // direction of the eccentricity about axis from ref (rad)
  double fn = 0;      // summed normal force of the joint's contacts (N)
  double journal_radius = 0;  // r_j (m); a joint with c_r >= r_j (a stand-in) is not drawn
  std::string name;
};

EccentricityView eccentricityView(const nscd::Simulator& sim, int clearance_joint);

// Per contact: a normal-force arrow (green), a tangential-force arrow (blue when
// sticking, yellow when sliding), both from the contact point along the force on
// body A, length |F| * force_scale, and a sphere at the point (white). Per
// clearance joint: the clearance circle magnified by ecc_scale (radius
// c_r * ecc_scale, grey) and a line from the bearing centre to the magnified
// journal-centre offset (cyan while free, magenta while in contact), drawn as an
// arrow with a sphere at its tip, at most 1.5 ring radii long (a larger
// eccentricity, a joint come apart, is written in the label: "J6 (e = 800 c_r)"). A clearance joint whose clearance is not smaller
// than its journal (c_r >= r_j: a stand-in, not a bearing) gets no ring.
// With style.labels: per named contact with a force, one text "NAME 12.3 N" at the
// tip of its largest normal-force arrow; per clearance joint "NAME" (and its force
// when in contact) beside its ring.
void buildContactMarkers(const std::vector<nscd::ContactReport>& contacts,
                         const std::vector<EccentricityView>& clearance,
                         const MarkerStyle& style, const ros::Time& stamp,
                         visualization_msgs::MarkerArray& out,
                         const MarkerNames& names = MarkerNames());

// An event of the run shown in the 3D view once it happened, e.g. "latch released
// t=8.430 ms" (sim time of the step at which its condition first held).
struct EventLabel {
  std::string label;
  double time = 0;  // s
};

// The status line drawn in the 3D view (~status, a TEXT_VIEW_FACING marker):
// sim time to the microsecond, the real-time factor reached ("paused" while the
// node is paused: its rtf is then 0), the arrow scale in newtons per millimetre of
// arrow, and chosen key figures ("C7.fn 13.2").
struct StatusText {
  nscd::Vec3 position = nscd::Vec3::Zero();  // world frame
  double height = 0.01;                       // m
};
void buildStatusMarker(double sim_time, double rtf, bool paused, const MarkerStyle& style,
                       const std::vector<std::string>& names, const std::vector<double>& values,
                       const StatusText& text, const ros::Time& stamp,
                       visualization_msgs::Marker& out);

// Appends one text marker per event (ns "events", orange), a list under the
// status text (one line each, in the order given).
void appendEventMarkers(const std::vector<EventLabel>& events, const MarkerStyle& style,
                        const StatusText& text, const ros::Time& stamp,
                        visualization_msgs::MarkerArray& out);

}  // namespace nscd_node
