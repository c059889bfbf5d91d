// State files (include/nscd_sim/state_file.hpp): keyed lines of hex floats, the
// model they belong to at the top, a checksum of everything above it at the end.
#include "nscd_sim/state_file.hpp"

#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <system_error>
#include <vector>

namespace nscd {
namespace {

constexpr const char* kMagic = "nscd-state 1";
constexpr int kBodyNumbers = 13;  // x y z, qw qx qy qz, vx vy vz, wx wy wz (body frame)

// 64-bit FNV-1a, continued from `h`.
std::uint64_t fnv1a(const std::string& s, std::uint64_t h = 0xcbf29ce484222325ULL) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::string hex64(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016" PRIx64, h);
  return buf;
}

// x bit for bit: "0x1.8p+1", "-0x1p-3", "0x0p+0", "nan" (locale-independent).
std::string hexFloat(double x) {
  char buf[64];
  char* p = buf;
  if (std::signbit(x)) *p++ = '-';  // a NaN keeps its sign too
  if (std::isfinite(x)) {
    *p++ = '0';
    *p++ = 'x';
  }
  const auto r = std::to_chars(p, buf + sizeof buf, std::fabs(x), std::chars_format::hex);
  return std::string(buf, r.ptr);
}

// A hex float as hexFloat writes it, or a decimal number (a hand-written state).
bool parseDouble(const std::string& word, double& x) {
  const char* b = word.data();
  const char* e = b + word.size();
  bool negative = false;
  if (b < e && (*b == '-' || *b == '+')) negative = *b++ == '-';
  std::from_chars_result r;
  if (e - b > 2 && b[0] == '0' && (b[1] == 'x' || b[1] == 'X'))
    r = std::from_chars(b + 2, e, x, std::chars_format::hex);
  else
    r = std::from_chars(b, e, x);
  if (r.ec != std::errc() || r.ptr != e || b == e) return false;
  if (negative) x = -x;
  return true;
}

// The state's sizes and the model's names: the first lines after the magic one.
struct StateShape {
  std::string fingerprint;
  size_t bodies = 0, joints = 0, clearance_joints = 0, contacts = 0, actuators = 0;
  size_t warm = 0, bilateral = 0, ring_hint = 0;

  static StateShape of(const Simulator& sim) {
    const Model& m = sim.model();
    const State& s = sim.state();
    StateShape sh;
    sh.fingerprint = stateFingerprint(m);
    sh.bodies = m.bodies.size();
    sh.joints = m.joints.size();
    sh.clearance_joints = m.clearance_joints.size();
    sh.contacts = m.contacts.size();
    sh.actuators = m.actuators.size();
    sh.warm = s.warm.size();
    sh.bilateral = s.warm_bilateral.size();
    sh.ring_hint = s.ring_hint.size();
    return sh;
  }
  std::string modelLine() const {
    std::ostringstream o;
    o << "model " << fingerprint << " bodies " << bodies << " joints " << joints << " clearance_joints "
      << clearance_joints << " contacts " << contacts << " actuators " << actuators;
    return o.str();
  }
  std::string sizesLine() const {
    std::ostringstream o;
    o << "sizes warm " << warm << " bilateral " << bilateral << " ring_hint " << ring_hint;
    return o.str();
  }
};

// ------------------------------------------------------------------ reading

// The file's lines (the checksum line's excepted), read one at a time; errors
// name the file and the line.
class LineReader {
 public:
  LineReader(const std::string& path, std::vector<std::string> lines) : path_(path), lines_(std::move(lines)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw StateFileError(path_ + ":" + std::to_string(line_) + ": " + what);
  }

  // The next line that is not a comment, split into words; its first must be `key`.
  std::vector<std::string> next(const std::string& key) {
    do {
      if (static_cast<size_t>(line_) >= lines_.size()) {
        ++line_;
        fail("expected a '" + key + "' line, found the checksum line (lines missing)");
      }
      ++line_;
    } while (!lines_[line_ - 1].empty() && lines_[line_ - 1][0] == '#');
    std::vector<std::string> words;
    std::istringstream ws(lines_[line_ - 1]);
    for (std::string w; ws >> w;) words.push_back(w);
    if (words.empty() || words[0] != key)
      fail("expected a '" + key + "' line, found '" + (words.empty() ? std::string() : words[0]) + "'");
    return words;
  }

