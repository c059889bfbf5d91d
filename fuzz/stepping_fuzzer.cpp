// Fuzz target: a valid scene stepped with fuzzed settings and commands. The input
// is text, one instruction a line (others are ignored):
//   scene NAME          one of kScenes (default the first)
//   steps N             how many steps, at most 400 (default 200)
//   set KEY=VALUE       a setting override, as nscd_run --set
//   schedule NAME=t:v,. an actuator schedule, as nscd_run --command
//   command K A VALUE   before step K, actuator A's command := VALUE (the node's
//                       ~A/command topic; any double, NaN included)
//   reset K             before step K, back to the initial state (the node's ~reset)
// Overrides that are refused, or budgets too large to fuzz (fuzz_support.hpp),
// end the input. Then every step: no crash, no non-finite output unless the step
// says NonFinite (fuzz_support.hpp); libFuzzer's -timeout bounds the time.
#include <cstdint>
#include <cstdlib>
#include <map>
#include <sstream>
#include <string>

#include "fuzz_support.hpp"
#include "nscd_sim/scene_loader.hpp"

namespace {

// Small scenes (a step well under a millisecond), every kind of joint, contact,
// spring and actuator among them.
const char* const kScenes[][2] = {
    {"clearance_pendulum", "urdf/clearance_pendulum.urdf"},
    {"actuated_pendulum", "test/ros/actuated_pendulum.urdf"},
    {"slider_crank", "urdf/slider_crank.urdf"},
    {"fourbar", "urdf/fourbar.urdf"},
    {"journal", "urdf/journal.urdf"},
    {"spring_mass", "urdf/spring_mass.urdf"},
    {"slope", "urdf/slope.urdf"},
    {"ball", "urdf/ball.urdf"},
    {"pendulum", "urdf/pendulum.urdf"},
    {"symmetric_clearance_pendulum", "test/scenes/symmetric_clearance_pendulum.urdf"},
};

const std::map<std::string, std::string>& scenes() {
  static const std::map<std::string, std::string> texts = [] {
    std::map<std::string, std::string> t;
    for (const auto& s : kScenes) t[s[0]] = nscd_fuzz::repoFile(s[1]);
    return t;
  }();
  return texts;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string scene = kScenes[0][0];
  int steps = 200;
  std::vector<nscd::SettingOverride> overrides;
  std::vector<std::string> schedules;
  std::vector<nscd_fuzz::SteppingCommand> commands;
  std::vector<int> resets;
  for (const std::string& line : nscd_fuzz::lines(data, size)) {
    std::istringstream in(line);
    std::string word, rest;
    in >> word;
    std::getline(in >> std::ws, rest);
    if (word == "scene" && scenes().count(rest)) {
      scene = rest;
    } else if (word == "steps") {
      steps = std::max(0, std::min(400, std::atoi(rest.c_str())));
    } else if (word == "set") {
      const size_t eq = rest.find('=');
      if (eq != std::string::npos && eq > 0) overrides.push_back({rest.substr(0, eq), rest.substr(eq + 1), "set"});
    } else if (word == "schedule") {
      schedules.push_back(rest);
    } else if (word == "command") {
      nscd_fuzz::SteppingCommand c;
      std::istringstream args(rest);
      std::string value;
      if (args >> c.step >> c.actuator >> value) {
        c.value = std::strtod(value.c_str(), nullptr);
        commands.push_back(c);
      }
    } else if (word == "reset") {
      resets.push_back(std::atoi(rest.c_str()));
    }
  }
  nscd::Model model;
  try {
    model = nscd::loadSceneFromString(scenes().at(scene), scene + ".urdf", overrides);
  } catch (const nscd::SceneError& e) {
    nscd_fuzz::expectOneLine(e.what(), "");
    return 0;
  }
  if (!nscd_fuzz::boundedBudget(model.settings)) return 0;
  nscd_fuzz::stepAndCheck(std::move(model), steps, commands, schedules, resets);
  return 0;
}
