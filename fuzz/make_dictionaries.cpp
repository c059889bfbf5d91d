// Writes the fuzz targets' dictionaries (libFuzzer -dict files) into a folder,
// from the loader's own tables: the scene vocabulary (every <nscd> element, its
// attributes and type values), the setting keys, plus the URDF elements the
// loader reads and the words of the other formats. Run by scripts/fuzz.sh.
//   make_dictionaries DIR   -> DIR/scene.dict settings.dict schedule.dict problem.dict stepping.dict
//                           state.dict
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "nscd_sim/scene_loader.hpp"

namespace {

const std::vector<std::string> kNumbers = {"0", "-0", "1", "-1", "0.5", "1e-3", "nan", "NaN", "inf", "-inf",
                                           "1e308", "-1e308", "1e-308", "4.9e-324", "1e400", "2147483648",
                                           "-2147483649", "9223372036854775808", "0x10", "1e", "."};

class Dict {
 public:
  void add(const std::string& word) { words_.insert(word); }
  void write(const std::string& path) const {
    std::ofstream out(path);
    for (const std::string& w : words_) {
      out << '"';
      for (unsigned char c : w) {
        if (c == '"' || c == '\\') out << '\\' << c;
        else if (c < 32 || c > 126) {
          char hex[8];
          std::snprintf(hex, sizeof hex, "\\x%02X", c);
          out << hex;
        } else out << c;
      }
      out << "\"\n";
    }
    if (!out) std::fprintf(stderr, "cannot write %s\n", path.c_str());
  }

 private:
  std::set<std::string> words_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_dictionaries DIR\n");
    return 2;
  }
  const std::string dir = argv[1];

  Dict scene;
  for (const nscd::SceneElementVocabulary& v : nscd::sceneVocabulary()) {
    scene.add("<" + v.element);
    scene.add("</" + v.element + ">");
    if (!v.variant.empty()) scene.add(" type=\"" + v.variant + "\"");
    for (const std::string& a : v.attributes) scene.add(" " + a + "=\"");
    for (const std::string& c : v.children) scene.add("<" + c);
  }
  // The URDF the loader reads (urdfdom and its own pre-pass).
  for (const char* e : {"robot", "link", "joint", "inertial", "mass", "inertia", "origin", "axis", "parent",
                        "child", "visual", "collision", "geometry", "box", "cylinder", "sphere", "mesh", "limit",
                        "dynamics", "mimic", "material", "color"}) {
    scene.add(std::string("<") + e);
    scene.add(std::string("</") + e + ">");
  }
  for (const char* a : {"name", "type", "value", "ixx", "ixy", "ixz", "iyy", "iyz", "izz", "xyz", "rpy", "link",
                        "size", "radius", "length", "filename", "lower", "upper", "effort", "velocity", "damping",
                        "friction"})
    scene.add(std::string(" ") + a + "=\"");
  for (const char* t : {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"})
    scene.add(std::string("type=\"") + t + "\"");
  for (const char* x : {"<?xml version=\"1.0\"?>", "/>", ">", "\"", "<!--", "-->", "&#10;", "&amp;", "<![CDATA["})
    scene.add(x);

  Dict settings;
  for (const std::string& k : nscd::settingKeys()) {
    scene.add(" " + k + "=\"");
    settings.add(k + "=");
    settings.add(k + ": ");
  }
  for (const char* w : {"true", "false", "yes", "no", "on", "off", "none", "moreau", "xy", "simulation:", "{", "}",
                        "[", "]", ", ", "- ", "---", "...", "&a ", "*a", "!!str ", "!!binary ", "? ", "|", ">",
                        "'", "\"", "#", "~", "null", "<<: "})
    settings.add(w);

  Dict schedule;
  for (const char* w : {"probe=", "handle=", "bar_seating=", "hinge_motor=", "push=", "table=", "=", ":", ","})
    schedule.add(w);

  Dict problem;
  for (const char* w : {"nscd-friction-contact-problem 1\n", "t ", " round ", " rows ", " blocks ", "residual ",
                        " converged ", " iterations ", "block F ", "block N ", "block B ", "\nW ", "\nb ",
                        "\nP_start ", "\nP "})
    problem.add(w);

  Dict stepping;
  for (const char* w : {"scene clearance_pendulum\n", "scene actuated_pendulum\n", "scene slider_crank\n",
                        "scene fourbar\n", "scene journal\n", "scene spring_mass\n", "scene slope\n", "scene ball\n",
                        "scene pendulum\n", "scene symmetric_clearance_pendulum\n", "steps ", "set ", "schedule ",
                        "command ", "reset ", "hinge_motor=", "push=", "\n"})
    stepping.add(w);
  for (const std::string& k : nscd::settingKeys()) stepping.add("set " + k + "=");

  // State files (src/engine/step/state_file.cpp): the keys, hex floats.
  Dict state;
  for (const char* w : {"nscd-state 1\n", "# ", "model ", " bodies ", " joints ", " clearance_joints ",
                        " contacts ", " actuators ", "sizes warm ", " bilateral ", " ring_hint ", "\nt ",
                        "\nstep_next ", "\nstep_error ", "\nbody ", "\ncommands", "\nprev_commands",
                        "\nwarm ", "\nbilateral", "\nring_hint", "\njoint_position", "\nchecksum ", " 0", " 1",
                        "0x1p+0", "-0x1p+0", "0x0p+0", "-0x0p+0", "0x1.fffffffffffffp+1023", "0x1p-1074",
                        "0x1p+1024", "0x1.6a09e667f3bcdp-1", "-nan", "0X1P+0", "0x.8p1", "0x1p", "p+"})
    state.add(w);

  for (const std::string& n : kNumbers) {
    for (Dict* d : {&scene, &settings, &schedule, &problem, &stepping, &state}) d->add(n);
  }
  scene.write(dir + "/scene.dict");
  settings.write(dir + "/settings.dict");
  schedule.write(dir + "/schedule.dict");
  problem.write(dir + "/problem.dict");
  stepping.write(dir + "/stepping.dict");
  state.write(dir + "/state.dict");
  return 0;
}
