// Fuzz target: FCLib files as nscd_fclib reads them (tools/fclib/read_fclib_problem.cpp:
// the HDF5 check of what FCLib will read, FCLib's own reader, the checks of what it
// returns, a global problem condensed to H^T M^-1 H). The input does not become the
// file's bytes: it chooses what an HDF5 file written here holds (FileWriter): which
// groups and datasets (a group where a dataset belongs, a text where numbers do),
// their lengths (what the size fields call for, or not) and their values (sizes,
// pointers, indices, numbers; consistent ones as often as not). Every file is
// well-formed HDF5: what is fuzzed is what FCLib and our checks make of its
// content. HDF5's parser of damaged bytes is not (docs/fuzzing.md says why).
// Oracles: a file is refused with one line, or read into a consistent problem of
// finite numbers; FCLib exiting (an HDF5 call of its own failed) or reading past a
// buffer is a finding. Dense matrices are capped at 10^6 entries.
#include <fuzzer/FuzzedDataProvider.h>
#include <hdf5.h>
#include <hdf5_hl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "read_fclib_problem.hpp"

namespace {

// Writes the parts of an FCLib file, each as the input says: as FCLib writes it
// (the planned value and length), or absent, of another kind, length or value.
// A mode byte of 0 (also what an exhausted input gives) keeps to the plan, so an
// empty input is a consistent problem and each deviation is a byte away.
class FileWriter {
 public:
  explicit FileWriter(FuzzedDataProvider& in) : in_(in) {}

