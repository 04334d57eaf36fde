// The panel of the live view (relight_panel.h).
#include "relight_panel.h"

#include <cmath>

#include <QCheckBox>
#include <QLabel>
#include <QSlider>
#include <QVBoxLayout>

#include "core/relight/live_legend.h"

namespace vbrdf_render {

namespace {

QString swatch(const std::array<float, 3> &rgb, const char *label) {
  const QString hex = QString::asprintf("#%02x%02x%02x", int(std::lround(rgb[0] * 255)), int(std::lround(rgb[1] * 255)),
                                        int(std::lround(rgb[2] * 255)));
  return "<span style='background-color:" + hex + "'>&nbsp;&nbsp;&nbsp;&nbsp;</span>&nbsp;" + QString(label) + "<br>";
}

QString legend_html(vbrdf::LiveDisplay display) {
  switch (display) {
  case vbrdf::LiveDisplay::FitStatus: {
    QString html = "<b>fit_status</b><br>";
    for (const vbrdf::LegendEntry &e : vbrdf::fit_status_legend()) html += swatch(e.rgb, e.label);
    return html;
  }
  case vbrdf::LiveDisplay::DiffuseQuality:
  case vbrdf::LiveDisplay::SpecularQuality: {
    QString html = display == vbrdf::LiveDisplay::DiffuseQuality ? "<b>DQ</b> (linear between stops)<br>"
                                                                  : "<b>SQ</b> (linear between stops)<br>";
    for (const vbrdf::LegendEntry &e : vbrdf::quality_legend()) html += swatch(e.rgb, e.label);
    return html;
  }
  case vbrdf::LiveDisplay::Diffuse: return "Diffuse term k<sub>d</sub> C d only.";
  case vbrdf::LiveDisplay::Specular: return "Specular term k<sub>s</sub> s<sup>&alpha;</sup> only.";
  case vbrdf::LiveDisplay::Full: break;
  }
  return "Full model. Move the light: Ctrl+Shift+drag.<br>Grey: vertices without a fit.";
}

} // namespace

RelightPanel::RelightPanel(QWidget *parent, std::function<void()> changed)
    : QDockWidget("Vertex BRDF: relight", parent), changed_(std::move(changed)) {
  setObjectName("VertexBrdfRelightPanel");
  auto *body = new QWidget(this);
  auto *layout = new QVBoxLayout(body);
  exposure_label_ = new QLabel(body);
  exposure_ = new QSlider(Qt::Horizontal, body);
  exposure_->setRange(-16, 16);
  exposure_->setValue(0);
  exposure_->setToolTip("Multiplies the model's linear value before clipping at 1 and sRGB encoding.");
  lights_ = new QCheckBox("Photo lights on a sphere", body);
  lights_->setChecked(true);
  lights_->setToolTip("Yellow: the light directions of the project's photos; orange: MeshLab's light now.");
  lights_note_ = new QLabel(body);
  lights_note_->setWordWrap(true);
  legend_ = new QLabel(body);
  legend_->setTextFormat(Qt::RichText);
  message_ = new QLabel(body);
  message_->setWordWrap(true);
  layout->addWidget(exposure_label_);
  layout->addWidget(exposure_);
  layout->addWidget(lights_);
  layout->addWidget(lights_note_);
  layout->addWidget(legend_);
  layout->addWidget(message_);
  layout->addStretch(1);
  setWidget(body);
  auto update_label = [this] { exposure_label_->setText(QString("Exposure: x%1").arg(double(exposure()), 0, 'g', 3)); };
  update_label();
  connect(exposure_, &QSlider::valueChanged, this, [this, update_label] {
    update_label();
    if (changed_) changed_();
  });
  connect(lights_, &QCheckBox::toggled, this, [this] {
    if (changed_) changed_();
  });
  set_display(display_);
  set_message("", false);
  set_lights_note("");
  setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  setFloating(true);
  resize(300, 340);
}

void RelightPanel::set_display(vbrdf::LiveDisplay display) {
  display_ = display;
  legend_->setText(legend_html(display));
  const bool model = int(display) < 3;
  exposure_->setEnabled(model);
  exposure_label_->setEnabled(model);
}

float RelightPanel::exposure() const { return std::exp2(float(exposure_->value()) / 4.0f); }

bool RelightPanel::show_lights() const { return lights_->isChecked(); }

void RelightPanel::set_lights_note(const QString &text) {
  lights_note_->setText(text);
  lights_note_->setVisible(!text.isEmpty());
}

void RelightPanel::set_message(const QString &text, bool warning) {
  message_->setText(text);
  message_->setStyleSheet(warning ? "color: #a00000;" : "");
  message_->setVisible(!text.isEmpty());
}

} // namespace vbrdf_render
