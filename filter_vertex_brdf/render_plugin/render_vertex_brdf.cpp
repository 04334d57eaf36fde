// "Vertex BRDF: relight" render plugin (render_vertex_brdf.h).
#include "render_vertex_brdf.h"

#include <QAction>

#include <common/GLExtensionsManager.h>
#include "meshlab/glarea.h"

#include "core/base/errors.h"
#include "core/relight/live_relight.h"
#include "core/relight/live_view_file.h"
#include "gl_view_state.h"
#include "light_sphere.h"
#include "photo_lights.h"
#include "meshlab_bridge.h"
#include "relight_attributes.h"
#include "relight_panel.h"

namespace {

// One action per display mode (MeshLab lists them under Render > Shaders); data = LiveDisplay.
const struct {
  const char *text;
  vbrdf::LiveDisplay display;
} kModes[] = {
    {"Vertex BRDF: relight", vbrdf::LiveDisplay::Full},
    {"Vertex BRDF: relight, diffuse only", vbrdf::LiveDisplay::Diffuse},
    {"Vertex BRDF: relight, specular only", vbrdf::LiveDisplay::Specular},
    {"Vertex BRDF: fit_status colours", vbrdf::LiveDisplay::FitStatus},
    {"Vertex BRDF: DQ colours", vbrdf::LiveDisplay::DiffuseQuality},
    {"Vertex BRDF: SQ colours", vbrdf::LiveDisplay::SpecularQuality},
};

} // namespace

RenderVertexBrdfPlugin::RenderVertexBrdfPlugin() = default;
RenderVertexBrdfPlugin::~RenderVertexBrdfPlugin() = default;  // GL objects need the view's context: Finalize frees them

QString RenderVertexBrdfPlugin::pluginName() const { return "RenderVertexBrdf"; }

QList<QAction *> RenderVertexBrdfPlugin::actions() {
  if (actions_.isEmpty())
    for (const auto &m : kModes) {
      auto *a = new QAction(m.text, this);
      a->setData(int(m.display));
      actions_ << a;
    }
  return actions_;
}

void RenderVertexBrdfPlugin::Init(QAction *action, MeshDocument &md, MLSceneGLSharedDataContext::PerMeshRenderingDataMap &,
                                  GLArea *gla) {
  gla->makeCurrent();
  supported_ = GLExtensionsManager::initializeGLextensions_notThrowing() && GLEW_VERSION_3_3;
  if (!supported_) {
    md.Log.Log(GLLogStream::WARNING, "Vertex BRDF relight needs OpenGL 3.3.");
    return;
  }
  if (panel_ == nullptr) panel_ = new vbrdf_render::RelightPanel(gla, [gla] { gla->update(); });
  panel_->set_display(vbrdf::LiveDisplay(action->data().toInt()));
  panel_->setWindowTitle(action->text());
  panel_->move(10, 100);
  panel_->show();
  fingerprint_ = 0;  // re-read the model
  mesh_id_ = -1;
}

bool RenderVertexBrdfPlugin::ensure_model(MeshModel &mesh, MeshDocument &md, GLArea *gla) {
  const uint64_t fingerprint = vbrdf_plugin::relight_model_fingerprint(mesh);
  if (mesh.id() == mesh_id_ && fingerprint == fingerprint_ && fingerprint != 0) return model_ok_;
  if (mesh.id() == mesh_id_ && fingerprint == 0 && fingerprint_ == 0 && !model_ok_ && mesh_id_ != -1) return false;
  live_.reset();
  mesh_id_ = mesh.id();
  fingerprint_ = fingerprint;
  model_ok_ = false;
  try {
    const vbrdf_plugin::RelightModel model = vbrdf_plugin::relight_model(mesh);
    const QGLContext *context = gla->context();
    auto get_proc = [context](const char *name) -> void * {
      return reinterpret_cast<void *>(context->getProcAddress(QString::fromLatin1(name)));
    };
    live_.reset(new vbrdf::LiveRelight(model.arrays.data.view(), model.fits, get_proc, model.lobe, model.diffuse));
    model_ok_ = true;
    load_photo_lights(md, mesh, model.arrays);
    const QString what = QString("Vertex BRDF relight: %1 vertices of '%2', %3 with a fit (lobe %4, diffuse %5).")
                             .arg(model.fits.size())
                             .arg(mesh.label())
                             .arg(model.modelled)
                             .arg(vbrdf::lobe_form_label(model.lobe))
                             .arg(QString::fromStdString(vbrdf::describe_diffuse_forms(model.diffuse)));
    md.Log.Log(GLLogStream::FILTER, qUtf8Printable(what));
    if (panel_) panel_->set_message(what.mid(QString("Vertex BRDF relight: ").size()), false);
  } catch (const std::exception &e) {  // InputError: no model; ProcessingError: GL
    md.Log.Log(GLLogStream::WARNING, e.what());
    if (panel_) panel_->set_message(QString::fromUtf8(e.what()), true);
  }
  return model_ok_;
}

