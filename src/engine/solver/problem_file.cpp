// Text form of one friction-contact problem (include/nscd_sim/problem_file.hpp):
// a header of keyed lines, one line per block, then W row by row, b, P_start, P,
// every number with 17 significant digits so a problem reads back bit for bit.
#include "nscd_sim/problem_file.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace nscd {
namespace {

constexpr const char* kMagic = "nscd-friction-contact-problem 1";

char kindLetter(BlockKind k) {
  return k == BlockKind::Frictional ? 'F' : k == BlockKind::Frictionless ? 'N' : 'B';
}

void writeVector(std::FILE* f, const char* name, const Eigen::Ref<const Eigen::VectorXd>& v) {
  std::fprintf(f, "%s", name);
  for (Eigen::Index i = 0; i < v.size(); ++i) std::fprintf(f, " %.17g", v(i));
  std::fputc('\n', f);
}

[[noreturn]] void bad(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": not a problem file: " + what);
}

// Reads "name v1 ... vn" from the stream into v (size n).
void readVector(std::istream& in, const std::string& path, const char* name, Eigen::VectorXd& v,
                int n) {
  std::string word;
  if (!(in >> word) || word != name) bad(path, std::string("expected ") + name);
  v.resize(n);
  for (int i = 0; i < n; ++i)
    if (!(in >> v(i))) bad(path, std::string("short ") + name);
}

}  // namespace

void writeProblemFile(const std::string& path, const ProblemView& view) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error(path + ": cannot write");
  const int m = int(view.b.size());
  std::fprintf(f, "%s\n", kMagic);
  std::fprintf(f, "t %.17g round %d rows %d blocks %d\n", view.t, view.round, m,
               int(view.blocks.size()));
  std::fprintf(f, "residual %.17g converged %d iterations %d\n", view.report.residual,
               view.report.converged ? 1 : 0, view.report.iteration_sum);
  for (const ProblemBlock& bl : view.blocks)
    std::fprintf(f, "block %c %d %d %.17g\n", kindLetter(bl.kind), bl.row, bl.size, bl.mu);
  for (int i = 0; i < m; ++i) writeVector(f, "W", view.W.row(i).transpose());
  writeVector(f, "b", view.b);
  writeVector(f, "P_start", view.P_start);
  writeVector(f, "P", view.P);
  const bool ok = std::ferror(f) == 0;
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error(path + ": write failed");
}

ProblemFile readProblemFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::string line;
  if (!std::getline(in, line) || line != kMagic) bad(path, "no header line");
  ProblemFile p;
  std::string k1, k2, k3, k4;
  int m = 0, nb = 0, conv = 0;
  if (!(in >> k1 >> p.t >> k2 >> p.round >> k3 >> m >> k4 >> nb) || k1 != "t" || m < 0 || nb < 0)
    bad(path, "bad t/rows line");
  if (!(in >> k1 >> p.residual >> k2 >> conv >> k3 >> p.iterations) || k1 != "residual")
    bad(path, "bad residual line");
  p.converged = conv != 0;
  for (int i = 0; i < nb; ++i) {
    std::string word;
    char kind = 0;
    ProblemBlock bl;
    if (!(in >> word >> kind >> bl.row >> bl.size >> bl.mu) || word != "block") bad(path, "bad block");
    bl.kind = kind == 'F' ? BlockKind::Frictional : kind == 'N' ? BlockKind::Frictionless
                                                                : BlockKind::Bilateral;
    // size > m - row, not row + size > m: a row near INT_MAX overflowed the sum.
    if (bl.row < 0 || bl.size < 1 || bl.size > m - bl.row) bad(path, "block outside the rows");
    p.blocks.push_back(bl);
  }
  // W's m x m numbers are read before W is made: its size then follows from the
  // numbers the file holds, never from the rows count alone (rows 2147483647 asked
  // Eigen for 2^62 entries, whose std::bad_alloc escaped the refusal).
  std::vector<double> entries;
  for (int i = 0; i < m; ++i) {
    std::string word;
    if (!(in >> word) || word != "W") bad(path, "expected W");
    for (int j = 0; j < m; ++j) {
      double x;
      if (!(in >> x)) bad(path, "short W");
      entries.push_back(x);
    }
  }
  p.W = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(entries.data(), m, m);
  readVector(in, path, "b", p.b, m);
  readVector(in, path, "P_start", p.P_start, m);
  readVector(in, path, "P", p.P, m);
  return p;
}

}  // namespace nscd
