#include "key_figures_panel.hpp"

#include <nscd_sim/Step.h>
#include <pluginlib/class_list_macros.hpp>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>

#include <QDoubleSpinBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPainter>
#include <QPushButton>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <thread>

namespace nscd_panel {

namespace {
const char* kDefaultTopic = "/nscd_sim_node/key_figures";

QColor seriesColor(std::size_t i) {
  static const QColor colors[] = {QColor(31, 119, 180), QColor(214, 39, 40), QColor(44, 160, 44),
                                  QColor(255, 127, 14), QColor(148, 103, 189), QColor(140, 86, 75),
                                  QColor(227, 119, 194), QColor(23, 190, 207)};
  return colors[i % (sizeof colors / sizeof colors[0])];
}
}  // namespace

// The strip chart: every chosen figure over the model's time window, one shared
// value axis (min/max of what is shown), drawn with QPainter.
class StripChart : public QWidget {
 public:
  StripChart(const KeyFigureSeries& model, QWidget* parent) : QWidget(parent), model_(model) {
    setMinimumHeight(120);
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
  }

 protected:
  void paintEvent(QPaintEvent*) override {
    QPainter p(this);
    p.fillRect(rect(), Qt::white);
    const QFontMetrics fm(p.font());
    const int left = fm.horizontalAdvance("-0.0000e-00") + 6, right = 8, top = 4;
    const int bottom = fm.height() + 6;
    const QRect plot(left, top, std::max(width() - left - right, 10),
                     std::max(height() - top - bottom, 10));
    p.setPen(QColor(200, 200, 200));
    p.drawRect(plot);
    double t0, t1, lo, hi;
    if (!model_.timeRange(t0, t1)) {
      p.setPen(Qt::gray);
      p.drawText(plot, Qt::AlignCenter, "no key figures received");
      return;
    }
    p.setPen(Qt::black);
    p.drawText(QRect(left, plot.bottom() + 2, plot.width(), fm.height()), Qt::AlignLeft,
               QString("%1 s").arg(t0, 0, 'f', 3));
    p.drawText(QRect(left, plot.bottom() + 2, plot.width(), fm.height()), Qt::AlignRight,
               QString("%1 s").arg(t1, 0, 'f', 3));
    if (!model_.valueRange(lo, hi)) return;
    p.drawText(QRect(0, plot.top(), left - 4, fm.height()), Qt::AlignRight,
               QString::number(hi, 'g', 4));
    p.drawText(QRect(0, plot.bottom() - fm.height(), left - 4, fm.height()), Qt::AlignRight,
               QString::number(lo, 'g', 4));
    auto px = [&](double t) { return plot.left() + (t - t0) / (t1 - t0) * plot.width(); };
    auto py = [&](double v) { return plot.bottom() - (v - lo) / (hi - lo) * plot.height(); };
    if (lo < 0 && hi > 0) {  // the zero line
      p.setPen(QPen(QColor(220, 220, 220), 1, Qt::DashLine));
      p.drawLine(QPointF(plot.left(), py(0)), QPointF(plot.right(), py(0)));
    }
    p.setRenderHint(QPainter::Antialiasing, true);
    const auto& names = model_.chosen();
    int legend_y = plot.top() + fm.ascent() + 2;
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto samples = model_.visible(names[i]);
      p.setPen(QPen(seriesColor(i), 1.5));
      if (samples.size() == 1) {
        p.drawEllipse(QPointF(px(samples[0].t), py(samples[0].v)), 2, 2);
      } else if (!samples.empty()) {
        QPolygonF line;
        line.reserve(int(samples.size()));
        for (const auto& s : samples) line << QPointF(px(s.t), py(s.v));
        p.drawPolyline(line);
      }
      double v;
      const QString text = model_.latestValue(names[i], v)
                               ? QString("%1 = %2").arg(QString::fromStdString(names[i]))
                                     .arg(v, 0, 'g', 6)
                               : QString::fromStdString(names[i]);
      p.drawText(plot.left() + 6, legend_y, text);
      legend_y += fm.height();
    }
  }

 private:
  const KeyFigureSeries& model_;
};

