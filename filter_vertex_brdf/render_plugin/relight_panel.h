#pragma once
// The small panel of "Vertex BRDF: relight" (a dock over MeshLab's view, as render_radiance_scaling
// has): the display mode, the exposure slider, the light-sphere switch, the legend of the false
// colours and the message when the mesh has no model. It holds no GL and calls `changed` when the user moves a control.
#include <functional>

#include <QDockWidget>

#include "core/relight/live_relight.h"

class QCheckBox;
class QLabel;
class QSlider;

namespace vbrdf_render {

class RelightPanel : public QDockWidget {
public:
  RelightPanel(QWidget *parent, std::function<void()> changed);

  void set_display(vbrdf::LiveDisplay display);  // shows the legend that goes with it
  vbrdf::LiveDisplay display() const { return display_; }
  float exposure() const;  // 2^(slider / 4), 1/16..16
  bool show_lights() const;  // the light sphere (light_sphere.h)
  void set_lights_note(const QString &text);  // which light file the sphere shows, or why none
  // The message under the controls: why the model is not drawn, or what is drawn ("" hides it).
  void set_message(const QString &text, bool warning);

private:
  QLabel *legend_, *message_, *exposure_label_, *lights_note_;
  QCheckBox *lights_;
  QSlider *exposure_;
  vbrdf::LiveDisplay display_ = vbrdf::LiveDisplay::Full;
  std::function<void()> changed_;
};

} // namespace vbrdf_render
