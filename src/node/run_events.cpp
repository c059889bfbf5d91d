// Events of a run (run_events.hpp).
#include "run_events.hpp"

#include <cmath>
#include <cstdlib>

#include "nscd_sim/key_figures.hpp"

namespace nscd_node {
namespace {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t");
  return s.substr(a, b - a + 1);
}

}  // namespace

bool parseEventDefinition(const std::string& text, const std::vector<std::string>& names,
                          EventDefinition& out, std::string& error) {
  const std::string form = " (expected \"LABEL: FIGURE > VALUE\" or \"LABEL: FIGURE < VALUE\", "
                           "FIGURE a key figure or a group BASE*.SUFFIX, e.g. \"C7 open: C7.gap > 1e-4\")";
  out = EventDefinition{};
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos) {
    error = "'" + text + "': no ':' after the label" + form;
    return false;
  }
  out.label = trim(text.substr(0, colon));
  const std::string cond = text.substr(colon + 1);
  const size_t op = cond.find_first_of("<>");
  if (out.label.empty() || op == std::string::npos) {
    error = "'" + text + "': " + (out.label.empty() ? "empty label" : "no '<' or '>'") + form;
    return false;
  }
  out.greater = cond[op] == '>';
  const std::string figure = trim(cond.substr(0, op));
  const std::string value = trim(cond.substr(op + 1));
  char* end = nullptr;
  out.threshold = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !std::isfinite(out.threshold)) {
    error = "'" + text + "': '" + value + "' is not a number" + form;
    return false;
  }
  const size_t star = figure.find('*');
  if (star == std::string::npos) {
    for (size_t i = 0; i < names.size(); ++i)
      if (names[i] == figure) out.figures.push_back(static_cast<int>(i));
  } else {
    const std::string base = figure.substr(0, star);
    const std::string suffix = figure.substr(star + 1);
    if (base.empty() || suffix.empty() || suffix[0] != '.' || suffix.find('*') != std::string::npos) {
      error = "'" + text + "': a group is BASE*.SUFFIX, e.g. C4*.gap" + form;
      return false;
    }
    for (size_t i = 0; i < names.size(); ++i) {
      const std::string& n = names[i];
      if (n.size() <= suffix.size() || n.compare(n.size() - suffix.size(), suffix.size(), suffix)) continue;
      const std::string stem = n.substr(0, n.size() - suffix.size());
      if (stem == base || stem.compare(0, base.size() + 1, base + "_") == 0)
        out.figures.push_back(static_cast<int>(i));
    }
  }
  if (out.figures.empty()) {
    error = "'" + text + "': no key figure '" + figure + "' in this scene" + form;
    return false;
  }
  return true;
}

std::vector<int> EventTracker::check(const nscd::Simulator& sim) {
  std::vector<int> now;
  for (size_t e = 0; e < events_.size(); ++e) {
    if (time_[e] >= 0) continue;
    const EventDefinition& d = events_[e];
    bool holds = true;
    for (int f : d.figures) {
      const double v = nscd::keyFigureValue(sim, f);
      if (!(d.greater ? v > d.threshold : v < d.threshold)) {  // NaN: does not hold
        holds = false;
        break;
      }
    }
    if (holds) {
      time_[e] = sim.state().t;
      now.push_back(static_cast<int>(e));
    }
  }
  return now;
}

std::vector<EventLabel> EventTracker::happened() const {
  std::vector<EventLabel> out;
  for (size_t e = 0; e < events_.size(); ++e)
    if (time_[e] >= 0) out.push_back({events_[e].label, time_[e]});
  return out;
}

}  // namespace nscd_node
