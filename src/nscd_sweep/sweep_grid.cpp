// Sweep grids, shards and the CSV merge (see sweep_grid.hpp).
#include "sweep_grid.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace nscd::sweep {
namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream is(s);
  while (std::getline(is, cur, sep)) out.push_back(cur);
  if (!s.empty() && s.back() == sep) out.push_back("");
  return out;
}

double toNumber(const std::string& s, const std::string& what) {
  size_t used = 0;
  double x = 0;
  try {
    x = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (s.empty() || used != s.size() || !std::isfinite(x))
    throw std::invalid_argument(what + ": '" + s + "' is not a finite number");
  return x;
}

std::string shortNumber(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

}  // namespace

SweepAxis parseAxis(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw std::invalid_argument("--param " + text + ": expected key=v1,v2,... or key=log:lo:hi:n");
  SweepAxis ax;
  ax.key = text.substr(0, eq);
  const std::string rhs = text.substr(eq + 1);
  const std::string what = "--param " + ax.key;
  if (rhs.rfind("log:", 0) == 0 || rhs.rfind("lin:", 0) == 0) {
    const std::vector<std::string> f = split(rhs, ':');
    if (f.size() != 4) throw std::invalid_argument(what + ": expected " + f[0] + ":lo:hi:n");
    const double lo = toNumber(f[1], what), hi = toNumber(f[2], what);
    const double nd = toNumber(f[3], what);
    const int n = static_cast<int>(nd);
    if (n < 1 || n != nd || n > 100000) throw std::invalid_argument(what + ": n must be an integer >= 1");
    const bool lg = f[0] == "log";
    if (lg && (lo <= 0 || hi <= 0)) throw std::invalid_argument(what + ": log spacing needs lo, hi > 0");
    for (int i = 0; i < n; ++i) {
      const double a = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
      const double x = lg ? std::exp(std::log(lo) + a * (std::log(hi) - std::log(lo))) : lo + a * (hi - lo);
      ax.values.push_back(shortNumber(x));
    }
  } else {
    ax.values = split(rhs, ',');
    for (const std::string& v : ax.values)
      if (v.empty()) throw std::invalid_argument(what + ": empty value in '" + rhs + "'");
  }
  return ax;
}

long gridSize(const std::vector<SweepAxis>& axes) {
  long n = 1;
  for (const SweepAxis& a : axes) n *= static_cast<long>(a.values.size());
  return n;
}

std::vector<int> gridPoint(const std::vector<SweepAxis>& axes, long k) {
  std::vector<int> idx(axes.size(), 0);
  for (size_t i = axes.size(); i-- > 0;) {
    const long m = static_cast<long>(axes[i].values.size());
    idx[i] = static_cast<int>(k % m);
    k /= m;
  }
  return idx;
}

void parseShard(const std::string& text, int& index, int& count) {
  const size_t sl = text.find('/');
  const std::string what = "--shard " + text;
  if (sl == std::string::npos) throw std::invalid_argument(what + ": expected i/n");
  const double i = toNumber(text.substr(0, sl), what), n = toNumber(text.substr(sl + 1), what);
  if (i != std::floor(i) || n != std::floor(n) || n < 1 || i < 0 || i >= n)
    throw std::invalid_argument(what + ": need integers 0 <= i < n");
  index = static_cast<int>(i);
  count = static_cast<int>(n);
}

long mergeCsv(const std::vector<std::string>& files, std::ostream& out, std::ostream& log) {
  std::string header;
  std::map<long, std::string> rows;
  long runs_total = -1;
  int runs_col = -1;
  for (const std::string& f : files) {
    std::ifstream in(f);
    if (!in) throw std::runtime_error("cannot read " + f);
    std::string h;
    if (!std::getline(in, h)) continue;  // an empty shard (more shards than runs)
    if (header.empty()) {
      header = h;
      const std::vector<std::string> cols = split(header, ',');
      if (cols.empty() || cols[0] != "run")
        throw std::runtime_error(f + ": not a sweep CSV (first column is not 'run')");
      for (size_t c = 0; c < cols.size(); ++c)
        if (cols[c] == "runs") runs_col = static_cast<int>(c);
    } else if (h != header) {
      throw std::runtime_error(f + ": header differs from " + files.front() + "'s");
    }
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty()) continue;
      const std::vector<std::string> cells = split(line, ',');
      const long run = static_cast<long>(toNumber(cells[0], f + ": run"));
      if (runs_col >= 0 && runs_col < static_cast<int>(cells.size()))
        runs_total = static_cast<long>(toNumber(cells[runs_col], f + ": runs"));
      if (!rows.emplace(run, line).second) log << "merge: run " << run << " appears twice (kept the first)\n";
    }
  }
  if (header.empty()) return 0;
  out << header << '\n';
  for (const auto& [run, line] : rows) out << line << '\n';
  if (runs_total >= 0) {
    long missing = 0;
    for (long k = 0; k < runs_total; ++k) missing += rows.count(k) == 0;
    if (missing > 0) log << "merge: " << missing << " of " << runs_total << " runs missing\n";
  }
  return static_cast<long>(rows.size());
}

}  // namespace nscd::sweep
