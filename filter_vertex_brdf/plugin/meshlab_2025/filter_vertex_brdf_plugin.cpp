#include "filter_vertex_brdf_plugin.h"

#include <cstdlib>
#include <functional>
#include <string>

#include <QDir>
#include <QFile>
#include <QFileInfo>

#include "filter_failure.h"
#include "meshlab_bridge.h"
#include "plugin_filters.h"

using vbrdf_plugin::PluginFilter;

namespace {

// The .mlp the filter reads relative paths against and names its default outputs after. PyMeshLab
// leaves the document's label and path empty, so scripts pass it (the vbrdf module does).
const char *const kProjectFile = "projectFile";

void add_project_file(RichParameterList &params) {
  params.addParam(RichString(kProjectFile, QString(), "Project file (.mlp)",
                             "The project the document was loaded from (PyMeshLab does not tell the filter): relative "
                             "paths are read against its folder and default outputs are named after it. Empty: the "
                             "document's own project, else the mesh file."));
}

// The one .mlp beside the current mesh's file that names that file, else "": the project a script
// most likely loaded when it did not say (PyMeshLab's load_project leaves no trace of it).
QString project_beside_the_mesh(const MeshDocument &md) {
  const MeshModel *mesh = md.mm();
  if (mesh == nullptr || mesh->fullName().isEmpty()) return QString();
  const QFileInfo mesh_file(mesh->fullName());
  QString found;
  for (const QFileInfo &candidate : mesh_file.absoluteDir().entryInfoList({"*.mlp"}, QDir::Files)) {
    QFile file(candidate.absoluteFilePath());
    if (!file.open(QIODevice::ReadOnly) || !file.readAll().contains(mesh_file.fileName().toUtf8())) continue;
    if (!found.isEmpty()) return QString();  // two candidates: no guess
    found = candidate.absoluteFilePath();
  }
  return found;
}

// Gives the document the project's path as its label, where MeshLab's GUI and meshlabserver put it:
// the 'Project file' parameter, else the document's own label, else the one project beside the mesh.
void use_project_file(MeshDocument &md, const RichParameterList &params,
                      const std::function<void(const std::string &)> &log) {
  const QString path = params.hasParameter(kProjectFile) ? params.getString(kProjectFile) : QString();
  if (path.isEmpty()) {
    if (!md.docLabel().isEmpty()) return;
    const QString guess = project_beside_the_mesh(md);
    if (guess.isEmpty()) return;
    md.setDocLabel(guess);
    log("Vertex BRDF: project file " + vbrdf_plugin::utf8(guess) + " (the one .mlp beside the mesh that names it; "
        "set 'Project file' [projectFile] to choose another).");
    return;
  }
  const QFileInfo project(path);
  if (!project.isFile())
    throw MLException("Project file '" + path + "' [" + kProjectFile + "] does not exist: give the path of the .mlp "
                      "the document was loaded from, or leave it empty.");
  md.setDocLabel(project.absoluteFilePath());
}

// PyMeshLab creates a GL context only for filters that ask for one, and a process without a Qt
// platform plugin and a display aborts when asked: the filters run on the CPU unless the user sets
// VBRDF_OPENGL=1 (under a display or xvfb-run; docs/pymeshlab.md#opengl).
bool opengl_requested() {
  const char *value = std::getenv("VBRDF_OPENGL");
  return value != nullptr && std::string(value) == "1";
}

} // namespace

FilterVertexBrdfPlugin::FilterVertexBrdfPlugin() : filters_(vbrdf_plugin::make_plugin_filters()) {
  for (size_t id = 0; id < filters_.size(); ++id) {
    typeList.push_back(ActionIDType(id));
    actionList.push_back(new QAction(filters_[id]->name(), this));
  }
}

FilterVertexBrdfPlugin::~FilterVertexBrdfPlugin() = default;

QString FilterVertexBrdfPlugin::pluginName() const { return "FilterVertexBrdf"; }

QString FilterVertexBrdfPlugin::filterName(ActionIDType id) const {
  return (id >= 0 && size_t(id) < filters_.size()) ? filters_[id]->name() : QString();
}

QString FilterVertexBrdfPlugin::filterInfo(ActionIDType id) const {
  return (id >= 0 && size_t(id) < filters_.size()) ? filters_[id]->info() : QString();
}

const PluginFilter &FilterVertexBrdfPlugin::filterOf(const QAction *action) const {
  return *filters_.at(size_t(ID(action)));
}

FilterPlugin::FilterClass FilterVertexBrdfPlugin::getClass(const QAction *action) const {
  return filterOf(action).filterClass();
}

FilterPlugin::FilterArity FilterVertexBrdfPlugin::filterArity(const QAction *action) const {
  return filterOf(action).arity();
}

int FilterVertexBrdfPlugin::getRequirements(const QAction *action) { return filterOf(action).requirements(); }

int FilterVertexBrdfPlugin::getPreConditions(const QAction *action) const { return filterOf(action).preConditions(); }

int FilterVertexBrdfPlugin::postCondition(const QAction *action) const { return filterOf(action).postConditions(); }

bool FilterVertexBrdfPlugin::requiresGLContext(const QAction *) const { return opengl_requested(); }

RichParameterList FilterVertexBrdfPlugin::initParameterList(const QAction *action, const MeshDocument &md) {
  RichParameterList params;
  filterOf(action).initParameters(md, params);  // never dereferences md.mm(): PyMeshLab lists on an empty document
  add_project_file(params);
  return params;
}

std::map<std::string, QVariant> FilterVertexBrdfPlugin::applyFilter(const QAction *action,
                                                                     const RichParameterList &params, MeshDocument &md,
                                                                     unsigned int &postConditionMask,
                                                                     vcg::CallBackPos *cb) {
  const PluginFilter &filter = filterOf(action);
  use_project_file(md, params, [this](const std::string &line) { log(GLLogStream::FILTER, line); });
  std::map<std::string, QVariant> figures;
  vbrdf_plugin::FilterRun run{md, params, cb, glContext,
                              [this](GLLogStream::Levels level, const std::string &line) { log(level, line); },
                              [&figures](const std::string &name, double value) { figures[name] = QVariant(value); }};
  const std::string failure = vbrdf_plugin::apply_filter(filter, run);
  if (!failure.empty()) {
    log(GLLogStream::WARNING, filter.name().toStdString() + " failed: " + failure);
    throw MLException(QString::fromStdString(failure));
  }
  postConditionMask = (unsigned int)filter.postConditions();
  return figures;
}
