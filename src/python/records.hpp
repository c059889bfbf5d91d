// NumPy structured arrays from rows of doubles: the one way the module hands out
// tables (Simulator.run's record, bodies(), contacts(), ...).
#pragma once

#include <string>
#include <vector>

#include <pybind11/numpy.h>

namespace nscd_python {

enum class FieldType { Float64, Int32, Bool };

struct Field {
  std::string name;
  FieldType type = FieldType::Float64;
};

// A structured array of `rows` records with these fields, from `values` (row-major,
// rows x fields.size(); integer and boolean fields hold exact small integers).
// Raises ValueError if two fields share a name.
pybind11::array recordArray(const std::vector<Field>& fields, const std::vector<double>& values,
                            size_t rows);

// Adds a fixed-width text field `name` holding `texts` (one per record) in front.
pybind11::array withNames(const pybind11::array& records, const std::vector<std::string>& texts);

}  // namespace nscd_python
