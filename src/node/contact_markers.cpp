#include "contact_markers.hpp"

#include <cmath>
#include <cstdio>

#include "ros_conversions.hpp"

namespace nscd_node {

namespace {

using visualization_msgs::Marker;

constexpr int kCircleSegments = 48;

std_msgs::ColorRGBA color(float r, float g, float b, float a = 1.0f) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

Marker makeMarker(const MarkerStyle& style, const ros::Time& stamp, const char* ns, int id,
                  int type) {
  Marker m;
  m.header.frame_id = style.frame;
  m.header.stamp = stamp;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.frame_locked = false;
  return m;
}

// An arrow from `from` along `vec`; false (no marker) when too short to draw.
bool makeArrow(const MarkerStyle& style, const ros::Time& stamp, const char* ns, int id,
               const nscd::Vec3& from, const nscd::Vec3& vec, const std_msgs::ColorRGBA& c,
               Marker& m) {
  if (!(vec.norm() > 1e-3 * style.size)) return false;  // also rejects NaN
  m = makeMarker(style, stamp, ns, id, Marker::ARROW);
  m.points.push_back(toPoint(from));
  m.points.push_back(toPoint(from + vec));
  m.scale.x = 0.3 * style.size;  // shaft diameter
  m.scale.y = 0.6 * style.size;  // head diameter
  m.scale.z = std::min(0.8 * style.size, 0.5 * vec.norm());  // head length
  m.color = c;
  return true;
}

}  // namespace

void buildStatusMarker(double sim_time, double rtf, const MarkerStyle& style,
                       const std::vector<std::string>& names, const std::vector<double>& values,
                       const StatusText& text, const ros::Time& stamp,
                       visualization_msgs::Marker& out) {
  out = makeMarker(style, stamp, "status", 0, Marker::TEXT_VIEW_FACING);
  out.pose.position.x = text.position.x();
  out.pose.position.y = text.position.y();
  out.pose.position.z = text.position.z();
  out.scale.z = text.height;
  out.color.r = out.color.g = out.color.b = out.color.a = 1.0f;
  char buf[160];
  // Two lines: RViz spaces the lines of a text marker widely.
  std::snprintf(buf, sizeof buf, "t = %.3f ms   rtf %.3g", 1e3 * sim_time, rtf);
  std::string s = buf;
  if (style.force_scale > 0) {
    std::snprintf(buf, sizeof buf, "   arrows: 1 mm = %.3g N", 1e-3 / style.force_scale);
    s += buf;
  }
  for (size_t i = 0; i < names.size() && i < values.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s%s %.3f", i == 0 ? "\n" : "   ", names[i].c_str(), values[i]);
    s += buf;
  }
  out.text = s;
}

EccentricityView eccentricityView(const nscd::Simulator& sim, int cj) {
  const nscd::ClearanceJoint& j = sim.model().clearance_joints[cj];
  const nscd::Pose bearing =
      j.bearing_body == nscd::kGround ? nscd::Pose{} : sim.bodyPose(j.bearing_body);
  EccentricityView v;
  v.center = bearing.apply(j.bearing_center);
  v.axis = bearing.rotate(j.bearing_axis).normalized();
  v.ref = bearing.rotate(j.bearing_ref).normalized();
  v.radial = j.radial;
  v.ecc = sim.clearanceEccentricity(cj);
  v.angle = sim.clearanceEccentricityAngle(cj);
  v.fn = sim.clearanceNormalForce(cj);
  return v;
}

void buildContactMarkers(const std::vector<nscd::ContactReport>& contacts,
                         const std::vector<EccentricityView>& clearance,
                         const MarkerStyle& style, const ros::Time& stamp,
                         visualization_msgs::MarkerArray& out) {
  out.markers.clear();
  out.markers.reserve(1 + 3 * contacts.size() + 3 * clearance.size());
  Marker clear = makeMarker(style, stamp, "", 0, Marker::SPHERE);
  clear.action = Marker::DELETEALL;
  out.markers.push_back(clear);

  // Not red: RViz draws URDF visuals without a material in red.
  const std_msgs::ColorRGBA green = color(0.1f, 0.9f, 0.2f);
  const std_msgs::ColorRGBA blue = color(0.15f, 0.45f, 1.0f);
  const std_msgs::ColorRGBA yellow = color(1.0f, 0.85f, 0.1f);
  const std_msgs::ColorRGBA white = color(0.95f, 0.95f, 0.95f);
  const std_msgs::ColorRGBA grey = color(0.6f, 0.6f, 0.6f, 0.8f);
  const std_msgs::ColorRGBA cyan = color(0.1f, 0.9f, 0.9f);
  const std_msgs::ColorRGBA magenta = color(0.9f, 0.1f, 0.9f);

  Marker m;
  for (size_t i = 0; i < contacts.size(); ++i) {
    const nscd::ContactReport& c = contacts[i];
    const int id = static_cast<int>(i);
    if (makeArrow(style, stamp, "normal_force", id, c.point,
                  style.force_scale * c.fn * c.normal, green, m))
      out.markers.push_back(m);
    if (makeArrow(style, stamp, "tangential_force", id, c.point, style.force_scale * c.ft,
                  c.sliding ? yellow : blue, m))
      out.markers.push_back(m);
    m = makeMarker(style, stamp, "contact_point", id, Marker::SPHERE);
    m.pose.position = toPoint(c.point);
    m.scale.x = m.scale.y = m.scale.z = style.size;
    m.color = white;
    out.markers.push_back(m);
  }

  for (size_t i = 0; i < clearance.size(); ++i) {
    const EccentricityView& v = clearance[i];
    const int id = static_cast<int>(i);
    const nscd::Vec3 e2 = v.axis.cross(v.ref);
    const double radius = v.radial * style.ecc_scale;

    m = makeMarker(style, stamp, "clearance_limit", id, Marker::LINE_STRIP);
    m.scale.x = 0.1 * style.size;
    m.color = grey;
    for (int k = 0; k <= kCircleSegments; ++k) {
      const double a = 2.0 * M_PI * k / kCircleSegments;
      m.points.push_back(toPoint(v.center + radius * (std::cos(a) * v.ref + std::sin(a) * e2)));
    }
    out.markers.push_back(m);

    const nscd::Vec3 tip =
        v.center + v.ecc * radius * (std::cos(v.angle) * v.ref + std::sin(v.angle) * e2);
    const std_msgs::ColorRGBA& c = v.fn > 0 ? magenta : cyan;
    m = makeMarker(style, stamp, "eccentricity", id, Marker::LINE_LIST);
    m.scale.x = 0.2 * style.size;
    m.color = c;
    m.points.push_back(toPoint(v.center));
    m.points.push_back(toPoint(tip));
    out.markers.push_back(m);

    m = makeMarker(style, stamp, "eccentricity_tip", id, Marker::SPHERE);
    m.pose.position = toPoint(tip);
    m.scale.x = m.scale.y = m.scale.z = 0.5 * style.size;
    m.color = c;
    out.markers.push_back(m);
  }
}

}  // namespace nscd_node
