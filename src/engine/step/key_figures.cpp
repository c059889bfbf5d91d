// The named figures of a simulation's state (key_figures.hpp).
#include "nscd_sim/key_figures.hpp"

#include <stdexcept>
#include <string>

namespace nscd {

std::vector<std::string> keyFigureNames(const Model& m) {
  std::vector<std::string> n;
  for (const Joint& j : m.joints)
    if (j.type != JointType::Fixed) n.push_back(j.name + ".q");
  for (const ClearanceJoint& cj : m.clearance_joints)
    for (const char* s : {".ecc", ".ecc_angle", ".fn"}) n.push_back(cj.name + s);
  for (const ContactPair& c : m.contacts)
    for (const char* s : {".gap", ".fn", ".ft"}) n.push_back(c.name + s);
  for (const Spring& s : m.springs) n.push_back(s.name + ".force");
  for (const Actuator& a : m.actuators)
    for (const char* s : {".cmd", ".effort"}) n.push_back(a.name + s);
  return n;
}

void keyFigureValues(const Simulator& sim, std::vector<double>& v) {
  const Model& m = sim.model();
  v.clear();  // keeps the capacity: no allocation after the first call
  for (size_t j = 0; j < m.joints.size(); ++j)
    if (m.joints[j].type != JointType::Fixed) v.push_back(sim.jointPosition(static_cast<int>(j)));
  for (size_t c = 0; c < m.clearance_joints.size(); ++c) {
    const int i = static_cast<int>(c);
    v.push_back(sim.clearanceEccentricity(i));
    v.push_back(sim.clearanceEccentricityAngle(i));
    v.push_back(sim.clearanceNormalForce(i));
  }
  for (size_t c = 0; c < m.contacts.size(); ++c) {
    const int i = static_cast<int>(c);
    v.push_back(sim.contactGap(i));
    v.push_back(sim.contactNormalForce(i));
    v.push_back(sim.contactTangentialForce(i));
  }
  for (size_t s = 0; s < m.springs.size(); ++s) v.push_back(sim.springForce(static_cast<int>(s)));
  for (size_t a = 0; a < m.actuators.size(); ++a) {
    v.push_back(sim.command(static_cast<int>(a)));
    v.push_back(sim.actuatorEffort(static_cast<int>(a)));
  }
}

double keyFigureValue(const Simulator& sim, int index) {
  const Model& m = sim.model();
  int k = index;
  if (k < 0) throw std::out_of_range("key figure index " + std::to_string(index));
  for (size_t j = 0; j < m.joints.size(); ++j)
    if (m.joints[j].type != JointType::Fixed && k-- == 0) return sim.jointPosition(static_cast<int>(j));
  if (k < 3 * static_cast<int>(m.clearance_joints.size())) {
    const int c = k / 3;
    return k % 3 == 0 ? sim.clearanceEccentricity(c)
                      : k % 3 == 1 ? sim.clearanceEccentricityAngle(c) : sim.clearanceNormalForce(c);
  }
  k -= 3 * static_cast<int>(m.clearance_joints.size());
  if (k < 3 * static_cast<int>(m.contacts.size())) {
    const int c = k / 3;
    return k % 3 == 0 ? sim.contactGap(c)
                      : k % 3 == 1 ? sim.contactNormalForce(c) : sim.contactTangentialForce(c);
  }
  k -= 3 * static_cast<int>(m.contacts.size());
  if (k < static_cast<int>(m.springs.size())) return sim.springForce(k);
  k -= static_cast<int>(m.springs.size());
  if (k < 2 * static_cast<int>(m.actuators.size()))
    return k % 2 == 0 ? sim.command(k / 2) : sim.actuatorEffort(k / 2);
  throw std::out_of_range("key figure index " + std::to_string(index));
}

}  // namespace nscd
