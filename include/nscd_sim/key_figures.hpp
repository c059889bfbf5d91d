// The named figures of a simulation's current state, in a fixed order and with
// the names of nscd_run's CSV columns: per joint that is not fixed `J.q`; per
// clearance joint `J.ecc`, `J.ecc_angle`, `J.fn`; per named contact `C.gap`,
// `C.fn`, `C.ft`; per spring `S.force`; per actuator `A.cmd`, `A.effort`. The
// node publishes them on ~key_figures (plottable by name); units as in the CSV.
#pragma once

#include <string>
#include <vector>

#include "nscd_sim/simulator.hpp"

namespace nscd {

std::vector<std::string> keyFigureNames(const Model& model);

// The values, in the order of keyFigureNames; `values` is resized once, so
// repeated calls do not allocate.
void keyFigureValues(const Simulator& sim, std::vector<double>& values);

// One value (index into keyFigureNames) without computing the others (the node's
// event conditions are checked after every step). Throws std::out_of_range.
double keyFigureValue(const Simulator& sim, int index);

}  // namespace nscd
