// The HDF5 check of an FCLib file (fclib_file_check.hpp). It follows fclib.h
// 3.1.0's fclib_read_local, fclib_read_global, read_matrix, read_*_vectors and
// read_problem_info step by step. FCLib tests for optional parts with
// `if (H5Lexists(..))` and `if (H5LTfind_dataset(..))`: an HDF5 error (negative)
// counts as present there, so it does here (present()), and the part must then
// be readable.
#include "fclib_file_check.hpp"

#include <hdf5.h>
#include <hdf5_hl.h>

#include <vector>

namespace nscd_fclib {
namespace {

// Closes an HDF5 file or group handle at the end of its scope.
struct Handle {
  hid_t id = -1;
  bool group = true;
  Handle(hid_t i, bool is_group) : id(i), group(is_group) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (id >= 0) group ? H5Gclose(id) : H5Fclose(id);
  }
};

// An optional part as FCLib tests for it: anything but 0, an error included.
bool present(htri_t found) { return found != 0; }

struct Checker {
  long max_length;
  std::string error;

  bool fail(const std::string& where, const std::string& what) {
    error = where + ": " + what;
    return false;
  }

  // A link `name` below `loc` that opens as a group (as H5Gopen in FCLib).
  static bool isGroup(hid_t loc, const char* name) {
    if (H5Lexists(loc, name, H5P_DEFAULT) <= 0) return false;
    const hid_t g = H5Gopen2(loc, name, H5P_DEFAULT);
    if (g < 0) return false;
    H5Gclose(g);
    return true;
  }

  // The dataset `name` in `loc`: its element count and class; false if it is not one.
  bool dataset(hid_t loc, const std::string& where, const char* name, hsize_t& count, H5T_class_t& cls,
               size_t& type_size) {
    int rank = -1;
    if (H5LTfind_dataset(loc, name) <= 0 || H5LTget_dataset_ndims(loc, name, &rank) < 0)
      return fail(where + "/" + name, "missing or not a dataset");
    if (rank < 0 || rank > H5S_MAX_RANK) return fail(where + "/" + name, "rank " + std::to_string(rank));
    std::vector<hsize_t> dims(static_cast<size_t>(rank) + 1, 0);
    if (H5LTget_dataset_info(loc, name, dims.data(), &cls, &type_size) < 0)
      return fail(where + "/" + name, "unreadable");
    count = 1;
    for (int d = 0; d < rank; ++d) {
      if (dims[d] > static_cast<hsize_t>(max_length)) return fail(where + "/" + name, "too long");
      count *= dims[d];
    }
    if (count > static_cast<hsize_t>(max_length)) return fail(where + "/" + name, "too long");
    return true;
  }

  // A numeric dataset of exactly `length` elements, read here as FCLib will read it
  // (into that many ints or doubles: HDF5 must be able to convert it).
  bool numbers(hid_t loc, const std::string& where, const char* name, long length, bool as_int = false) {
    hsize_t count = 0;
    H5T_class_t cls{};
    size_t size = 0;
    if (!dataset(loc, where, name, count, cls, size)) return false;
    if (cls != H5T_INTEGER && cls != H5T_FLOAT) return fail(where + "/" + name, "not numbers");
    if (count != static_cast<hsize_t>(length))
      return fail(where + "/" + name, std::to_string(count) + " values where " + std::to_string(length) + " are due");
    herr_t read = -1;
    if (as_int) {
      ints_.resize(length + 1);  // + 1: a buffer even for no values
      read = H5LTread_dataset_int(loc, name, ints_.data());
    } else {
      doubles_.resize(length + 1);
      read = H5LTread_dataset_double(loc, name, doubles_.data());
    }
    if (read < 0) return fail(where + "/" + name, "unreadable as numbers");
    return true;
  }

  // One integer (a size field), read as FCLib reads it.
  bool integer(hid_t loc, const std::string& where, const char* name, int& value) {
    if (!numbers(loc, where, name, 1, true)) return false;
    value = ints_[0];
    return true;
  }

  std::vector<int> ints_;
  std::vector<double> doubles_;

  // An optional text FCLib reads with H5LTread_dataset_string into a buffer of the type's size.
  bool optionalText(hid_t loc, const std::string& where, const char* name) {
    if (!present(H5LTfind_dataset(loc, name))) return true;
    hsize_t count = 0;
    H5T_class_t cls{};
    size_t size = 0;
    if (!dataset(loc, where, name, count, cls, size)) return false;
    if (cls != H5T_STRING || count != 1 || size == 0) return fail(where + "/" + name, "not one fixed-length text");
    const hid_t d = H5Dopen2(loc, name, H5P_DEFAULT);
    if (d < 0) return fail(where + "/" + name, "unreadable");
    const hid_t t = H5Dget_type(d);
    const htri_t variable = t < 0 ? -1 : H5Tis_variable_str(t);
    if (t >= 0) H5Tclose(t);
    H5Dclose(d);
    if (variable != 0) return fail(where + "/" + name, "not one fixed-length text");
    std::string text(size, '\0');
    if (H5LTread_dataset_string(loc, name, &text[0]) < 0) return fail(where + "/" + name, "unreadable");
    return true;
  }