// The light sphere: centred on the mesh's bounding box, 1.1 times its half diagonal; the photo
// lights when the project has a light file (else the panel says why; the sphere then shows only
// MeshLab's light).
void RenderVertexBrdfPlugin::load_photo_lights(MeshDocument &md, MeshModel &mesh, const vbrdf_plugin::MeshArrays &arrays) {
  const vbrdf::Bounds box = vbrdf::compute_bounds(arrays.data.view());
  sphere_centre_ = box.centre();
  sphere_radius_ = 0.55f * box.diagonal();
  photo_lights_.clear();
  if (panel_ == nullptr) return;
  try {
    const vbrdf_plugin::PhotoLights lights = vbrdf_plugin::photo_lights(md, mesh, arrays);
    photo_lights_ = lights.directions;
    panel_->set_lights_note(QString("%1 photo lights from %2").arg(photo_lights_.size())
                                .arg(QString::fromStdString(lights.file).section('/', -1)));
  } catch (const std::exception &e) {
    panel_->set_lights_note(QString::fromUtf8(e.what()));
  }
}

// MeshLab's normal rendering of one layer, as GLArea::paintEvent draws it without a render plugin
// (its private setLightingColors copied: light colours from the view's settings, back-face culling).
void RenderVertexBrdfPlugin::draw_as_meshlab_does(MLSceneGLSharedDataContext &shared, MeshModel &mesh, GLArea *gla) {
  MLRenderingData data;
  shared.getRenderInfoPerMeshView(mesh.id(), gla->context(), data);
  MLPerViewGLOptions opts;
  if (data.get(opts)) {
    if (opts._double_side_lighting || opts._fancy_lighting) glEnable(GL_LIGHT1);
    else glDisable(GL_LIGHT1);
    const GLAreaSetting &s = gla->glas;
    for (GLenum light : {GLenum(GL_LIGHT0), GLenum(GL_LIGHT1)}) {
      glLightfv(light, GL_AMBIENT, vcg::Color4f::Construct(s.baseLightAmbientColor).V());
      glLightfv(light, GL_DIFFUSE, vcg::Color4f::Construct(s.baseLightDiffuseColor).V());
      glLightfv(light, GL_SPECULAR, vcg::Color4f::Construct(s.baseLightSpecularColor).V());
    }
    if (opts._fancy_lighting) {
      glLightfv(GL_LIGHT0, GL_DIFFUSE, vcg::Color4f::Construct(s.fancyFLightDiffuseColor).V());
      glLightfv(GL_LIGHT1, GL_DIFFUSE, vcg::Color4f::Construct(s.fancyBLightDiffuseColor).V());
    }
    if (opts._back_face_cull) glEnable(GL_CULL_FACE);
    else glDisable(GL_CULL_FACE);
  }
  shared.setMeshTransformationMatrix(mesh.id(), mesh.cm.Tr);
  shared.draw(mesh.id(), gla->context());
}

// For the GUI test (tests/gui): the drawn view, when VBRDF_RELIGHT_VIEW_LOG names a file.
void RenderVertexBrdfPlugin::log_view(const vbrdf::LiveView &view) {
  const QByteArray path = qgetenv("VBRDF_RELIGHT_VIEW_LOG");
  if (path.isEmpty()) return;
  vbrdf::LiveViewRecord record;
  record.view = view;
  glGetIntegerv(GL_VIEWPORT, record.viewport);
  vbrdf::write_live_view(path.toStdString(), record);
}

void RenderVertexBrdfPlugin::Render(QAction *, MeshDocument &md, MLSceneGLSharedDataContext::PerMeshRenderingDataMap &,
                                    GLArea *gla) {
  if (gla == nullptr || gla->mvc() == nullptr) return;
  MLSceneGLSharedDataContext *shared = gla->mvc()->sharedDataContext();
  if (shared == nullptr) return;
  MeshModel *current = md.mm();
  for (MeshModel *mp : md.meshList) {
    if (mp == nullptr || !gla->meshVisibilityMap[mp->id()]) continue;
    if (mp == current && ensure_model(*mp, md, gla)) {
      vbrdf::LiveView view = vbrdf_render::current_gl_view();
      view.display = panel_ ? panel_->display() : vbrdf::LiveDisplay::Full;
      view.exposure = panel_ ? panel_->exposure() : 1.0f;
      try {
        live_->draw(view);
        log_view(view);
        const double eye_light[3] = {view.light_eye[0], view.light_eye[1], view.light_eye[2]};
        double world[3];
        if (panel_ && panel_->show_lights() && sphere_radius_ > 0 && view.light_eye[3] == 0.0f &&
            vbrdf::eye_to_world_direction(view.modelview, eye_light, world))
          vbrdf_render::draw_light_sphere(sphere_centre_, sphere_radius_, photo_lights_,
                                          {{float(world[0]), float(world[1]), float(world[2])}});
        continue;
      } catch (const std::exception &e) {
        md.Log.Log(GLLogStream::WARNING, e.what());
        if (panel_) panel_->set_message(QString::fromUtf8(e.what()), true);
      }
    }
    draw_as_meshlab_does(*shared, *mp, gla);  // other layers, or no model
  }
}

void RenderVertexBrdfPlugin::Finalize(QAction *, MeshDocument *, GLArea *gla) {
  if (gla) gla->makeCurrent();
  release();
}

void RenderVertexBrdfPlugin::release() {
  live_.reset();
  mesh_id_ = -1;
  fingerprint_ = 0;
  model_ok_ = false;
  if (panel_) {
    panel_->close();
    delete panel_;
    panel_ = nullptr;
  }
}
