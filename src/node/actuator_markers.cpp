// The interactive markers of the actuators (actuator_markers.hpp).
#include "actuator_markers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <visualization_msgs/InteractiveMarkerControl.h>
#include <visualization_msgs/Marker.h>

#include "nscd_sim/key_figures.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "ros_conversions.hpp"

namespace nscd_node {
namespace {

using visualization_msgs::InteractiveMarker;
using visualization_msgs::InteractiveMarkerControl;
using visualization_msgs::InteractiveMarkerFeedback;

}  // namespace

ActuatorMarkersOptions readActuatorMarkersOptions(const ros::NodeHandle& pnh) {
  ActuatorMarkersOptions o;
  pnh.param("sim_node", o.sim_node, o.sim_node);
  XmlRpc::XmlRpcValue v;
  if (pnh.getParam("text_size", v) && !(paramNumber(v, o.text_size) && o.text_size > 0))
    throw nscd::SceneError("parameter " + pnh.resolveName("text_size") + ": expected a positive number (m)");
  const std::string where = "parameter " + pnh.resolveName("actuators");
  const std::string form = "expected {NAME: {min: MIN, max: MAX}, ...}, optionally with scale (m), "
                           "figures (key-figure names) and text_offset ([RIGHT, UP], m)";
  if (!pnh.getParam("actuators", v) || v.getType() != XmlRpc::XmlRpcValue::TypeStruct || v.size() == 0)
    throw nscd::SceneError(where + ": " + form);
  for (auto it = v.begin(); it != v.end(); ++it) {
    ActuatorMarkerConfig c;
    c.actuator = it->first;
    XmlRpc::XmlRpcValue& e = it->second;
    const std::string at = where + "/" + c.actuator;
    if (e.getType() != XmlRpc::XmlRpcValue::TypeStruct || !e.hasMember("min") || !e.hasMember("max") ||
        !paramNumber(e["min"], c.range.min) || !paramNumber(e["max"], c.range.max))
      throw nscd::SceneError(at + ": " + form);
    if (!(c.range.min < c.range.max))
      throw nscd::SceneError(at + ": min must be below max, got [" + std::to_string(c.range.min) +
                             ", " + std::to_string(c.range.max) + "]");
    if (e.hasMember("scale") && !(paramNumber(e["scale"], c.scale) && c.scale > 0))
      throw nscd::SceneError(at + "/scale: expected a positive number (m)");
    if (e.hasMember("text_offset")) {
      XmlRpc::XmlRpcValue& t = e["text_offset"];
      double right = NAN, up = NAN;
      if (t.getType() != XmlRpc::XmlRpcValue::TypeArray || t.size() != 2 || !paramNumber(t[0], right) ||
          !paramNumber(t[1], up))
        throw nscd::SceneError(at + "/text_offset: expected [RIGHT, UP] (m on the screen from the marker)");
      c.text_offset = {right, up};
    }
    if (e.hasMember("figures")) {
      XmlRpc::XmlRpcValue& f = e["figures"];
      if (f.getType() != XmlRpc::XmlRpcValue::TypeArray)
        throw nscd::SceneError(at + "/figures: expected a list of key-figure names");
      for (int i = 0; i < f.size(); ++i) {
        if (f[i].getType() != XmlRpc::XmlRpcValue::TypeString)
          throw nscd::SceneError(at + "/figures: expected a list of key-figure names");
        c.figures.push_back(static_cast<std::string>(f[i]));
      }
    }
    o.actuators.push_back(c);
  }
  return o;
}

ActuatorMarkers::ActuatorMarkers(ros::NodeHandle& nh, const nscd::Model& model,
                                 const ActuatorMarkersOptions& options)
    : model_(model), text_size_(options.text_size), server_(ros::this_node::getName()) {
  const std::vector<std::string> names = nscd::keyFigureNames(model);
  // Default marker size: a fifth of the bodies' extent (at least 5 mm).
  nscd::Vec3 lo = nscd::Vec3::Constant(1e300), hi = nscd::Vec3::Constant(-1e300);
  for (const nscd::Body& b : model.bodies) {
    lo = lo.cwiseMin(b.initial_pose.p);
    hi = hi.cwiseMax(b.initial_pose.p);
  }
  const double default_scale = model.bodies.empty() ? 0.1 : std::max(0.005, 0.2 * (hi - lo).norm());
  markers_.reserve(options.actuators.size());
  for (const ActuatorMarkerConfig& c : options.actuators) {
    Marker m;
    m.config = c;
    m.handle = actuatorHandle(model, c.actuator);
    if (m.config.scale <= 0) m.config.scale = default_scale;
    for (const std::string& f : c.figures)
      if (std::find(names.begin(), names.end(), f) == names.end())
        throw nscd::SceneError("parameter actuators/" + c.actuator + "/figures: unknown key figure '" +
                               f + "'");
    const bool rotate = m.handle.motion == ActuatorHandle::Motion::Rotate;
    m.unit = rotate ? "rad" : "mm";
    m.display = rotate ? 1.0 : 1e3;
    m.effort_unit = rotate ? "N m" : "N";
    m.figure_values.assign(c.figures.size(), NAN);
    markers_.push_back(m);
  }
  for (size_t i = 0; i < markers_.size(); ++i) {
    Marker& m = markers_[i];
    const std::string topic = options.sim_node + "/" + m.config.actuator + "/command";
    m.command_pub = nh.advertise<std_msgs::Float64>(topic, 10);
    m.command_sub = nh.subscribe<std_msgs::Float64>(
        topic, 10, [this, i](const std_msgs::Float64ConstPtr& msg) { onCommand(i, msg); });
    const double initial = model.actuators[m.handle.actuator].initial_command;
    m.shown_command = initial;
    m.shown_text = text(m);
    server_.insert(build(m, initial),
                   [this, i](const visualization_msgs::InteractiveMarkerFeedbackConstPtr& f) { onFeedback(i, f); });
    ROS_INFO("nscd_actuator_markers: '%s' (%s, range [%g, %g]) commands %s", m.config.actuator.c_str(),
             m.handle.motion == ActuatorHandle::Motion::Rotate ? "turn about its joint axis" : "slide along its axis",
             m.config.range.min, m.config.range.max, nh.resolveName(topic).c_str());
  }
  server_.applyChanges();
  figures_sub_ = nh.subscribe<nscd_sim::KeyFigures>(options.sim_node + "/key_figures", 10,
                                                    &ActuatorMarkers::onKeyFigures, this);
  refresh_timer_ = nh.createWallTimer(ros::WallDuration(0.1), &ActuatorMarkers::refresh, this);
}

namespace {

// An annulus about the marker's x axis (in its y-z plane), radii 0.44 s to 0.5 s.
visualization_msgs::Marker gripRing(double s, const std_msgs::ColorRGBA& color) {
  visualization_msgs::Marker ring;
  ring.type = visualization_msgs::Marker::TRIANGLE_LIST;
  ring.scale.x = ring.scale.y = ring.scale.z = 1;
  ring.pose.orientation.w = 1;
  ring.color = color;
  const double r0 = 0.44 * s, r1 = 0.5 * s;
  constexpr int kSegments = 48;
  auto at = [](double r, double a) {
    geometry_msgs::Point p;
    p.y = r * std::cos(a);
    p.z = r * std::sin(a);
    return p;
  };
  for (int k = 0; k < kSegments; ++k) {
    const double a0 = 2 * M_PI * k / kSegments, a1 = 2 * M_PI * (k + 1) / kSegments;
    for (const geometry_msgs::Point& p : {at(r0, a0), at(r1, a0), at(r1, a1), at(r0, a0), at(r1, a1), at(r0, a1)})
      ring.points.push_back(p);
  }
  return ring;
}

// What the mouse grabs: a thin ring about the axis (RViz's default is a broad disc
// that hides the part) or two arrows along it, translucent orange.
InteractiveMarkerControl dragControl(bool rotate, double s) {
  InteractiveMarkerControl drag;
  drag.name = rotate ? "rotate" : "slide";
  drag.interaction_mode = rotate ? InteractiveMarkerControl::ROTATE_AXIS : InteractiveMarkerControl::MOVE_AXIS;
  drag.orientation_mode = InteractiveMarkerControl::INHERIT;
  drag.always_visible = true;
  const std_msgs::ColorRGBA grip = rgba(1.0f, 0.55f, 0.0f, 0.7f);
  if (rotate) {
    drag.markers.push_back(gripRing(s, grip));
  } else {
    for (double side : {1.0, -1.0}) {  // arrows pointing both ways along x, off the centre
      visualization_msgs::Marker arrow;
      arrow.type = visualization_msgs::Marker::ARROW;
      geometry_msgs::Point a, b;
      a.x = side * 0.15 * s;
      b.x = side * 0.55 * s;
      arrow.points = {a, b};
      arrow.scale.x = 0.08 * s;
      arrow.scale.y = 0.18 * s;
      arrow.scale.z = 0.15 * s;
      arrow.pose.orientation.w = 1;
      arrow.color = grip;
      drag.markers.push_back(arrow);
    }
  }
  return drag;
}

// The commanded lever: from the pivot towards the driven body, turning with the command.
InteractiveMarkerControl leverControl(double s) {
  InteractiveMarkerControl lever;
  lever.name = "lever";
  lever.interaction_mode = InteractiveMarkerControl::NONE;
  lever.orientation_mode = InteractiveMarkerControl::INHERIT;
  lever.always_visible = true;
  visualization_msgs::Marker arrow;
  arrow.type = visualization_msgs::Marker::ARROW;
  geometry_msgs::Point a, b;
  b.y = 0.5 * s;
  arrow.points = {a, b};
  arrow.scale.x = 0.03 * s;
  arrow.scale.y = 0.08 * s;
  arrow.scale.z = 0.1 * s;
  arrow.color = rgba(1.0f, 0.55f, 0.0f, 0.9f);
  arrow.pose.orientation.w = 1;
  lever.markers.push_back(arrow);
  return lever;
}

// The text (command, then effort and figures), facing the viewer, above the marker;
// line height h, at `offset` ([right, up]; empty: centred above the marker). One
// marker per line: RViz spaces the lines of one text marker several heights apart.
InteractiveMarkerControl textControl(const std::string& shown_text, const std::vector<double>& offset,
                                     double s, double h) {
  InteractiveMarkerControl label;
  label.name = "text";
  label.interaction_mode = InteractiveMarkerControl::NONE;
  label.orientation_mode = InteractiveMarkerControl::VIEW_FACING;
  label.always_visible = true;
  size_t start = 0;
  for (int line = 0; start <= shown_text.size(); ++line) {
    const size_t end = std::min(shown_text.find('\n', start), shown_text.size());
    visualization_msgs::Marker t;
    t.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    t.scale.x = t.scale.y = t.scale.z = h;
    // In a view-facing control y is left and z up on the screen; the lines go down
    // from the first, which stands at the offset (default: centred above the marker).
    const double right = offset.empty() ? 0.0 : offset[0];
    const double up = offset.empty() ? 0.55 * s + 2.1 * h : offset[1];
    t.pose.position.y = -right;
    t.pose.position.z = up - 1.4 * h * line;
    t.pose.orientation.w = 1;
    t.color = rgba(1.0f, 0.8f, 0.3f, 1.0f);
    t.text = shown_text.substr(start, end - start);
    label.markers.push_back(t);
    start = end + 1;
  }
  return label;
}

}  // namespace

InteractiveMarker ActuatorMarkers::build(const Marker& m, double command) const {
  const double s = m.config.scale;
  InteractiveMarker im;
  im.header.frame_id = m.handle.frame;  // stamp 0: RViz follows the frame's latest tf
  im.name = m.config.actuator;
  im.scale = s;
  im.pose = toPose(m.handle.poseAt(command));
  const bool rotate = m.handle.motion == ActuatorHandle::Motion::Rotate;
  im.controls.push_back(dragControl(rotate, s));
  if (rotate) im.controls.push_back(leverControl(s));
  const double h = text_size_ > 0 ? text_size_ : 0.12 * s;
  im.controls.push_back(textControl(m.shown_text, m.config.text_offset, s, h));
  return im;
}

std::string ActuatorMarkers::text(const Marker& m) const {
  char buf[160];
  std::string s;
  const double shown = shownCommand(m);
  std::snprintf(buf, sizeof buf, "%s %.3f %s", m.config.actuator.c_str(), m.display * shown, m.unit.c_str());
  s = buf;
  // A command the node has not reached yet (a rate limit, or not yet stepped).
  if (std::isfinite(m.applied) && std::abs(m.applied - shown) > 1e-9 * std::max(1.0, std::abs(shown))) {
    std::snprintf(buf, sizeof buf, " (now %.3f)", m.display * m.applied);
    s += buf;
  }
  if (std::isfinite(m.effort)) {
    std::snprintf(buf, sizeof buf, "\neffort %.3g %s", m.effort, m.effort_unit.c_str());
    s += buf;
  }
  for (size_t k = 0; k < m.config.figures.size(); ++k) {
    if (!std::isfinite(m.figure_values[k])) continue;
    std::snprintf(buf, sizeof buf, "   %s %.3g", m.config.figures[k].c_str(), m.figure_values[k]);
    s += buf;
  }
  return s;
}

// Where the marker stands: the last command sent, else the one the node applies.
double ActuatorMarkers::shownCommand(const Marker& m) const {
  if (std::isfinite(m.target)) return m.target;
  if (std::isfinite(m.applied)) return m.applied;
  return model_.actuators[m.handle.actuator].initial_command;
}

void ActuatorMarkers::onFeedback(size_t i, const visualization_msgs::InteractiveMarkerFeedbackConstPtr& f) {
  Marker& m = markers_[i];
  switch (f->event_type) {
    case InteractiveMarkerFeedback::MOUSE_DOWN:
      m.dragging = true;
      return;
    case InteractiveMarkerFeedback::MOUSE_UP:
      m.dragging = false;
      m.shown_command = NAN;  // the next refresh puts the marker where the command is
      return;
    case InteractiveMarkerFeedback::POSE_UPDATE:
      break;
    default:
      return;
  }
  const double asked = m.handle.commandAt(fromPose(f->pose), shownCommand(m));
  if (!std::isfinite(asked)) return;
  const double command = m.config.range.clip(asked);
  if (command != asked) {
    if (!m.out_of_range)
      ROS_WARN("nscd_actuator_markers: %s command %g %s is outside its range [%g, %g]: clipped to %g",
               m.config.actuator.c_str(), m.display * asked, m.unit.c_str(), m.display * m.config.range.min,
               m.display * m.config.range.max, m.display * command);
    m.out_of_range = true;
    // The marker back inside the range (RViz applies it when the drag ends).
    server_.setPose(m.config.actuator, toPose(m.handle.poseAt(command)));
  } else {
    m.out_of_range = false;
  }
  server_.applyChanges();  // other viewers see the marker move (the server took the pose)
  m.target = command;
  std_msgs::Float64 msg;
  msg.data = command;
  m.command_pub.publish(msg);
}

void ActuatorMarkers::onCommand(size_t i, const std_msgs::Float64ConstPtr& msg) {
  if (std::isfinite(msg->data)) markers_[i].target = msg->data;
}

void ActuatorMarkers::onKeyFigures(const nscd_sim::KeyFiguresConstPtr& msg) {
  if (msg->names.size() != msg->values.size()) return;
  // Sim time going back: ~reset. The commands are the initial ones again.
  if (msg->sim_time < last_sim_time_)
    for (Marker& m : markers_) m.target = NAN;
  last_sim_time_ = msg->sim_time;
  const auto value = [&msg](const std::string& name) {
    const auto it = std::find(msg->names.begin(), msg->names.end(), name);
    return it == msg->names.end() ? NAN : msg->values[it - msg->names.begin()];
  };
  for (Marker& m : markers_) {
    m.applied = value(m.config.actuator + ".cmd");
    m.effort = value(m.config.actuator + ".effort");
    for (size_t k = 0; k < m.config.figures.size(); ++k) m.figure_values[k] = value(m.config.figures[k]);
  }
}

void ActuatorMarkers::refresh(const ros::WallTimerEvent&) {
  bool changed = false;
  for (Marker& m : markers_) {
    const std::string t = text(m);
    const double c = shownCommand(m);
    const bool moved = !m.dragging && !(c == m.shown_command);
    if (t == m.shown_text && !moved) continue;
    m.shown_text = t;
    // While dragged, the marker keeps the pose RViz gives it.
    InteractiveMarker im;
    if (m.dragging && server_.get(m.config.actuator, im)) {
      const geometry_msgs::Pose pose = im.pose;
      im = build(m, c);
      im.pose = pose;
    } else {
      im = build(m, c);
      m.shown_command = c;
    }
    server_.insert(im);
    changed = true;
  }
  if (changed) server_.applyChanges();
}

}  // namespace nscd_node
