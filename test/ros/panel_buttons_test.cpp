// rostest: the KeyFigures panel (src/rviz_panel/) built as a plain widget with Qt's
// offscreen platform, against the node started paused. Its buttons are clicked in
// code; every wait polls (Qt events + ROS callbacks) up to a generous time limit.
#include <gtest/gtest.h>

#include <QApplication>
#include <QLabel>
#include <QListWidget>
#include <QPushButton>
#include <QSpinBox>

#include <chrono>
#include <cstdlib>
#include <functional>
#include <memory>
#include <thread>

#include "key_figures_panel.hpp"

namespace {

QApplication* app = nullptr;

bool waitFor(const std::function<bool()>& done, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    app->processEvents();
    ros::spinOnce();
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

QString labelStarting(const QWidget& w, const QString& prefix) {
  for (auto* l : w.findChildren<QLabel*>())
    if (l->text().startsWith(prefix)) return l->text();
  return QString();
}

QPushButton* button(const QWidget& w, const QString& text) {
  for (auto* b : w.findChildren<QPushButton*>())
    if (b->text() == text) return b;
  return nullptr;
}

}  // namespace

TEST(PanelButtons, FiguresStepPlayPauseResetAndConfig) {
  nscd_panel::KeyFiguresPanel panel;
  panel.onInitialize();
  auto* names = panel.findChild<QListWidget*>();
  ASSERT_NE(names, nullptr);
  // The figures arrive: names listed, sim time 0 to the microsecond; paused per /diagnostics.
  // (The labels follow on the panel's 50 ms timer.)
  ASSERT_TRUE(waitFor([&] {
    return names->count() > 0 && button(panel, "Play") &&
           labelStarting(panel, "t = ").startsWith("t = 0.000000 s  (0 steps)   rtf ");
  }, 20.0)) << labelStarting(panel, "t = ").toStdString();
  ASSERT_EQ(names->findItems("hinge.q", Qt::MatchExactly).size(), 1);

  // Step 3: the service answers and the next figures show 3 steps.
  panel.findChild<QSpinBox*>()->setValue(3);
  ASSERT_NE(button(panel, "Step"), nullptr);
  button(panel, "Step")->click();
  EXPECT_TRUE(waitFor([&] { return labelStarting(panel, "t = ").contains("(3 steps)"); }, 10.0))
      << labelStarting(panel, "t = ").toStdString();
  EXPECT_TRUE(waitFor([&] { return labelStarting(panel, "/nscd_sim_node/step: 3 step(s)") != ""; }, 5.0));

  // Play: the node runs (more steps); Pause: it stops.
  ASSERT_NE(button(panel, "Play"), nullptr);
  button(panel, "Play")->click();
  EXPECT_TRUE(waitFor([&] { return labelStarting(panel, "/nscd_sim_node/pause: running") != ""; }, 10.0));
  EXPECT_TRUE(waitFor([&] {
    const QString t = labelStarting(panel, "t = ");
    return !t.contains("(3 steps)") && !t.contains("(0 steps)");
  }, 10.0));
  ASSERT_TRUE(waitFor([&] { return button(panel, "Pause") != nullptr; }, 10.0));
  button(panel, "Pause")->click();
  EXPECT_TRUE(waitFor([&] { return labelStarting(panel, "/nscd_sim_node/pause: paused") != ""; }, 10.0));

  // Reset: back to sim time 0.
  ASSERT_NE(button(panel, "Reset"), nullptr);
  button(panel, "Reset")->click();
  EXPECT_TRUE(waitFor([&] { return labelStarting(panel, "t = ").startsWith("t = 0.000000 s  (0 steps)"); }, 10.0))
      << labelStarting(panel, "t = ").toStdString();
  EXPECT_TRUE(waitFor([&] { return labelStarting(panel, "/nscd_sim_node/reset: done") != ""; }, 10.0));

  // The checked figures, the topic and the window are saved in the config and loaded back.
  names->findItems("hinge.q", Qt::MatchExactly).front()->setCheckState(Qt::Checked);
  rviz::Config config;
  panel.save(config);
  QString figures, topic;
  ASSERT_TRUE(config.mapGetString("Figures", &figures));
  EXPECT_EQ(figures.toStdString(), "hinge.q");
  ASSERT_TRUE(config.mapGetString("Topic", &topic));
  EXPECT_EQ(topic.toStdString(), "/nscd_sim_node/key_figures");
  config.mapSetValue("Window", 0.5);
  nscd_panel::KeyFiguresPanel other;
  other.load(config);
  rviz::Config again;
  other.save(again);
  float window = 0;
  ASSERT_TRUE(again.mapGetFloat("Window", &window));
  EXPECT_FLOAT_EQ(window, 0.5f);
  ASSERT_TRUE(again.mapGetString("Figures", &figures));
  EXPECT_EQ(figures.toStdString(), "hinge.q");
}

int main(int argc, char** argv) {
  setenv("QT_QPA_PLATFORM", "offscreen", 1);
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "panel_buttons_test");
  QApplication a(argc, argv);
  app = &a;
  return RUN_ALL_TESTS();
}
