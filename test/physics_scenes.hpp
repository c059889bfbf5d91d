// Scene texts for the physics tests, generated with the parameters each test needs.
#pragma once

#include <cmath>
#include <sstream>
#include <string>

namespace nscd_test {

inline std::string num(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// A sphere (radius r, mass m) whose lowest point is `height` above the plane z=0.
inline std::string ballScene(double height, double e, double mu, double dt,
                             const std::string& extra_sim = "") {
  const double r = 0.05, m = 1.0, I = 0.4 * m * r * r;
  return R"(<robot name="ball">
  <link name="world"/>
  <link name="ball"><inertial><mass value=")" + num(m) + R"("/><inertia ixx=")" + num(I) +
         R"(" iyy=")" + num(I) + R"(" izz=")" + num(I) + R"(" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="free" type="floating"><parent link="world"/><child link="ball"/>
    <origin xyz="0 0 )" + num(height + r) + R"("/></joint>
  <nscd><contact name="ground" mu=")" + num(mu) + R"(" e=")" + num(e) + R"(">
    <shape link="ball" type="sphere" radius=")" + num(r) + R"("/>
    <shape link="world" type="plane"/></contact></nscd>
  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 0 -9.81" )" + extra_sim + R"(/></nscd>
</robot>)";
}

// A 0.1 m cube of 1 kg resting on a plane tilted by `alpha` about x.
inline std::string slopeScene(double alpha, double mu, double dt) {
  const double h = 0.05, m = 1.0, I = m * (0.1 * 0.1 + 0.1 * 0.1) / 12.0;
  const double ny = -std::sin(alpha), nz = std::cos(alpha);
  return R"(<robot name="slope">
  <link name="world"/>
  <link name="block"><inertial><mass value=")" + num(m) + R"("/><inertia ixx=")" + num(I) +
         R"(" iyy=")" + num(I) + R"(" izz=")" + num(I) + R"(" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="free" type="floating"><parent link="world"/><child link="block"/>
    <origin xyz="0 )" + num(h * ny) + " " + num(h * nz) + R"(" rpy=")" + num(alpha) + R"( 0 0"/></joint>
  <nscd><contact name="slide" mu=")" + num(mu) + R"(" e="0">
    <shape link="block" type="box" size="0.1 0.1 0.1"/>
    <shape link="world" type="plane"><origin rpy=")" + num(alpha) + R"( 0 0"/></shape></contact></nscd>
  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 0 -9.81"/></nscd>
</robot>)";
}

// In the x-y plane (planar, gravity -y): a disc of radius r (mass m, I = m r^2/2)
// whose contact shape is its rim, a `ring`, on a `face` of length `len` (along
// the slope, centred at the origin) tilted up by alpha about z; the disc starts
// at rest touching the face `s0` up the slope from its centre.
inline std::string ringOnFaceScene(double r, double alpha, double len, double s0, double mu,
                                   double dt) {
  const double m = 0.1, I = 0.5 * m * r * r;
  const double ca = std::cos(alpha), sa = std::sin(alpha);
  const double cx = s0 * ca - r * sa, cy = s0 * sa + r * ca;  // on the slope, r along its normal
  return R"(<robot name="ring_on_face">
  <link name="world"/>
  <link name="disc"><inertial><mass value=")" + num(m) + R"("/><inertia ixx=")" + num(I) +
         R"(" iyy=")" + num(I) + R"(" izz=")" + num(I) + R"(" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="free" type="floating"><parent link="world"/><child link="disc"/>
    <origin xyz=")" + num(cx) + " " + num(cy) + R"( 0"/></joint>
  <nscd><contact name="rim" mu=")" + num(mu) + R"(" e="0">
    <shape link="disc" type="ring" radius=")" + num(r) + R"("/>
    <shape link="world" type="face" size=")" + num(len) + R"( 0.01"><origin rpy="-1.5707963267948966 0 )" +
         num(alpha) + R"("/></shape></contact></nscd>
  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 -9.81 0" planar="xy"/></nscd>
</robot>)";
}