  // A matrix group as read_matrix reads it; its sizes out.
  bool matrix(hid_t parent, const std::string& parent_where, const char* name, int& m, int& n) {
    const std::string where = parent_where + "/" + name;
    if (!isGroup(parent, name)) return fail(where, "missing or not a group");
    Handle g(H5Gopen2(parent, name, H5P_DEFAULT), true);
    int nzmax = 0, nz = 0;
    if (!integer(g.id, where, "nzmax", nzmax) || !integer(g.id, where, "m", m) || !integer(g.id, where, "n", n) ||
        !integer(g.id, where, "nz", nz))
      return false;
    if (m < 0 || n < 0 || nzmax < 0 || nz < -2 || m >= max_length || n >= max_length || nzmax > max_length ||
        nz > max_length)
      return fail(where, "sizes m " + std::to_string(m) + ", n " + std::to_string(n) + ", nzmax " +
                             std::to_string(nzmax) + ", nz " + std::to_string(nz));
    const long pointers = nz >= 0 ? nz : nz == -1 ? n + 1L : m + 1L;
    const long indices = nz >= 0 ? nz : nzmax;
    if (!numbers(g.id, where, "p", pointers, true) || !numbers(g.id, where, "i", indices, true) ||
        !numbers(g.id, where, "x", nzmax))
      return false;
    if (present(H5LTfind_dataset(g.id, "conditioning"))) {
      if (!optionalText(g.id, where, "comment") || !numbers(g.id, where, "conditioning", 1) ||
          !numbers(g.id, where, "determinant", 1) || !numbers(g.id, where, "rank", 1, true))
        return false;
    }
    return true;
  }

  bool spacedim(hid_t main, const std::string& where, int& dim) {
    if (!integer(main, where, "spacedim", dim)) return false;
    if (dim != 2 && dim != 3) return fail(where + "/spacedim", std::to_string(dim) + " (must be 2 or 3)");
    return true;
  }

  bool info(hid_t main, const std::string& where) {
    if (!present(H5Lexists(main, "info", H5P_DEFAULT))) return true;
    if (!isGroup(main, "info")) return fail(where + "/info", "not a group");
    Handle g(H5Gopen2(main, "info", H5P_DEFAULT), true);
    return optionalText(g.id, where + "/info", "title") && optionalText(g.id, where + "/info", "description") &&
           optionalText(g.id, where + "/info", "math_info");
  }

  bool vectors(hid_t main, const std::string& where, const std::vector<std::pair<const char*, long>>& due) {
    if (!isGroup(main, "vectors")) return fail(where + "/vectors", "missing or not a group");
    Handle g(H5Gopen2(main, "vectors", H5P_DEFAULT), true);
    for (const auto& [name, length] : due)
      if (!numbers(g.id, where + "/vectors", name, length)) return false;
    return true;
  }

  bool local(hid_t file) {
    const std::string where = "/fclib_local";
    Handle main(H5Gopen2(file, "fclib_local", H5P_DEFAULT), true);
    int dim = 0, m = 0, n = 0;
    if (!spacedim(main.id, where, dim) || !matrix(main.id, where, "W", m, n)) return false;
    if (m % dim != 0) return fail(where + "/W", std::to_string(m) + " rows: not " + std::to_string(dim) + " per contact");
    std::vector<std::pair<const char*, long>> due = {{"q", m}, {"mu", m / dim}};
    if (present(H5Lexists(main.id, "V", H5P_DEFAULT))) {
      int vm = 0, vn = 0, rm = 0, rn = 0;
      if (!matrix(main.id, where, "V", vm, vn) || !matrix(main.id, where, "R", rm, rn)) return false;
      due.push_back({"s", rm});
    }
    return vectors(main.id, where, due) && info(main.id, where);
  }

  bool global(hid_t file) {
    const std::string where = "/fclib_global";
    Handle main(H5Gopen2(file, "fclib_global", H5P_DEFAULT), true);
    int dim = 0, mm = 0, mn = 0, hm = 0, hn = 0;
    if (!spacedim(main.id, where, dim) || !matrix(main.id, where, "M", mm, mn) ||
        !matrix(main.id, where, "H", hm, hn))
      return false;
    if (hn % dim != 0) return fail(where + "/H", std::to_string(hn) + " columns: not " + std::to_string(dim) + " per contact");
    std::vector<std::pair<const char*, long>> due = {{"f", mm}, {"w", hn}, {"mu", hn / dim}};
    if (present(H5Lexists(main.id, "G", H5P_DEFAULT))) {
      int gm = 0, gn = 0;
      if (!matrix(main.id, where, "G", gm, gn)) return false;
      due.push_back({"b", gn});
    }
    return vectors(main.id, where, due) && info(main.id, where);
  }
};

}  // namespace

bool checkFclibFile(const char* path, FclibKind& kind, std::string& error, long max_length) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const htri_t hdf5 = H5Fis_hdf5(path);
  if (hdf5 <= 0) {
    error = hdf5 < 0 ? "cannot be opened" : "not an HDF5 file";
    return false;
  }
  Handle file(H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), false);
  if (file.id < 0) {
    error = "HDF5 cannot open it";
    return false;
  }
  Checker c{max_length, {}, {}, {}};
  bool ok = false;
  // fclib_read_local returns NULL only if H5Lexists says 0; nscd_fclib then tries
  // fclib_read_global, which needs the group.
  if (present(H5Lexists(file.id, "fclib_local", H5P_DEFAULT))) {
    kind = FclibKind::Local;
    ok = Checker::isGroup(file.id, "fclib_local") ? c.local(file.id)
                                                  : c.fail("/fclib_local", "not a readable group");
  } else if (Checker::isGroup(file.id, "fclib_global")) {
    kind = FclibKind::Global;
    ok = c.global(file.id);
  } else {
    c.error = "neither a /fclib_local nor a /fclib_global group";
  }
  error = c.error;
  return ok;
}

}  // namespace nscd_fclib
