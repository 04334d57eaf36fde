#pragma once
// MeshLab 2020.09 render plugin "Vertex BRDF: relight" (Render > Shaders): draws the current mesh
// with its per-vertex reflectance model, lit by MeshLab's own light (Ctrl+Shift+drag). A thin adapter:
// the model comes from the mesh's attributes (plugin/relight_attributes.h), the drawing from the
// core (core/relight/live_relight.h), the view from GL state (gl_view_state.h), the controls from
// relight_panel.h. Without a model it shows why and draws MeshLab's normal rendering.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <GL/glew.h>
#include <QObject>
#include <common/interfaces.h>

namespace vbrdf {
class LiveRelight;
struct LiveView;
}
namespace vbrdf_render {
class RelightPanel;
}
namespace vbrdf_plugin {
struct MeshArrays;
}

class RenderVertexBrdfPlugin : public QObject, public MeshRenderInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_RENDER_INTERFACE_IID)
  Q_INTERFACES(MeshRenderInterface)

public:
  RenderVertexBrdfPlugin();
  ~RenderVertexBrdfPlugin() override;

  QString pluginName() const override;
  QList<QAction *> actions() override;
  bool isSupported() override { return supported_; }
  void Init(QAction *action, MeshDocument &md, MLSceneGLSharedDataContext::PerMeshRenderingDataMap &mp,
            GLArea *gla) override;
  void Render(QAction *action, MeshDocument &md, MLSceneGLSharedDataContext::PerMeshRenderingDataMap &mp,
              GLArea *gla) override;
  void Finalize(QAction *action, MeshDocument *md, GLArea *gla) override;

private:
  // True when `mesh`'s model is uploaded (re-read when its attributes changed).
  bool ensure_model(MeshModel &mesh, MeshDocument &md, GLArea *gla);
  void release();
  void log_view(const vbrdf::LiveView &view);
  void load_photo_lights(MeshDocument &md, MeshModel &mesh, const vbrdf_plugin::MeshArrays &arrays);
  static void draw_as_meshlab_does(MLSceneGLSharedDataContext &shared, MeshModel &mesh, GLArea *gla);

  QList<QAction *> actions_;
  bool supported_ = false;
  vbrdf_render::RelightPanel *panel_ = nullptr;
  std::unique_ptr<vbrdf::LiveRelight> live_;
  int mesh_id_ = -1;
  uint64_t fingerprint_ = 0;  // of the uploaded model, or of the mesh whose model was missing
  bool model_ok_ = false;
  std::vector<std::array<float, 3>> photo_lights_;  // world directions (light sphere)
  std::array<float, 3> sphere_centre_{{0, 0, 0}};
  float sphere_radius_ = 0;
};
