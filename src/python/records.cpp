// Structured arrays from rows of doubles (records.hpp).
#include "records.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <set>
#include <stdexcept>

namespace py = pybind11;

namespace nscd_python {

py::array recordArray(const std::vector<Field>& fields, const std::vector<double>& values, size_t rows) {
  if (values.size() != rows * fields.size()) throw std::logic_error("recordArray: values do not fit");
  std::set<std::string> seen;
  py::list spec;
  for (const Field& f : fields) {
    if (!seen.insert(f.name).second)
      throw std::invalid_argument("two output fields are named '" + f.name +
                                  "': rename one of the scene's elements");
    const char* format = f.type == FieldType::Float64 ? "<f8" : f.type == FieldType::Int32 ? "<i4" : "?";
    spec.append(py::make_tuple(f.name, format));
  }
  py::module_ np = py::module_::import("numpy");
  py::object dtype = np.attr("dtype")(spec);
  py::array out = np.attr("zeros")(py::int_(rows), dtype);
  const py::ssize_t itemsize = out.itemsize();
  py::dict layout = dtype.attr("fields");
  std::vector<py::ssize_t> offsets;
  for (const Field& f : fields)
    offsets.push_back(py::cast<py::ssize_t>(py::tuple(layout[py::str(f.name)])[1]));
  auto* base = static_cast<char*>(out.mutable_data());
  const size_t n = fields.size();
  for (size_t r = 0; r < rows; ++r) {
    char* rec = base + r * itemsize;
    for (size_t c = 0; c < n; ++c) {
      const double v = values[r * n + c];
      char* at = rec + offsets[c];
      switch (fields[c].type) {
        case FieldType::Float64: std::memcpy(at, &v, sizeof v); break;
        case FieldType::Int32: {
          const int32_t i = static_cast<int32_t>(v);
          std::memcpy(at, &i, sizeof i);
          break;
        }
        case FieldType::Bool: *at = v != 0 ? 1 : 0; break;
      }
    }
  }
  return out;
}

py::array withNames(const py::array& records, const std::vector<std::string>& texts) {
  py::module_ np = py::module_::import("numpy");
  size_t width = 1;
  for (const std::string& t : texts) width = std::max(width, t.size());
  py::list spec;
  spec.append(py::make_tuple("name", "<U" + std::to_string(width)));
  py::object old = records.attr("dtype");
  for (py::handle name : old.attr("names")) spec.append(py::make_tuple(name, old[name]));
  py::array out = np.attr("zeros")(records.attr("shape"), np.attr("dtype")(spec));
  for (py::handle name : old.attr("names")) out[name] = records[name];
  py::list names;
  for (const std::string& t : texts) names.append(t);
  out[py::str("name")] = names;
  return out;
}

}  // namespace nscd_python