KeyFiguresPanel::KeyFiguresPanel(QWidget* parent)
    : rviz::Panel(parent), model_(2.0), results_(std::make_shared<CallResults>()),
      topic_(kDefaultTopic) {
  auto* layout = new QVBoxLayout(this);

  auto* topic_row = new QHBoxLayout;
  topic_row->addWidget(new QLabel("Topic:"));
  topic_edit_ = new QLineEdit(topic_);
  topic_row->addWidget(topic_edit_);
  topic_row->addWidget(new QLabel("Window (s):"));
  window_spin_ = new QDoubleSpinBox;
  window_spin_->setRange(0.001, 1000.0);
  window_spin_->setDecimals(3);
  window_spin_->setValue(model_.window());
  topic_row->addWidget(window_spin_);
  layout->addLayout(topic_row);

  // The chart above the figure list: in a narrow dock the chart keeps the width.
  chart_ = new StripChart(model_, this);
  layout->addWidget(chart_, 3);
  name_list_ = new QListWidget;
  name_list_->setToolTip("Check the figures to plot (names seen on the topic)");
  name_list_->setMinimumHeight(60);
  layout->addWidget(name_list_, 1);

  auto* buttons = new QHBoxLayout;
  pause_button_ = new QPushButton("Pause");
  step_button_ = new QPushButton("Step");
  step_count_ = new QSpinBox;
  step_count_->setRange(1, 100000);
  step_count_->setToolTip("Steps per Step click");
  reset_button_ = new QPushButton("Reset");
  buttons->addWidget(pause_button_);
  buttons->addWidget(step_button_);
  buttons->addWidget(step_count_);
  buttons->addWidget(reset_button_);
  buttons->addStretch(1);
  layout->addLayout(buttons);
  // The time and the answers on lines of their own, wrapped: the panel stays narrow
  // enough to leave the 3D view most of the window.
  time_label_ = new QLabel("t = --");
  time_label_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  time_label_->setWordWrap(true);
  layout->addWidget(time_label_);
  message_label_ = new QLabel;
  message_label_->setWordWrap(true);
  layout->addWidget(message_label_);

  connect(topic_edit_, &QLineEdit::editingFinished, this, &KeyFiguresPanel::topicEdited);
  connect(window_spin_, QOverload<double>::of(&QDoubleSpinBox::valueChanged), this,
          &KeyFiguresPanel::windowChanged);
  connect(name_list_, &QListWidget::itemChanged, this, &KeyFiguresPanel::itemChanged);
  connect(pause_button_, &QPushButton::clicked, this, &KeyFiguresPanel::pauseClicked);
  connect(step_button_, &QPushButton::clicked, this, &KeyFiguresPanel::stepClicked);
  connect(reset_button_, &QPushButton::clicked, this, &KeyFiguresPanel::resetClicked);

  timer_ = new QTimer(this);
  connect(timer_, &QTimer::timeout, this, &KeyFiguresPanel::tick);
}

KeyFiguresPanel::~KeyFiguresPanel() = default;

void KeyFiguresPanel::onInitialize() {
  subscribe();
  diag_sub_ = nh_.subscribe("/diagnostics", 5, &KeyFiguresPanel::onDiagnostics, this);
  timer_->start(50);  // repaint at most 20 times a second
}

void KeyFiguresPanel::subscribe() {
  figures_sub_.shutdown();
  model_.clear();
  have_sim_time_ = false;
  dirty_ = true;
  const std::string topic = topic_.trimmed().toStdString();
  if (topic.empty()) return;
  try {
    figures_sub_ = nh_.subscribe(topic, 20, &KeyFiguresPanel::onKeyFigures, this);
  } catch (const ros::Exception& e) {
    message_label_->setText(QString("bad topic: %1").arg(e.what()));
  }
}

std::string KeyFiguresPanel::serviceNamespace() const {
  std::string t = topic_.trimmed().toStdString();
  const auto slash = t.rfind('/');
  return slash == std::string::npos ? std::string() : t.substr(0, slash);
}

void KeyFiguresPanel::onKeyFigures(const nscd_sim::KeyFigures::ConstPtr& msg) {
  const std::size_t known = model_.allNames().size();
  if (model_.add(msg->sim_time, msg->names, msg->values) == KeyFigureSeries::AddResult::Rejected)
    return;
  have_sim_time_ = true;
  sim_time_ = msg->sim_time;
  steps_ = msg->steps;
  dirty_ = true;
  if (model_.allNames().size() != known) syncNameList();
}

void KeyFiguresPanel::onDiagnostics(const diagnostic_msgs::DiagnosticArray::ConstPtr& msg) {
  for (const auto& s : msg->status) {
    if (s.name != "nscd_sim: simulator") continue;
    for (const auto& kv : s.values) {
      if (kv.key == "rtf") {
        try {
          rtf_ = std::stod(kv.value);
          have_rtf_ = true;
        } catch (...) {
        }
      } else if (kv.key == "paused") {
        paused_ = kv.value == "true";
        have_paused_ = true;
      }
    }
    dirty_ = true;
  }
}

void KeyFiguresPanel::syncNameList() {
  syncing_ = true;
  for (const auto& n : model_.allNames()) {
    const QString q = QString::fromStdString(n);
    if (!name_list_->findItems(q, Qt::MatchExactly).isEmpty()) continue;
    auto* item = new QListWidgetItem(q, name_list_);
    item->setFlags(item->flags() | Qt::ItemIsUserCheckable);
    const bool on = std::find(wanted_.begin(), wanted_.end(), n) != wanted_.end();
    item->setCheckState(on ? Qt::Checked : Qt::Unchecked);
  }
  syncing_ = false;
}

void KeyFiguresPanel::applyChoice() {
  model_.setChosen(wanted_);
  dirty_ = true;
}