  // words[first..] as numbers, exactly n of them.
  std::vector<double> numbers(const std::vector<std::string>& words, size_t first, size_t n,
                              const std::string& what) const {
    if (words.size() - first != n)
      fail(what + " has " + std::to_string(words.size() - first) + " numbers, expected " + std::to_string(n));
    std::vector<double> v(n);
    for (size_t i = 0; i < n; ++i)
      if (!parseDouble(words[first + i], v[i])) fail(what + ": '" + words[first + i] + "' is not a number");
    return v;
  }

  // Only comments may follow the last key.
  void expectEnd() {
    while (static_cast<size_t>(line_) < lines_.size()) {
      const std::string& text = lines_[line_++];
      if (text.empty() || text[0] != '#') fail("a line after the state's last one ('joint_position')");
    }
  }

 private:
  std::string path_;
  std::vector<std::string> lines_;
  int line_ = 1;  // the magic line was read
};

// The file's lines but the last (the checksum's), once its first line and
// checksum are right; throws StateFileError.
std::vector<std::string> checkedLines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw StateFileError(path + ": cannot read the state file");
  std::ostringstream all;
  all << in.rdbuf();
  const std::string text = all.str();
  std::vector<std::string> lines;
  for (size_t a = 0; a < text.size();) {
    const size_t b = text.find('\n', a);
    lines.push_back(text.substr(a, b == std::string::npos ? std::string::npos : b - a));
    a = b == std::string::npos ? text.size() : b + 1;
  }
  const std::string where = path + ":" + std::to_string(lines.size()) + ": ";
  if (lines.empty() || lines[0] != kMagic)
    throw StateFileError(path + ":1: not a state file (its first line is not '" + std::string(kMagic) + "')");
  if (text.back() != '\n') throw StateFileError(where + "the file ends inside this line (truncated)");
  const std::string& last = lines.back();
  if (last.rfind("checksum ", 0) != 0)
    throw StateFileError(where + "the file ends before its 'checksum' line (truncated)");
  const size_t body = text.size() - last.size() - 1;
  if (last.substr(9) != hex64(fnv1a(text.substr(0, body))))
    throw StateFileError(where + "the checksum differs: the file was changed or damaged after it was written");
  lines.pop_back();
  return lines;
}

size_t count(LineReader& r, const std::vector<std::string>& words, size_t i, const std::string& key) {
  if (i + 1 >= words.size() || words[i] != key) r.fail("expected '" + key + " N'");
  size_t n = 0;
  const std::string& w = words[i + 1];
  const auto res = std::from_chars(w.data(), w.data() + w.size(), n);
  if (res.ec != std::errc() || res.ptr != w.data() + w.size()) r.fail("'" + key + " " + w + "': not a count");
  return n;
}

// "file: N, this scene: M" for each count that differs.
void checkCount(LineReader& r, const char* what, size_t file, size_t scene) {
  if (file != scene)
    r.fail(std::string("the state was written for another scene: ") + std::to_string(file) + " " + what +
           " in the file, " + std::to_string(scene) + " in this scene");
}

void checkFinite(LineReader& r, const std::vector<double>& v, const std::string& what) {
  for (size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) r.fail(what + ": value " + std::to_string(i) + " is not finite");
}

// The model and sizes lines, checked against the scene.
void readShape(LineReader& r, const StateShape& want) {
  std::vector<std::string> w = r.next("model");
  if (w.size() != 12) r.fail("expected 'model FINGERPRINT bodies N joints N clearance_joints N contacts N actuators N'");
  StateShape got;
  got.fingerprint = w[1];
  got.bodies = count(r, w, 2, "bodies");
  got.joints = count(r, w, 4, "joints");
  got.clearance_joints = count(r, w, 6, "clearance_joints");
  got.contacts = count(r, w, 8, "contacts");
  got.actuators = count(r, w, 10, "actuators");
  checkCount(r, "bodies", got.bodies, want.bodies);
  checkCount(r, "joints", got.joints, want.joints);
  checkCount(r, "clearance joints", got.clearance_joints, want.clearance_joints);
  checkCount(r, "named contacts", got.contacts, want.contacts);
  checkCount(r, "actuators", got.actuators, want.actuators);
  if (got.fingerprint != want.fingerprint)
    r.fail("the state was written for another scene: the names of its bodies, joints, contacts or actuators "
           "differ (fingerprint " + got.fingerprint + ", this scene " + want.fingerprint + ")");
  w = r.next("sizes");
  if (w.size() != 7) r.fail("expected 'sizes warm N bilateral N ring_hint N'");
  got.warm = count(r, w, 1, "warm");
  got.bilateral = count(r, w, 3, "bilateral");
  got.ring_hint = count(r, w, 5, "ring_hint");
  checkCount(r, "contact slots", got.warm, want.warm);
  checkCount(r, "bilateral rows", got.bilateral, want.bilateral);
  checkCount(r, "ring hints", got.ring_hint, want.ring_hint);
}

// One "KEY v1 ... vn" line of n finite numbers.
std::vector<double> readVector(LineReader& r, const std::string& key, size_t n) {
  const std::vector<std::string> w = r.next(key);
  std::vector<double> v = r.numbers(w, 1, n, "'" + key + "'");
  if (key != "ring_hint") checkFinite(r, v, "'" + key + "'");
  return v;
}

void readBodies(LineReader& r, State& s, size_t n) {
  s.bodies.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const std::string what = "body " + std::to_string(i);
    const std::vector<std::string> w = r.next("body");
    if (w.size() < 2 || w[1] != std::to_string(i)) r.fail("expected '" + what + "'");
    const std::vector<double> v = r.numbers(w, 2, kBodyNumbers, what);
    checkFinite(r, v, what);
    BodyState& b = s.bodies[i];
    b.x = Vec3(v[0], v[1], v[2]);
    b.q = Quat(v[3], v[4], v[5], v[6]);
    b.v = Vec3(v[7], v[8], v[9]);
    b.w = Vec3(v[10], v[11], v[12]);
    if (std::abs(b.q.norm() - 1) > 1e-9) r.fail(what + ": its quaternion is not of unit length");
  }
}