// A pendulum: hinge about y at the origin, centre of mass `l` below, released at theta0.
inline std::string pendulumScene(double l, double m, double I, double theta0, double dt) {
  return R"(<robot name="pendulum">
  <link name="world"/>
  <link name="bob"><inertial><origin xyz="0 0 )" + num(-l) + R"("/><mass value=")" + num(m) +
         R"("/><inertia ixx=")" + num(I) + R"(" iyy=")" + num(I) + R"(" izz=")" + num(I) +
         R"(" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="world"/><child link="bob"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <nscd><initial joint="hinge" position=")" + num(theta0) + R"("/></nscd>
  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 0 -9.81"/></nscd>
</robot>)";
}

// Mass m on a prismatic joint along x, linear spring k to the origin, stretched by `stretch`.
inline std::string springMassScene(double m, double k, double stretch, double dt) {
  return R"(<robot name="spring_mass">
  <link name="world"/>
  <link name="mass"><inertial><mass value=")" + num(m) + R"("/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="slider" type="prismatic"><parent link="world"/><child link="mass"/><axis xyz="1 0 0"/>
    <origin xyz="0.5 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <nscd><spring name="spring" type="linear" stiffness=")" + num(k) + R"(" rest_length=")" +
         num(0.5 - stretch) + R"(" damping="0">
    <end link="world" xyz="0 0 0"/><end link="mass" xyz="0 0 0"/></spring></nscd>
  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 0 0"/></nscd>
</robot>)";
}

// A four-bar in the x-z plane (axes y): ground pivots (0,0,0) and (L0,0,0).
// Crank L1 at angle `phi` from +x; coupler L2; rocker L3 closed by a loop joint.
inline std::string fourBarScene(double phi, double crank_rate, double dt, double mismatch = 0) {
  const double L0 = 0.4, L1 = 0.1, L2 = 0.4, L3 = 0.3;
  // Angles in the x-z plane measured from +x about -y (so that z = L sin(angle)).
  const double Ax = L1 * std::cos(phi), Az = L1 * std::sin(phi);
  // Coupler end B on the circle of radius L3 around (L0,0), at distance L2 from A.
  const double dx = L0 - Ax, dz = -Az, d = std::hypot(dx, dz);
  const double a = (L2 * L2 - L3 * L3 + d * d) / (2 * d);
  const double hh = std::sqrt(std::max(0.0, L2 * L2 - a * a));
  const double Bx = Ax + a * dx / d - hh * dz / d, Bz = Az + a * dz / d + hh * dx / d;
  const double ang_coupler = std::atan2(Bz - Az, Bx - Ax);
  const double ang_rocker = std::atan2(Bz - 0.0, Bx - L0);
  // Rotation about +y by angle beta maps +x to (cos b, 0, -sin b): use beta = -angle.
  auto rod = [&](const std::string& name, double L, double m) {
    const double I = m * L * L / 12.0;
    return "<link name=\"" + name + "\"><inertial><origin xyz=\"" + num(L / 2) + " 0 0\"/><mass value=\"" +
           num(m) + "\"/><inertia ixx=\"1e-5\" iyy=\"" + num(I) + "\" izz=\"" + num(I) +
           "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>\n";
  };
  const double rel_coupler = ang_coupler - phi;
  // The loop joint's frame is its child link's frame (URDF meaning), so the loop
  // closes at a massless link fixed to the rocker's tip.
  return R"(<robot name="fourbar">
  <link name="world"/>
)" + rod("crank", L1, 0.1) + rod("coupler", L2, 0.4) + rod("rocker", L3, 0.3) +
         R"(  <link name="rocker_tip"/>
  <joint name="j1" type="continuous"><parent link="world"/><child link="crank"/><axis xyz="0 1 0"/>
    <origin rpy="0 )" + num(-phi) + R"( 0"/></joint>
  <joint name="j2" type="continuous"><parent link="crank"/><child link="coupler"/><axis xyz="0 1 0"/>
    <origin xyz=")" + num(L1) + R"( 0 0" rpy="0 )" + num(-rel_coupler) + R"( 0"/></joint>
  <joint name="j3" type="continuous"><parent link="world"/><child link="rocker"/><axis xyz="0 1 0"/>
    <origin xyz=")" + num(L0) + R"( 0 0" rpy="0 )" + num(-ang_rocker) + R"( 0"/></joint>
  <joint name="tip" type="fixed"><parent link="rocker"/><child link="rocker_tip"/>
    <origin xyz=")" + num(L3 + mismatch) + R"( 0 0"/></joint>
  <nscd><joint name="loop" type="revolute" parent="coupler" child="rocker_tip">
    <origin xyz=")" + num(L2) + R"( 0 0" rpy="0 )" + num(-(ang_rocker - ang_coupler)) + R"( 0"/><axis xyz="0 1 0"/></joint></nscd>
  <nscd><initial link="crank" wy=")" + num(-crank_rate) + R"("/></nscd>
  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 0 -9.81"/></nscd>
