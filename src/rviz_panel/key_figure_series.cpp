#include "key_figure_series.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nscd_panel {

SampleRing::SampleRing(std::size_t capacity) : buf_(std::max<std::size_t>(capacity, 1)) {}

void SampleRing::push(const Sample& s) {
  if (size_ < buf_.size()) {
    buf_[(head_ + size_) % buf_.size()] = s;
    ++size_;
  } else {
    buf_[head_] = s;  // overwrite the oldest
    head_ = (head_ + 1) % buf_.size();
  }
}

const Sample& SampleRing::at(std::size_t i) const {
  if (i >= size_) throw std::out_of_range("SampleRing::at");
  return buf_[(head_ + i) % buf_.size()];
}

Sample& SampleRing::back() {
  if (size_ == 0) throw std::out_of_range("SampleRing::back");
  return buf_[(head_ + size_ - 1) % buf_.size()];
}

KeyFigureSeries::KeyFigureSeries(double window_s, std::size_t capacity)
    : window_(window_s > 0 && std::isfinite(window_s) ? window_s : 2.0),
      capacity_(std::max<std::size_t>(capacity, 1)) {}

void KeyFigureSeries::setChosen(const std::vector<std::string>& names) {
  std::vector<Series> next;
  std::vector<std::string> chosen;
  for (const auto& n : names) {
    if (n.empty() || std::find(chosen.begin(), chosen.end(), n) != chosen.end()) continue;
    chosen.push_back(n);
    auto it = std::find_if(series_.begin(), series_.end(),
                           [&](const Series& s) { return s.name == n; });
    if (it != series_.end())
      next.push_back(std::move(*it));
    else
      next.push_back(Series{n, SampleRing(capacity_)});
  }
  chosen_ = std::move(chosen);
  series_ = std::move(next);
}

bool KeyFigureSeries::isChosen(const std::string& name) const { return find(name) != nullptr; }

void KeyFigureSeries::setWindow(double window_s) {
  if (window_s > 0 && std::isfinite(window_s)) window_ = window_s;
}

KeyFigureSeries::AddResult KeyFigureSeries::add(double sim_time,
                                                const std::vector<std::string>& names,
                                                const std::vector<double>& values) {
  if (names.size() != values.size() || !std::isfinite(sim_time)) return AddResult::Rejected;
  AddResult result = AddResult::Added;
  if (has_time_ && sim_time < latest_t_) {
    clear();
    result = AddResult::Reset;
  }
  const bool same_time = has_time_ && sim_time == latest_t_;
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    if (std::find(all_names_.begin(), all_names_.end(), n) == all_names_.end())
      all_names_.push_back(n);
    auto it = std::find_if(series_.begin(), series_.end(),
                           [&](const Series& s) { return s.name == n; });
    if (it == series_.end() || !std::isfinite(values[i])) continue;
    SampleRing& ring = it->ring;
    if (same_time && ring.size() > 0 && ring.back().t == sim_time)
      ring.back().v = values[i];
    else
      ring.push(Sample{sim_time, values[i]});
  }
  has_time_ = true;
  latest_t_ = sim_time;
  return result;
}

void KeyFigureSeries::clear() {
  for (auto& s : series_) s.ring.clear();
  has_time_ = false;
  latest_t_ = 0.0;
}

bool KeyFigureSeries::timeRange(double& t0, double& t1) const {
  if (!has_time_) return false;
  t1 = latest_t_;
  t0 = latest_t_ - window_;
  return true;
}

const KeyFigureSeries::Series* KeyFigureSeries::find(const std::string& name) const {
  for (const auto& s : series_)
    if (s.name == name) return &s;
  return nullptr;
}

std::vector<Sample> KeyFigureSeries::visible(const std::string& name) const {
  std::vector<Sample> out;
  const Series* s = find(name);
  if (!s || !has_time_) return out;
  const double t0 = latest_t_ - window_;
  for (std::size_t i = 0; i < s->ring.size(); ++i) {
    const Sample& x = s->ring.at(i);
    if (x.t >= t0) out.push_back(x);
  }
  return out;
}

bool KeyFigureSeries::valueRange(double& lo, double& hi) const {
  bool any = false;
  for (const auto& s : series_)
    for (const Sample& x : visible(s.name)) {
      if (!any) {
        lo = hi = x.v;
        any = true;
      } else {
        lo = std::min(lo, x.v);
        hi = std::max(hi, x.v);
      }
    }
  if (!any) return false;
  if (hi - lo <= 1e-12 * std::max(1.0, std::abs(hi))) {
    const double pad = std::max(std::abs(hi) * 0.05, 1e-9);
    lo -= pad;
    hi += pad;
  }
  return true;
}

bool KeyFigureSeries::latestValue(const std::string& name, double& v) const {
  const Series* s = find(name);
  if (!s || s->ring.size() == 0) return false;
  v = s->ring.at(s->ring.size() - 1).v;
  return true;
}

}  // namespace nscd_panel
