// Events of a run shown in the 3D view once they happen ("latch released t=8.43
// ms"): a label and a condition on key figures, checked after every step; the
// first step at which the condition holds fixes the event's time, until ~reset.
//
// Definition (the node's ~events parameter, one string per event):
//   "LABEL: FIGURE > VALUE"  or  "LABEL: FIGURE < VALUE"
// FIGURE is a key-figure name (C7.gap, J4.ecc, probe.effort, ...) or a group
// BASE*.SUFFIX: BASE.SUFFIX and every BASE_<anything>.SUFFIX (the scripts' contact
// groups: C4*.gap is C4.gap, C4_2.gap, C4_F1.gap, C4_3.gap, ...); the condition
// holds when every figure of the group satisfies it. ROS-free.
#pragma once

#include <string>
#include <vector>

#include "contact_markers.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd_node {

struct EventDefinition {
  std::string label;
  std::vector<int> figures;  // indices into nscd::keyFigureNames
  bool greater = true;       // FIGURE > VALUE (else <)
  double threshold = 0;
};

// Parses one definition against the scene's key-figure names; false with a
// one-line `error` (what is wrong and what was expected) if it cannot be used.
bool parseEventDefinition(const std::string& text, const std::vector<std::string>& figure_names,
                          EventDefinition& out, std::string& error);

class EventTracker {
 public:
  explicit EventTracker(std::vector<EventDefinition> events = {}) : events_(std::move(events)) {
    time_.assign(events_.size(), -1.0);
  }
  // After a step: fixes the time of each event whose condition first holds;
  // returns the indices of the events that happened now.
  std::vector<int> check(const nscd::Simulator& sim);
  void reset() { time_.assign(events_.size(), -1.0); }
  // The events that happened, in the order of their definitions.
  std::vector<EventLabel> happened() const;
  const std::vector<EventDefinition>& definitions() const { return events_; }
  bool empty() const { return events_.empty(); }

 private:
  std::vector<EventDefinition> events_;
  std::vector<double> time_;  // s; < 0: not yet
};

}  // namespace nscd_node
