// RViz panel "nscd_sim/KeyFigures": strip charts of chosen figures of the node's
// ~key_figures topic over sim time, pause/play, step and reset buttons calling the
// node's services, and the sim time (to the microsecond) and the rtf (from the
// node's /diagnostics). The data live in KeyFigureSeries (ROS- and Qt-free).
#pragma once

#ifndef Q_MOC_RUN
#include <diagnostic_msgs/DiagnosticArray.h>
#include <nscd_sim/KeyFigures.h>
#include <ros/ros.h>
#include <rviz/panel.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "key_figure_series.hpp"
#endif

class QCheckBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QListWidget;
class QListWidgetItem;
class QPushButton;
class QSpinBox;
class QTimer;

namespace nscd_panel {

class StripChart;

// Results of service calls made on worker threads, picked up by the GUI timer.
struct CallResults {
  std::mutex mutex;
  std::vector<std::string> messages;
  void post(const std::string& m) {
    std::lock_guard<std::mutex> lock(mutex);
    messages.push_back(m);
  }
  std::vector<std::string> take() {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::string> out;
    out.swap(messages);
    return out;
  }
};

class KeyFiguresPanel : public rviz::Panel {
  Q_OBJECT
 public:
  explicit KeyFiguresPanel(QWidget* parent = nullptr);
  ~KeyFiguresPanel() override;

  void onInitialize() override;
  void load(const rviz::Config& config) override;
  void save(rviz::Config config) const override;

 private Q_SLOTS:
  void topicEdited();
  void windowChanged(double s);
  void itemChanged(QListWidgetItem* item);
  void pauseClicked();
  void stepClicked();
  void resetClicked();
  void tick();

 private:
  void subscribe();
  void onKeyFigures(const nscd_sim::KeyFigures::ConstPtr& msg);
  void onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg);
  void syncNameList();
  void applyChoice();
  std::string serviceNamespace() const;
  void callAsync(const std::string& what);

  ros::NodeHandle nh_;
  ros::Subscriber figures_sub_;
  ros::Subscriber diag_sub_;
  KeyFigureSeries model_;
  std::shared_ptr<CallResults> results_;

  QString topic_;
  std::vector<std::string> wanted_;  // chosen names, also those not seen yet
  bool have_sim_time_ = false;
  double sim_time_ = 0.0;
  unsigned long long steps_ = 0;
  bool have_rtf_ = false;
  double rtf_ = 0.0;
  bool paused_ = false;
  bool have_paused_ = false;
  bool dirty_ = true;
  bool syncing_ = false;
  std::string last_message_;

  QLineEdit* topic_edit_;
  QListWidget* name_list_;
  QDoubleSpinBox* window_spin_;
  StripChart* chart_;
  QPushButton* pause_button_;
  QPushButton* step_button_;
  QSpinBox* step_count_;
  QPushButton* reset_button_;
  QLabel* time_label_;
  QLabel* message_label_;
  QTimer* timer_;
};

}  // namespace nscd_panel
