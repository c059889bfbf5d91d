#include "contact_markers.hpp"

#include <cmath>
#include <cstdio>

#include "label_layout.hpp"
#include "ros_conversions.hpp"

namespace nscd_node {

namespace {

using visualization_msgs::Marker;

constexpr int kCircleSegments = 48;
constexpr double kMaxDrawnEcc = 1.5;  // eccentricity arrows: at most 1.5 ring radii

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

void buildStatusMarker(double sim_time, double rtf, bool paused, const MarkerStyle& style,
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
  if (paused) std::snprintf(buf, sizeof buf, "t = %.3f ms   paused", 1e3 * sim_time);
  else std::snprintf(buf, sizeof buf, "t = %.3f ms   rtf %.3g", 1e3 * sim_time, rtf);
  std::string s = buf;
  if (style.force_scale > 0) {
    std::snprintf(buf, sizeof buf, "   arrows: 1 mm = %.3g N", 1e-3 / style.force_scale);
    s += buf;
  }
  if (style.ecc_scale > 0) {
    std::snprintf(buf, sizeof buf, "   eccentricity x%.3g", style.ecc_scale);
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
  v.journal_radius = j.radius;
  v.name = j.name;
  return v;
}

namespace {

// Not red: RViz draws URDF visuals without a material in red.
const std_msgs::ColorRGBA kGreen = rgba(0.1f, 0.9f, 0.2f);
const std_msgs::ColorRGBA kBlue = rgba(0.15f, 0.45f, 1.0f);
const std_msgs::ColorRGBA kYellow = rgba(1.0f, 0.85f, 0.1f);
const std_msgs::ColorRGBA kWhite = rgba(0.95f, 0.95f, 0.95f);
const std_msgs::ColorRGBA kGrey = rgba(0.75f, 0.75f, 0.75f, 0.9f);
const std_msgs::ColorRGBA kCyan = rgba(0.1f, 0.9f, 0.9f);
const std_msgs::ColorRGBA kMagenta = rgba(1.0f, 0.2f, 1.0f);

// A clearance joint not drawn: its journal fills its bearing (a stand-in).
bool isStandIn(const EccentricityView& v) {
  return v.journal_radius > 0 && !(v.radial < v.journal_radius);
}

// Appends the markers of one buildContactMarkers call to `out`, all with one
// style and stamp; its labels are laid out so that they neither overlap each other
// nor cover a ring (bearings close together, as the C-60's J3-J6 or the concentric
// J2/J7/S3, would otherwise pile their labels up).
class ContactMarkerWriter {
 public:
  ContactMarkerWriter(const MarkerStyle& style, const ros::Time& stamp,
                      visualization_msgs::MarkerArray& out)
      : style_(style),
        stamp_(stamp),
        out_(out),
        label_h_(style.label_size > 0 ? style.label_size : 3 * style.size),
        layout_(label_h_) {}

  // Keeps the labels off the drawn rings.
  void reserveRings(const std::vector<EccentricityView>& clearance) {
    if (!style_.labels) return;
    for (const EccentricityView& v : clearance)
      if (!isStandIn(v)) layout_.addRing(lifted(v.center), v.radial * style_.ecc_scale);
  }

  // Each contact's force arrows and point. Returns, per named source (`sources`
  // of them), the contact with the largest normal force (its label's place; -1: none).
  std::vector<int> addContacts(const std::vector<nscd::ContactReport>& contacts, size_t sources) {
    std::vector<int> strongest_pair(sources, -1);
    Marker m;
    for (size_t i = 0; i < contacts.size(); ++i) {
      const nscd::ContactReport& c = contacts[i];
      const int id = static_cast<int>(i);
      if (makeArrow(style_, stamp_, "normal_force", id, c.point,
                    style_.force_scale * c.fn * c.normal, kGreen, m))
        out_.markers.push_back(m);
      if (makeArrow(style_, stamp_, "tangential_force", id, c.point, style_.force_scale * c.ft,
                    c.sliding ? kYellow : kBlue, m))
        out_.markers.push_back(m);
      m = makeMarker(style_, stamp_, "contact_point", id, Marker::SPHERE);
      m.pose.position = toPoint(c.point);
      m.scale.x = m.scale.y = m.scale.z = style_.size;
      m.color = kWhite;
      out_.markers.push_back(m);
      if (!c.clearance && c.source >= 0 && c.source < static_cast<int>(strongest_pair.size()) &&
          c.fn > 0 && (strongest_pair[c.source] < 0 || c.fn > contacts[strongest_pair[c.source]].fn))
        strongest_pair[c.source] = id;
    }
    return strongest_pair;
  }

  // A label per named contact pair with its summed normal force, at the pair's
  // strongest contact (addContacts).
  void addContactLabels(const std::vector<nscd::ContactReport>& contacts,
                        const std::vector<int>& strongest_pair, const MarkerNames& names) {
    if (!style_.labels) return;
    char buf[48];
    for (size_t p = 0; p < strongest_pair.size(); ++p) {
      if (strongest_pair[p] < 0) continue;
      double fn = 0;  // the pair's summed normal force
      for (const nscd::ContactReport& c : contacts)
        if (!c.clearance && c.source == static_cast<int>(p)) fn += c.fn;
      std::snprintf(buf, sizeof buf, " %.2f N", fn);
      const std::string text = names.contacts[p] + buf;
      addLabel("contact_label", static_cast<int>(p),
               layout_.place(text, contactLabelPlaces(contacts[strongest_pair[p]], text)), text, kWhite);
    }
  }

  // Clearance joint `id`'s ring, eccentricity arrow and tip, and label.
  void addClearance(const EccentricityView& v, int id) {
    if (isStandIn(v)) return;
    const nscd::Vec3 e2 = v.axis.cross(v.ref);
    const double radius = v.radial * style_.ecc_scale;
    const nscd::Vec3 center = lifted(v.center);
    addRing(v, id, center, radius, e2);
    const nscd::Vec3 dir = std::cos(v.angle) * v.ref + std::sin(v.angle) * e2;
    // Drawn at most 1.5 ring radii long: a journal far outside its clearance (a
    // joint come apart) would otherwise draw a line across the whole scene; the
    // label then gives the value.
    const nscd::Vec3 tip = center + std::min(v.ecc, kMaxDrawnEcc) * radius * dir;
    addEccentricity(v, id, center, tip);
    if (style_.labels && !v.name.empty()) {
      char buf[80] = "";
      int n = v.fn > 0 ? std::snprintf(buf, sizeof buf, " %.2f N", v.fn) : 0;
      if (v.ecc > kMaxDrawnEcc) std::snprintf(buf + n, sizeof buf - n, " (e = %.3g c_r)", v.ecc);
      // Outside the ring, preferably opposite the eccentricity (the arrow side stays
      // free), else turned round the ring or further out, where no label is yet.
      const nscd::Vec3 side = v.ecc > 0.05 ? nscd::Vec3(-dir) : nscd::Vec3(-e2);
      const std::string text = v.name + buf;
      addLabel("clearance_label", id,
               layout_.place(text, layout_.aroundRing(center, radius, v.ref, e2, side, text)), text,
               v.fn > 0 ? kMagenta : kCyan);
    }
  }

 private:
  nscd::Vec3 lifted(nscd::Vec3 p) const {
    if (style_.have_marker_z) p.z() = style_.marker_z;
    return p;
  }

  void addLabel(const char* ns, int id, const nscd::Vec3& at, const std::string& text,
                const std_msgs::ColorRGBA& c) {
    Marker t = makeMarker(style_, stamp_, ns, id, Marker::TEXT_VIEW_FACING);
    t.pose.position = toPoint(lifted(at));
    t.scale.z = label_h_;
    t.color = c;
    t.text = text;
    out_.markers.push_back(t);
  }

  // A contact label's candidate places: beyond the arrow's tip, so the text does
  // not hide the arrow; further out along the arrow, or beside its tip, when that
  // place is taken.
  std::vector<nscd::Vec3> contactLabelPlaces(const nscd::ContactReport& c, const std::string& text) const {
    const nscd::Vec3 tip = c.point + style_.force_scale * c.fn * c.normal;
    std::vector<nscd::Vec3> at;
    for (int k = 0; k < 4; ++k) at.push_back(lifted(tip + (0.7 + 1.3 * k) * label_h_ * c.normal));
    const nscd::Vec3 side = c.normal.cross(nscd::Vec3::UnitZ());
    if (side.norm() > 1e-6) {
      const double off = labelBox(text, label_h_).half_width + 0.7 * label_h_;
      at.push_back(lifted(tip + off * side.normalized()));
      at.push_back(lifted(tip - off * side.normalized()));
    }
    return at;
  }

  // The clearance's limit: a circle of `radius` round `center` in the (ref, e2) plane.
  void addRing(const EccentricityView& v, int id, const nscd::Vec3& center, double radius,
               const nscd::Vec3& e2) {
    Marker m = makeMarker(style_, stamp_, "clearance_limit", id, Marker::LINE_STRIP);
    m.scale.x = 0.25 * style_.size;
    m.color = kGrey;
    for (int k = 0; k <= kCircleSegments; ++k) {
      const double a = 2.0 * M_PI * k / kCircleSegments;
      m.points.push_back(toPoint(center + radius * (std::cos(a) * v.ref + std::sin(a) * e2)));
    }
    out_.markers.push_back(m);
  }

  // The journal's offset: an arrow from the bearing centre to `tip` (a bare line
  // when too short for an arrow head), and a sphere at its tip.
  void addEccentricity(const EccentricityView& v, int id, const nscd::Vec3& center,
                       const nscd::Vec3& tip) {
    const std_msgs::ColorRGBA& c = v.fn > 0 ? kMagenta : kCyan;
    Marker m = makeMarker(style_, stamp_, "eccentricity", id, Marker::ARROW);
    m.points.push_back(toPoint(center));
    m.points.push_back(toPoint(tip));
    m.scale.x = 0.5 * style_.size;
    m.scale.y = 1.2 * style_.size;
    m.scale.z = std::min(1.2 * style_.size, 0.5 * (tip - center).norm());
    m.color = c;
    out_.markers.push_back(m);

    m = makeMarker(style_, stamp_, "eccentricity_tip", id, Marker::SPHERE);
    m.pose.position = toPoint(tip);
    m.scale.x = m.scale.y = m.scale.z = 0.8 * style_.size;
    m.color = c;
    out_.markers.push_back(m);
  }

  const MarkerStyle& style_;
  const ros::Time& stamp_;
  visualization_msgs::MarkerArray& out_;
  const double label_h_;
  LabelLayout layout_;
};

}  // namespace

void buildContactMarkers(const std::vector<nscd::ContactReport>& contacts,
                         const std::vector<EccentricityView>& clearance,
                         const MarkerStyle& style, const ros::Time& stamp,
                         visualization_msgs::MarkerArray& out, const MarkerNames& names) {
  out.markers.clear();
  out.markers.reserve(1 + 3 * contacts.size() + 5 * clearance.size());
  Marker clear = makeMarker(style, stamp, "", 0, Marker::SPHERE);
  clear.action = Marker::DELETEALL;
  out.markers.push_back(clear);
  ContactMarkerWriter writer(style, stamp, out);
  writer.reserveRings(clearance);
  const std::vector<int> strongest_pair = writer.addContacts(contacts, names.contacts.size());
  writer.addContactLabels(contacts, strongest_pair, names);
  for (size_t i = 0; i < clearance.size(); ++i) writer.addClearance(clearance[i], static_cast<int>(i));
}

void appendEventMarkers(const std::vector<EventLabel>& events, const MarkerStyle& style,
                        const StatusText& text, const ros::Time& stamp,
                        visualization_msgs::MarkerArray& out) {
  char buf[160];
  for (size_t k = 0; k < events.size(); ++k) {
    Marker m = makeMarker(style, stamp, "events", static_cast<int>(k), Marker::TEXT_VIEW_FACING);
    // The status text is two lines centred on its position, which RViz draws about 9
    // text heights apart: the list starts below the second line.
    m.pose.position.x = text.position.x();
    m.pose.position.y = text.position.y() - text.height * (6.5 + 1.6 * k);
    m.pose.position.z = text.position.z();
    m.scale.z = text.height;
    m.color = rgba(1.0f, 0.6f, 0.1f);
    std::snprintf(buf, sizeof buf, "%s  t = %.3f ms", events[k].label.c_str(), 1e3 * events[k].time);
    m.text = buf;
    out.markers.push_back(m);
  }
}

}  // namespace nscd_node
