// Reading the XML of a scene: attribute readers and checks that fail with one
// "FILE:LINE: what" SceneError, against the scene vocabulary (scene_vocabulary.cpp).
// Internal to the engine.
#pragma once

#include <tinyxml2.h>

#include <limits>
#include <string>
#include <vector>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/types.hpp"
#include "number_text.hpp"

namespace nscd {

using tinyxml2::XMLAttribute;
using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Where errors point: the scene's name (file path).
struct Ctx {
  std::string file;
  [[noreturn]] void fail(int line, const std::string& what) const {
    if (line > 0) throw SceneError(file + ":" + std::to_string(line) + ": " + what);
    throw SceneError(file + ": " + what);
  }
};

std::string tag(const XMLElement* e);      // "<name>"
std::string squote(const std::string& s);  // "'s'"
bool blank(const std::string& s);          // only white space

// The vocabulary entry of an element (variant: its type, for elements whose
// attributes depend on it); the loader checks against it (scene_vocabulary.cpp).
const SceneElementVocabulary& vocabularyOf(const std::string& element,
                                           const std::string& variant = "");
// Every attribute of e in `allowed` / every child element in `allowed`.
void checkAttributes(const Ctx& c, const XMLElement* e, const std::vector<std::string>& allowed);
void checkChildren(const Ctx& c, const XMLElement* e, const std::vector<std::string>& allowed);
// Both, against the vocabulary entry of `element` (and `variant`).
void checkElement(const Ctx& c, const XMLElement* e, const std::string& element,
                  const std::string& variant = "");

double toNumber(const Ctx& c, const XMLElement* e, const char* name, const std::string& v);
bool has(const XMLElement* e, const char* name);
std::string reqString(const Ctx& c, const XMLElement* e, const char* name);
double optNumber(const Ctx& c, const XMLElement* e, const char* name, double def);
double reqNumber(const Ctx& c, const XMLElement* e, const char* name);
Vec3 toVec3(const Ctx& c, const XMLElement* e, const char* name, const std::string& v);
Vec3 optVec3(const Ctx& c, const XMLElement* e, const char* name, const Vec3& def);
Vec3 reqVec3(const Ctx& c, const XMLElement* e, const char* name);
int optInt(const Ctx& c, const XMLElement* e, const char* name, int def);
// URDF roll-pitch-yaw (fixed axes x, y, z): R = Rz(yaw) Ry(pitch) Rx(roll).
Quat rpyToQuat(const Vec3& rpy);
// The optional single <origin xyz rpy> child of e.
Pose originChild(const Ctx& c, const XMLElement* e);
// x within (lo | [lo, hi) | hi]; "must be > lo" when hi is infinite.
void requireRange(const Ctx& c, const XMLElement* e, const char* name, double x, double lo,
                  bool lo_open, double hi, bool hi_open);

}  // namespace nscd
