// The RViz panel's data model (src/rviz_panel/key_figure_series.*), without ROS or Qt.
#include "key_figure_series.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using nscd_panel::KeyFigureSeries;
using nscd_panel::Sample;
using nscd_panel::SampleRing;
using Result = KeyFigureSeries::AddResult;

namespace {
const std::vector<std::string> kNames{"C7.fn", "TRIP.fn", "latch.gap"};
}

TEST(SampleRing, KeepsTheNewestInOrderWhenFull) {
  SampleRing r(3);
  for (int i = 0; i < 5; ++i) r.push(Sample{double(i), 10.0 * i});
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r.at(0).t, 2.0);
  EXPECT_EQ(r.at(1).t, 3.0);
  EXPECT_EQ(r.at(2).t, 4.0);
  EXPECT_EQ(r.back().v, 40.0);
  EXPECT_THROW(r.at(3), std::out_of_range);
  r.clear();
  EXPECT_EQ(r.size(), 0u);
}

TEST(KeyFigureSeries, RecordsOnlyChosenFiguresButRemembersEveryName) {
  KeyFigureSeries m(1.0);
  m.setChosen({"TRIP.fn"});
  EXPECT_EQ(m.add(0.0, kNames, {1, 2, 3}), Result::Added);
  EXPECT_EQ(m.add(0.1, kNames, {4, 5, 6}), Result::Added);
  EXPECT_EQ(m.allNames(), kNames);
  auto trip = m.visible("TRIP.fn");
  ASSERT_EQ(trip.size(), 2u);
  EXPECT_EQ(trip[0].v, 2.0);
  EXPECT_EQ(trip[1].v, 5.0);
  EXPECT_DOUBLE_EQ(trip[1].t, 0.1);
  EXPECT_TRUE(m.visible("C7.fn").empty());
  double v = 0;
  EXPECT_FALSE(m.latestValue("C7.fn", v));
  ASSERT_TRUE(m.latestValue("TRIP.fn", v));
  EXPECT_EQ(v, 5.0);
}

TEST(KeyFigureSeries, WindowHidesOlderSamplesAndSetsTheTimeAxis) {
  KeyFigureSeries m(0.25);
  m.setChosen({"C7.fn"});
  double t0, t1;
  EXPECT_FALSE(m.timeRange(t0, t1));
  for (int i = 0; i <= 10; ++i) m.add(0.1 * i, kNames, {double(i), 0, 0});
  ASSERT_TRUE(m.timeRange(t0, t1));
  EXPECT_DOUBLE_EQ(t1, 1.0);
  EXPECT_DOUBLE_EQ(t0, 0.75);
  auto s = m.visible("C7.fn");
  ASSERT_EQ(s.size(), 3u);  // 0.8, 0.9, 1.0
  EXPECT_EQ(s.front().v, 8.0);
  double lo, hi;
  ASSERT_TRUE(m.valueRange(lo, hi));
  EXPECT_EQ(lo, 8.0);
  EXPECT_EQ(hi, 10.0);
  m.setWindow(-1.0);  // ignored
  EXPECT_EQ(m.window(), 0.25);
  m.setWindow(10.0);  // older samples are still in the ring
  EXPECT_EQ(m.visible("C7.fn").size(), 11u);
}

TEST(KeyFigureSeries, ValueRangeSpansEveryChosenFigureAndWidensAFlatOne) {
  KeyFigureSeries m(10.0);
  m.setChosen({"C7.fn", "latch.gap"});
  m.add(0.0, kNames, {5, 100, -1e-3});
  m.add(0.1, kNames, {7, 100, 2e-3});
  double lo, hi;
  ASSERT_TRUE(m.valueRange(lo, hi));
  EXPECT_EQ(lo, -1e-3);
  EXPECT_EQ(hi, 7.0);  // TRIP.fn (100) is not chosen
  m.setChosen({"TRIP.fn"});
  EXPECT_FALSE(m.valueRange(lo, hi));  // newly chosen: nothing recorded yet
  m.add(0.2, kNames, {0, 100, 0});
  ASSERT_TRUE(m.valueRange(lo, hi));
  EXPECT_LT(lo, 100.0);
  EXPECT_GT(hi, 100.0);
}

TEST(KeyFigureSeries, TimeJumpBackwardsClearsEverySeries) {
  KeyFigureSeries m(10.0);
  m.setChosen({"C7.fn", "TRIP.fn"});
  m.add(0.0, kNames, {1, 1, 1});
  m.add(0.5, kNames, {2, 2, 2});
  EXPECT_EQ(m.add(0.0, kNames, {3, 4, 5}), Result::Reset);
  auto s = m.visible("TRIP.fn");
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].t, 0.0);
  EXPECT_EQ(s[0].v, 4.0);
  EXPECT_EQ(m.latestTime(), 0.0);
  EXPECT_EQ(m.chosen().size(), 2u);  // the choice survives a reset
}

TEST(KeyFigureSeries, SameTimeReplacesTheLastSample) {
  KeyFigureSeries m(10.0);
  m.setChosen({"C7.fn"});
  m.add(0.2, kNames, {1, 0, 0});
  EXPECT_EQ(m.add(0.2, kNames, {9, 0, 0}), Result::Added);  // a command landed
  auto s = m.visible("C7.fn");
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].v, 9.0);
}

TEST(KeyFigureSeries, RejectsMalformedMessagesAndSkipsNonFiniteValues) {
  KeyFigureSeries m(10.0);
  m.setChosen({"C7.fn", "TRIP.fn"});
  EXPECT_EQ(m.add(0.0, kNames, {1, 2}), Result::Rejected);
  EXPECT_EQ(m.add(std::nan(""), kNames, {1, 2, 3}), Result::Rejected);
  EXPECT_FALSE(m.hasTime());
  m.add(0.0, kNames, {std::numeric_limits<double>::infinity(), 2, 3});
  EXPECT_TRUE(m.visible("C7.fn").empty());
  EXPECT_EQ(m.visible("TRIP.fn").size(), 1u);
}

TEST(KeyFigureSeries, KeepsSamplesOfFiguresThatStayChosen) {
  KeyFigureSeries m(10.0, 4);
  m.setChosen({"C7.fn"});
  for (int i = 0; i < 6; ++i) m.add(0.1 * i, kNames, {double(i), 0, 0});
  EXPECT_EQ(m.visible("C7.fn").size(), 4u);  // capacity
  m.setChosen({"TRIP.fn", "C7.fn", "C7.fn", ""});
  EXPECT_EQ(m.chosen(), (std::vector<std::string>{"TRIP.fn", "C7.fn"}));
  EXPECT_EQ(m.visible("C7.fn").size(), 4u);
  EXPECT_EQ(m.visible("C7.fn").front().v, 2.0);
  m.setChosen({});
  m.setChosen({"C7.fn"});
  EXPECT_TRUE(m.visible("C7.fn").empty());  // dropped when unchosen
}
