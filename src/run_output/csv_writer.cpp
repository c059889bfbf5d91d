#include "csv_writer.hpp"

#include <stdexcept>

namespace nscd {

CsvWriter::CsvWriter(const std::string& path, const Simulator& sim) {
  f_ = std::fopen(path.c_str(), "w");
  if (!f_) throw std::runtime_error(path + ": cannot open for writing");
  const Model& m = sim.model();
  std::fprintf(f_, "t");
  for (const Body& b : m.bodies)
    for (const char* c : {"x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "wx", "wy", "wz"})
      std::fprintf(f_, ",%s.%s", b.name.c_str(), c);
  for (const Joint& j : m.joints)
    if (j.type != JointType::Fixed) std::fprintf(f_, ",%s.q", j.name.c_str());
  for (const ClearanceJoint& cj : m.clearance_joints)
    std::fprintf(f_, ",%s.ecc,%s.ecc_angle,%s.fn", cj.name.c_str(), cj.name.c_str(), cj.name.c_str());
  for (const ContactPair& c : m.contacts)
    std::fprintf(f_, ",%s.gap,%s.fn,%s.ft", c.name.c_str(), c.name.c_str(), c.name.c_str());
  for (const Spring& s : m.springs) std::fprintf(f_, ",%s.force", s.name.c_str());
  for (const Actuator& a : m.actuators) std::fprintf(f_, ",%s.cmd,%s.effort", a.name.c_str(), a.name.c_str());
  std::fprintf(f_, ",iters,residual");
  adaptive_ = m.settings.step_control == StepControl::Adaptive;
  if (adaptive_) std::fprintf(f_, ",h,error,rejected,extrapolated");
  std::fprintf(f_, "\n");
}

CsvWriter::~CsvWriter() {
  if (f_) std::fclose(f_);
}

void CsvWriter::writeRow(const Simulator& sim) {
  const Model& m = sim.model();
  const State& s = sim.state();
  std::fprintf(f_, "%.10g", s.t);
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    const BodyState& b = s.bodies[i];
    const Vec3 w = b.q * b.w;
    std::fprintf(f_, ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g",
                 b.x.x(), b.x.y(), b.x.z(), b.q.w(), b.q.x(), b.q.y(), b.q.z(), b.v.x(), b.v.y(),
                 b.v.z(), w.x(), w.y(), w.z());
  }
  for (size_t j = 0; j < m.joints.size(); ++j)
    if (m.joints[j].type != JointType::Fixed) std::fprintf(f_, ",%.12g", sim.jointPosition(j));
  for (size_t c = 0; c < m.clearance_joints.size(); ++c)
    std::fprintf(f_, ",%.10g,%.10g,%.10g", sim.clearanceEccentricity(c),
                 sim.clearanceEccentricityAngle(c), sim.clearanceNormalForce(c));
  for (size_t c = 0; c < m.contacts.size(); ++c)
    std::fprintf(f_, ",%.10g,%.10g,%.10g", sim.contactGap(c), sim.contactNormalForce(c),
                 sim.contactTangentialForce(c));
  for (size_t i = 0; i < m.springs.size(); ++i) std::fprintf(f_, ",%.10g", sim.springForce(i));
  for (size_t i = 0; i < m.actuators.size(); ++i)
    std::fprintf(f_, ",%.10g,%.10g", sim.command(i), sim.actuatorEffort(i));
  const StepStats& st = sim.stats();
  std::fprintf(f_, ",%d,%.4g", st.iterations, st.residual);
  if (adaptive_) std::fprintf(f_, ",%.10g,%.4g,%d,%d", st.h, st.error, st.rejected, st.extrapolated ? 1 : 0);
  std::fprintf(f_, "\n");
}

}  // namespace nscd