  // A group `name` in `loc` (or, rarely, a dataset or nothing there); its id or -1.
  hid_t group(hid_t loc, const char* name) {
    const uint8_t mode = in_.ConsumeIntegral<uint8_t>();
    if (mode >= 252) return -1;
    if (mode >= 248) {
      const int one = 1;
      const hsize_t n = 1;
      H5LTmake_dataset_int(loc, name, 1, &n, &one);
      return -1;
    }
    return H5Gcreate2(loc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  }

  // A numeric dataset of `length` values, value k planned as planned(k); returns
  // the values written (the planned ones if it was left out or is not numeric).
  template <class Planned>
  std::vector<double> numbers(hid_t loc, const char* name, long length, bool ints, Planned planned) {
    std::vector<double> plan(std::max(0L, length));
    for (long k = 0; k < length; ++k) plan[k] = planned(k);
    const uint8_t mode = in_.ConsumeIntegral<uint8_t>();
    if (mode >= 250) return plan;  // absent
    if (mode >= 247) {             // a group where the dataset belongs
      H5Gclose(H5Gcreate2(loc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
      return plan;
    }
    if (mode >= 244) {  // a text
      H5LTmake_dataset_string(loc, name, "1");
      return plan;
    }
    std::vector<double> values = plan;
    if (mode >= 224) values.resize(in_.ConsumeIntegralInRange<long>(0, 40), 0.0);  // another length
    const bool garble = mode >= 160 && mode < 224;
    for (double& v : values) {
      if (!garble || in_.ConsumeBool()) continue;
      if (ints) v = in_.ConsumeBool() ? in_.ConsumeIntegralInRange<int>(-3, 12) : in_.ConsumeIntegral<int>();
      else v = in_.ConsumeBool() ? in_.ConsumeIntegralInRange<int>(-2, 4) : in_.ConsumeFloatingPoint<double>();
    }
    if (mode >= 128 && mode < 160) ints = !ints;  // the other numeric type (HDF5 converts it)
    const hsize_t n = values.size();
    if (ints) {
      std::vector<int> iv(values.size() + 1);
      for (size_t k = 0; k < values.size(); ++k)
        iv[k] = std::isfinite(values[k]) ? static_cast<int>(std::clamp(values[k], -2e9, 2e9)) : 0;
      H5LTmake_dataset_int(loc, name, 1, &n, iv.data());
    } else {
      values.push_back(0);  // a buffer even for no values
      H5LTmake_dataset_double(loc, name, 1, &n, values.data());
      values.pop_back();
    }
    return values;
  }

  // One integer (a size field): the value written, or the planned one.
  int integer(hid_t loc, const char* name, int planned) {
    const std::vector<double> v = numbers(loc, name, 1, true, [&](long) { return planned; });
    return v.size() == 1 && std::isfinite(v[0]) ? static_cast<int>(std::clamp(v[0], -2e9, 2e9)) : planned;
  }

  // A text dataset, or something else there, or nothing.
  void text(hid_t loc, const char* name) {
    const uint8_t mode = in_.ConsumeIntegral<uint8_t>();
    if (mode < 128) H5LTmake_dataset_string(loc, name, in_.ConsumeBytesAsString(12).c_str());
    else if (mode < 240) return;
    else numbers(loc, name, 2, true, [](long) { return 1; });
  }

  // A matrix group as FCLib writes it: planned rows x cols with `diagonal` entries
  // on the diagonal (so M is positive definite), in a storage the input picks.
  void matrix(hid_t parent, const char* name, int rows, int cols) {
    const hid_t g = group(parent, name);
    if (g < 0) return;
    const int storage = in_.ConsumeIntegralInRange<int>(-2, 0);  // -2 rows, -1 columns, 0 triplets
    const int diagonal = std::min(rows, cols);
    const int nzmax = integer(g, "nzmax", diagonal), m = integer(g, "m", rows), n = integer(g, "n", cols);
    const int nz = integer(g, "nz", storage == 0 ? diagonal : storage);
    const int cap = 64;  // lengths the size fields call for, bounded here
    const long pointers = nz >= 0 ? nz : nz == -1 ? n + 1L : m + 1L;
    const long indices = nz >= 0 ? nz : nzmax;
    const auto bounded = [&](long length) { return std::clamp(length, 0L, static_cast<long>(cap)); };
    numbers(g, "p", bounded(pointers), true, [&](long k) { return nz >= 0 ? k : std::min<long>(k, diagonal); });
    numbers(g, "i", bounded(indices), true, [](long k) { return k; });
    numbers(g, "x", bounded(nzmax), false, [](long k) { return 2.0 + k; });
    if (in_.ConsumeBool()) {  // matrix info
      numbers(g, "conditioning", 1, false, [](long) { return 10.0; });
      text(g, "comment");
      numbers(g, "determinant", 1, false, [](long) { return 1.0; });
      numbers(g, "rank", 1, true, [&](long) { return diagonal; });
    }
    H5Gclose(g);
  }

  void info(hid_t main) {
    if (in_.ConsumeBool()) return;
    const hid_t g = group(main, "info");
    if (g < 0) return;
    for (const char* name : {"title", "description", "math_info"}) text(g, name);
    H5Gclose(g);
  }

  // /fclib_local: W of `contacts` contacts of `dim` rows, perhaps V and R, vectors, info.
  void local(hid_t file) {
    const hid_t main = group(file, "fclib_local");
    if (main < 0) return;
    const int dim = integer(main, "spacedim", in_.ConsumeBool() ? 3 : 2);
    const int contacts = in_.ConsumeIntegralInRange<int>(1, 4), rows = std::clamp(dim, 1, 3) * contacts;
    matrix(main, "W", rows, rows);
    const bool bilateral = in_.ConsumeIntegral<uint8_t>() > 200;
    const int p = in_.ConsumeIntegralInRange<int>(1, 3);
    if (bilateral) {
      matrix(main, "V", rows, p);
      matrix(main, "R", p, p);
    }
    const hid_t v = group(main, "vectors");
    if (v >= 0) {
      numbers(v, "q", rows, false, [](long k) { return -0.1 * (k % 3 == 0); });
      numbers(v, "mu", contacts, false, [](long) { return 0.3; });
      if (bilateral) numbers(v, "s", p, false, [](long) { return 0.0; });
      H5Gclose(v);
    }
    info(main);
    H5Gclose(main);
  }

  // /fclib_global: M (velocities x velocities), H (velocities x dim contacts), perhaps G, vectors, info.
  void global(hid_t file) {
    const hid_t main = group(file, "fclib_global");
    if (main < 0) return;
    const int dim = integer(main, "spacedim", in_.ConsumeBool() ? 3 : 2);
    const int contacts = in_.ConsumeIntegralInRange<int>(1, 4), columns = std::clamp(dim, 1, 3) * contacts;
    const int velocities = in_.ConsumeIntegralInRange<int>(1, 8);
    matrix(main, "M", velocities, velocities);
    matrix(main, "H", velocities, columns);
    const bool equalities = in_.ConsumeIntegral<uint8_t>() > 220;
    if (equalities) matrix(main, "G", velocities, 1);
    const hid_t v = group(main, "vectors");
    if (v >= 0) {
      numbers(v, "f", velocities, false, [](long) { return -9.81; });
      numbers(v, "w", columns, false, [](long) { return 0.0; });
      numbers(v, "mu", contacts, false, [](long) { return 0.5; });
      if (equalities) numbers(v, "b", 1, false, [](long) { return 0.0; });
      H5Gclose(v);
    }
    info(main);
    H5Gclose(main);
  }

 private:
  FuzzedDataProvider& in_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = nscd_fuzz::scratchFile(nullptr, 0, ".hdf5");
  {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // a write refused (a bad length) is fine
    FuzzedDataProvider in(data, size);
    const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) nscd_fuzz::fail("cannot create " + path);
    FileWriter w(in);
    const bool local_first = in.ConsumeBool();
    if (local_first) w.local(file);
    if (!local_first || in.ConsumeIntegral<uint8_t>() > 240) w.global(file);
    H5Fclose(file);
  }
  nscd_fclib::LocalProblem p;
  std::string error;
  if (!nscd_fclib::readFclibProblem(path.c_str(), p, error, 1e6)) {
    nscd_fuzz::expectOneLine(error, "");
    return 0;
  }
  const Eigen::Index n = p.W.rows();
  if ((p.dim != 2 && p.dim != 3) || p.W.cols() != n || n != p.dim * static_cast<Eigen::Index>(p.contacts) ||
      p.q.size() != n || static_cast<int>(p.mu.size()) != p.contacts)
    nscd_fuzz::fail("a problem read with inconsistent sizes");
  if (!p.W.allFinite() || !p.q.allFinite()) nscd_fuzz::fail("a problem read with a number that is not finite");
  for (double mu : p.mu)
    if (!(std::isfinite(mu) && mu >= 0)) nscd_fuzz::fail("a problem read with a bad mu");
  return 0;
}
