#include "io/registered_project.h"

#include <QDomDocument>
#include <QFile>
#include <QFileInfo>
#include <wrap/qt/shot_qt.h>

#include "base/errors.h"

namespace vbrdf {

namespace {

QString absolute_in(const QString &dir, const QString &name) {
  return QFileInfo(QFileInfo(name).isAbsolute() ? name : dir + "/" + name).absoluteFilePath();
}

QDomElement camera_element(QDomDocument &doc, const Shot &shot) {
  // vcglib's writer, as MeshLab saves a project (text, not binary).
  return WriteShotToQDomNode(shot, doc);
}

std::string patched_project(const std::string &project_path, const RegistrationResult &registration) {
  QFile file(QString::fromStdString(project_path));
  QDomDocument doc;
  if (!file.open(QIODevice::ReadOnly) || !doc.setContent(&file))
    throw ProcessingError("Cannot read the project '" + project_path + "' again to write its corrected cameras.");
  const QString dir = QFileInfo(file).absolutePath();
  const QDomElement root = doc.documentElement();
  for (QDomElement m = root.firstChildElement("MeshGroup").firstChildElement("MLMesh"); !m.isNull();
       m = m.nextSiblingElement("MLMesh"))
    m.setAttribute("filename", absolute_in(dir, m.attribute("filename")));
  for (QDomElement r = root.firstChildElement("RasterGroup").firstChildElement("MLRaster"); !r.isNull();
       r = r.nextSiblingElement("MLRaster")) {
    for (QDomElement p = r.firstChildElement("Plane"); !p.isNull(); p = p.nextSiblingElement("Plane"))
      p.setAttribute("fileName", absolute_in(dir, p.attribute("fileName")));
    Shot shot;
    const QDomNode camera = r.firstChild();
    if (!ReadShotFromQDomNode(shot, camera)) continue;
    if (const Shot *corrected = registration.corrected_for(shot))
      r.replaceChild(camera_element(doc, *corrected), camera);
  }
  return doc.toString(1).toStdString();
}

std::string new_project(const std::string &mesh_path, const std::vector<Raster> &rasters,
                        const RegistrationResult &registration) {
  QDomDocument doc("MeshLabDocument");
  QDomElement root = doc.createElement("MeshLabProject");
  doc.appendChild(root);
  QDomElement meshes = doc.createElement("MeshGroup");
  QDomElement mesh = doc.createElement("MLMesh");
  mesh.setAttribute("label", QFileInfo(QString::fromStdString(mesh_path)).fileName());
  mesh.setAttribute("filename", QString::fromStdString(mesh_path));
  meshes.appendChild(mesh);
  root.appendChild(meshes);
  QDomElement group = doc.createElement("RasterGroup");
  for (const Raster &raster : rasters) {
    QDomElement r = doc.createElement("MLRaster");
    r.setAttribute("label", QString::fromStdString(raster.label));
    const Shot *corrected = registration.corrected_for(raster.shot);
    r.appendChild(camera_element(doc, corrected ? *corrected : raster.shot));
    QDomElement plane = doc.createElement("Plane");
    plane.setAttribute("semantic", 1);
    plane.setAttribute("fileName", QString::fromStdString(raster.image_path));
    r.appendChild(plane);
    group.appendChild(r);
  }
  root.appendChild(group);
  return doc.toString(1).toStdString();
}

} // namespace

std::string registered_project_text(const std::string &project_path, const std::string &mesh_path,
                                    const std::vector<Raster> &rasters, const RegistrationResult &registration) {
  if (!project_path.empty() && QFileInfo(QString::fromStdString(project_path)).isReadable())
    return patched_project(project_path, registration);
  return new_project(mesh_path, rasters, registration);
}

} // namespace vbrdf