void KeyFiguresPanel::itemChanged(QListWidgetItem* item) {
  if (syncing_) return;
  const std::string n = item->text().toStdString();
  auto it = std::find(wanted_.begin(), wanted_.end(), n);
  if (item->checkState() == Qt::Checked) {
    if (it == wanted_.end()) wanted_.push_back(n);
  } else if (it != wanted_.end()) {
    wanted_.erase(it);
  }
  applyChoice();
  Q_EMIT configChanged();
}

void KeyFiguresPanel::topicEdited() {
  if (topic_edit_->text() == topic_) return;
  topic_ = topic_edit_->text();
  subscribe();
  Q_EMIT configChanged();
}

void KeyFiguresPanel::windowChanged(double s) {
  model_.setWindow(s);
  dirty_ = true;
  Q_EMIT configChanged();
}

// Runs a service call on a detached thread: waits at most 1 s for the service, and
// posts a one-line result that tick() shows. The GUI thread never blocks.
void KeyFiguresPanel::callAsync(const std::string& what) {
  const std::string ns = serviceNamespace();
  const bool pause = !paused_;
  const unsigned count = unsigned(step_count_->value());
  std::shared_ptr<CallResults> results = results_;
  std::thread([what, ns, pause, count, results] {
    const std::string name = ns + "/" + what;
    if (!ros::service::waitForService(name, ros::Duration(1.0))) {
      results->post(name + ": not available");
      return;
    }
    if (what == "pause") {
      std_srvs::SetBool srv;
      srv.request.data = pause;
      const bool ok = ros::service::call(name, srv) && srv.response.success;
      results->post(name + (ok ? (pause ? ": paused" : ": running") : ": failed " + srv.response.message));
    } else if (what == "step") {
      nscd_sim::Step srv;
      srv.request.count = count;
      const bool ok = ros::service::call(name, srv) && srv.response.success;
      char buf[160];
      std::snprintf(buf, sizeof buf, ": %u step(s), t = %.6f s", srv.response.steps_taken,
                    srv.response.sim_time);
      results->post(name + (ok ? std::string(buf) : ": failed " + srv.response.message));
    } else {
      std_srvs::Empty srv;
      results->post(name + (ros::service::call(name, srv) ? ": done" : ": failed"));
    }
  }).detach();
}

void KeyFiguresPanel::pauseClicked() {
  callAsync("pause");
  paused_ = !paused_;  // until /diagnostics says otherwise
  have_paused_ = true;
  dirty_ = true;
}

void KeyFiguresPanel::stepClicked() { callAsync("step"); }

void KeyFiguresPanel::resetClicked() { callAsync("reset"); }

void KeyFiguresPanel::tick() {
  for (const auto& m : results_->take()) {
    last_message_ = m;
    message_label_->setText(QString::fromStdString(m));
  }
  if (!dirty_) return;
  dirty_ = false;
  QString text = have_sim_time_ ? QString("t = %1 s  (%2 steps)").arg(sim_time_, 0, 'f', 6)
                                      .arg(steps_)
                                : QString("t = --");
  text += have_rtf_ ? QString("   rtf %1").arg(rtf_, 0, 'g', 3) : QString("   rtf --");
  if (have_paused_ && paused_) text += "   paused";
  time_label_->setText(text);
  pause_button_->setText(have_paused_ && paused_ ? "Play" : "Pause");
  chart_->update();
}

void KeyFiguresPanel::load(const rviz::Config& config) {
  rviz::Panel::load(config);
  QString topic;
  if (config.mapGetString("Topic", &topic) && !topic.isEmpty()) {
    topic_ = topic;
    topic_edit_->setText(topic_);
  }
  float window;
  if (config.mapGetFloat("Window", &window) && window > 0) {
    window_spin_->setValue(window);
    model_.setWindow(window);
  }
  QString figures;
  if (config.mapGetString("Figures", &figures)) {
    wanted_.clear();
    for (const QString& f : figures.split(',', Qt::SkipEmptyParts))
      wanted_.push_back(f.trimmed().toStdString());
    applyChoice();
    syncing_ = true;
    for (int i = 0; i < name_list_->count(); ++i) {
      auto* item = name_list_->item(i);
      const bool on = std::find(wanted_.begin(), wanted_.end(), item->text().toStdString()) !=
                      wanted_.end();
      item->setCheckState(on ? Qt::Checked : Qt::Unchecked);
    }
    syncing_ = false;
  }
  subscribe();
}

void KeyFiguresPanel::save(rviz::Config config) const {
  rviz::Panel::save(config);
  config.mapSetValue("Topic", topic_);
  config.mapSetValue("Window", window_spin_->value());
  QStringList figures;
  for (const auto& f : wanted_) figures << QString::fromStdString(f);
  config.mapSetValue("Figures", figures.join(","));
}

}  // namespace nscd_panel

PLUGINLIB_EXPORT_CLASS(nscd_panel::KeyFiguresPanel, rviz::Panel)