void readWarm(LineReader& r, State& s, size_t n) {
  s.warm.resize(n);
  s.warm_valid.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const std::string what = "warm " + std::to_string(i);
    const std::vector<std::string> w = r.next("warm");
    if (w.size() < 2 || w[1] != std::to_string(i)) r.fail("expected '" + what + "'");
    if (w.size() != 6) r.fail(what + ": expected 3 numbers and 0 or 1");
    const std::vector<double> v = r.numbers({w.begin(), w.end() - 1}, 2, 3, what);
    checkFinite(r, v, what);
    s.warm[i] = Vec3(v[0], v[1], v[2]);
    if (w[5] != "0" && w[5] != "1") r.fail(what + ": '" + w[5] + "' is not 0 or 1");
    s.warm_valid[i] = w[5] == "1";
  }
}

double readScalar(LineReader& r, const std::string& key) { return readVector(r, key, 1)[0]; }

// ------------------------------------------------------------------ writing

void writeVector(std::ostream& o, const char* key, const std::vector<double>& v) {
  o << key;
  for (double x : v) o << ' ' << hexFloat(x);
  o << '\n';
}

}  // namespace

std::string stateFingerprint(const Model& m) {
  std::string names;
  auto add = [&](const char* kind, const std::string& name) { names += std::string(kind) + ' ' + name + '\n'; };
  for (const Body& b : m.bodies) add("body", b.name);
  for (const Joint& j : m.joints) add("joint", j.name);
  for (const ClearanceJoint& c : m.clearance_joints) add("clearance_joint", c.name);
  for (const ContactPair& c : m.contacts) add("contact", c.name);
  for (const Actuator& a : m.actuators) add("actuator", a.name);
  return hex64(fnv1a(names));
}