</robot>)";
}

}  // namespace nscd_test

namespace nscd_test {

// A sleeve (bearing) hanging on a fixed pin (journal, on ground) along x, with
// radial clearance cr. com_x: centre of mass offset along the axis.
inline std::string sleeveScene(double cr, double com_x, double mu, double gravity_z,
                               double dt, const std::string& extra = "") {
  const double m = 0.2, r = 5e-3;
  return R"(<robot name="sleeve">
  <link name="world"/>
  <link name="sleeve"><inertial><origin xyz=")" + num(com_x) + R"( 0 0"/><mass value=")" + num(m) +
         R"("/><inertia ixx="5e-6" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="pin" type="continuous"><parent link="world"/><child link="sleeve"/><axis xyz="1 0 0"/></joint>
  <nscd><clearance joint="pin" journal="parent" radius=")" + num(r) + R"(" radial=")" + num(cr) +
         R"(" length="20e-3" axial="0.2e-3" bumps="3" bump_radius="0.5e-3" mu=")" + num(mu) + R"(" e="0"/></nscd>
)" + extra + R"(  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 0 )" + num(gravity_z) + R"("/></nscd>
</robot>)";
}

// A pendulum in the x-y plane (point-like arm, centre of mass l below the hinge,
// gravity -y) on a revolute joint about z, optionally with clearance (cr > 0), released from theta0.
inline std::string clearancePendulumScene(double cr, double mu, double rj, double l,
                                          double theta0, double dt, bool projection = true,
                                          const std::string& planar = "false") {
  const double m = 0.1, I = 1e-6;
  std::string clearance;
  if (cr > 0)
    clearance = R"(  <nscd><clearance joint="hinge" journal="parent" radius=")" + num(rj) + R"(" radial=")" +
                num(cr) + R"(" length=")" + num(4 * rj) + R"(" axial="0.1e-3" mu=")" + num(mu) +
                R"(" e="0"/></nscd>
)";
  return R"(<robot name="clearance_pendulum">
  <link name="world"/>
  <link name="arm"><inertial><origin xyz="0 )" + num(-l) + R"( 0"/><mass value=")" + num(m) +
         R"("/><inertia ixx=")" + num(I) + R"(" iyy=")" + num(I) + R"(" izz=")" + num(I) +
         R"(" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="continuous"><parent link="world"/><child link="arm"/><axis xyz="0 0 1"/></joint>
)" + clearance + R"(  <nscd><initial joint="hinge" position=")" + num(theta0) + R"("/></nscd>
  <nscd><simulation dt=")" + num(dt) + R"(" gravity="0 -9.81 0" projection=")" +
         (projection ? "true" : "false") + R"(" planar=")" + planar + R"("/></nscd>
</robot>)";
}

// A bar (0.1 kg, 0.2 m, COM 0.1 m from the pivot; J about the hinge 3.3e-4 + 0.1 * 0.1^2)
// on a vertical hinge, no gravity; `nscd` is the whole content of its <nscd> (actuators,
// initial positions, <simulation>).
inline std::string crankScene(const std::string& nscd) {
  return R"(<?xml version="1.0"?>
<robot name="crank">
  <link name="world"/>
  <link name="bar">
    <inertial><origin xyz="0.1 0 0"/><mass value="0.1"/>
      <inertia ixx="1e-6" ixy="0" ixz="0" iyy="3.3e-4" iyz="0" izz="3.3e-4"/></inertial>
  </link>
  <joint name="hinge" type="continuous">
    <parent link="world"/><child link="bar"/><axis xyz="0 0 1"/>
  </joint>
  <nscd>)" + nscd + R"(</nscd>
</robot>)";
}

}  // namespace nscd_test
