// The data model of the RViz key-figures panel: for each chosen figure name a ring
// buffer of (sim time, value) samples, fed with whole (names, values, sim time)
// messages as the node publishes them on ~key_figures. No ROS and no Qt here, so it
// is unit-tested without a display (test/test_key_figure_series.cpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace nscd_panel {

struct Sample {
  double t;  // sim time, s
  double v;  // value, SI units as published
};

// A fixed-capacity ring buffer of samples in increasing time order.
class SampleRing {
 public:
  explicit SampleRing(std::size_t capacity = 4096);
  void push(const Sample& s);  // drops the oldest sample when full
  void clear() { size_ = 0; head_ = 0; }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return buf_.size(); }
  const Sample& at(std::size_t i) const;  // 0 = oldest
  Sample& back();

 private:
  std::vector<Sample> buf_;
  std::size_t head_ = 0;  // index of the oldest sample
  std::size_t size_ = 0;
};

class KeyFigureSeries {
 public:
  enum class AddResult { Added, Reset, Rejected };

  explicit KeyFigureSeries(double window_s = 2.0, std::size_t capacity = 4096);

  // The figures to record; a name keeps its samples if it stays chosen.
  void setChosen(const std::vector<std::string>& names);
  const std::vector<std::string>& chosen() const { return chosen_; }
  bool isChosen(const std::string& name) const;

  // The sim-time span shown (s, > 0; a bad value is ignored).
  void setWindow(double window_s);
  double window() const { return window_; }

  // One message. Rejected: names and values differ in length, or the time is not
  // finite. A time earlier than the last one (the node was reset) clears every
  // series first and returns Reset. A message at the same time as the last one
  // (a command landing between steps) replaces the last sample. Non-finite values
  // are not recorded. Every name seen is remembered (allNames) for the chooser.
  AddResult add(double sim_time, const std::vector<std::string>& names,
                const std::vector<double>& values);

  void clear();  // samples only; the chosen names and allNames stay

  // Names seen so far, in first-seen order.
  const std::vector<std::string>& allNames() const { return all_names_; }
  bool hasTime() const { return has_time_; }
  double latestTime() const { return latest_t_; }
  // The shown time axis: [latest - window, latest] (false before any message).
  bool timeRange(double& t0, double& t1) const;
  // The samples of `name` inside the time window, oldest first.
  std::vector<Sample> visible(const std::string& name) const;
  // Min and max of the visible samples of every chosen figure; a flat range is
  // widened so an axis can be drawn (false if there is no visible sample).
  bool valueRange(double& lo, double& hi) const;
  // Last recorded value of a chosen figure (false if none).
  bool latestValue(const std::string& name, double& v) const;

 private:
  struct Series {
    std::string name;
    SampleRing ring;
  };
  const Series* find(const std::string& name) const;

  double window_;
  std::size_t capacity_;
  std::vector<std::string> chosen_;
  std::vector<Series> series_;  // one per chosen name, same order
  std::vector<std::string> all_names_;
  bool has_time_ = false;
  double latest_t_ = 0.0;
};

}  // namespace nscd_panel