std::string stateChecksumLine(const std::string& text) { return "checksum " + hex64(fnv1a(text)) + '\n'; }

void writeStateFile(const std::string& path, const Simulator& sim, const std::string& note) {
  const State& s = sim.state();
  std::ostringstream o;
  o << kMagic << '\n';
  if (!note.empty()) {
    std::istringstream lines(note);  // one comment line per line of the note
    for (std::string l; std::getline(lines, l);) o << "# " << l << '\n';
  }
  const StateShape shape = StateShape::of(sim);
  o << shape.modelLine() << '\n' << shape.sizesLine() << '\n';
  o << "t " << hexFloat(s.t) << '\n';
  o << "step_next " << hexFloat(s.step_next) << '\n';
  o << "step_error " << hexFloat(s.step_error) << '\n';
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    const BodyState& b = s.bodies[i];
    o << "body " << i;
    for (double x : {b.x.x(), b.x.y(), b.x.z(), b.q.w(), b.q.x(), b.q.y(), b.q.z(), b.v.x(), b.v.y(), b.v.z(),
                     b.w.x(), b.w.y(), b.w.z()})
      o << ' ' << hexFloat(x);
    o << '\n';
  }
  writeVector(o, "commands", s.commands);
  writeVector(o, "prev_commands", s.prev_commands);
  for (size_t i = 0; i < s.warm.size(); ++i)
    o << "warm " << i << ' ' << hexFloat(s.warm[i].x()) << ' ' << hexFloat(s.warm[i].y()) << ' '
      << hexFloat(s.warm[i].z()) << ' ' << (s.warm_valid[i] ? 1 : 0) << '\n';
  writeVector(o, "bilateral", s.warm_bilateral);
  writeVector(o, "ring_hint", s.ring_hint);
  writeVector(o, "joint_position", s.joint_position);
  const std::string text = o.str();
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f) throw StateFileError(path + ": cannot write the state file");
  f << text << stateChecksumLine(text);
  f.close();
  if (!f) throw StateFileError(path + ": writing the state file failed");
}

State readStateFile(const std::string& path, const Simulator& sim) {
  LineReader r(path, checkedLines(path));
  const StateShape want = StateShape::of(sim);
  const State& now = sim.state();
  readShape(r, want);
  State s;
  s.t = readScalar(r, "t");
  // The front ends count steps from t as a long (nscd_run's clock, the Python
  // module's step count): t = 1e300 made nscd_run convert 1e305 to a long.
  const double dt = sim.model().settings.dt;
  if (!(std::abs(s.t) / dt < 0x1p62)) {
    std::ostringstream o;
    o << "t = " << s.t << " s is beyond this run's step count (|t| / dt >= 2^62, dt = " << dt << " s)";
    r.fail(o.str());
  }
  s.step_next = readScalar(r, "step_next");
  if (s.step_next < 0) r.fail("step_next must be >= 0");
  s.step_error = readScalar(r, "step_error");
  if (s.step_error < 0) r.fail("step_error must be >= 0");
  readBodies(r, s, want.bodies);
  s.commands = readVector(r, "commands", now.commands.size());
  s.prev_commands = readVector(r, "prev_commands", now.prev_commands.size());
  readWarm(r, s, want.warm);
  s.warm_bilateral = readVector(r, "bilateral", want.bilateral);
  s.ring_hint = readVector(r, "ring_hint", want.ring_hint);
  for (size_t i = 0; i < s.ring_hint.size(); ++i)
    if (std::isinf(s.ring_hint[i])) r.fail("'ring_hint': value " + std::to_string(i) + " is infinite");
  s.joint_position = readVector(r, "joint_position", now.joint_position.size());
  r.expectEnd();
  return s;
}

void loadStateFile(const std::string& path, Simulator& sim) {
  State s = readStateFile(path, sim);
  sim.setState(s);
}

}  // namespace nscd
