#include "inputs/project.h"

#include <QDomDocument>
#include <QFile>
#include <QFileInfo>
#include <wrap/qt/shot_qt.h>

#include "base/errors.h"
#include "base/file_util.h"

namespace vbrdf {

namespace {
std::string absolute_in(const QString &dir, const QString &name) {
  return QFileInfo(QFileInfo(name).isAbsolute() ? name : dir + "/" + name).absoluteFilePath().toStdString();
}
} // namespace

Project read_project(const std::string &mlp_path) {
  QFile file(QString::fromStdString(mlp_path));
  if (!file.open(QIODevice::ReadOnly))
    throw InputError("Cannot open project '" + mlp_path + "': check the path.");
  QDomDocument doc;
  QString xml_error;
  int xml_line = 0;
  if (!doc.setContent(&file, &xml_error, &xml_line))
    throw InputError("Project '" + mlp_path + "' is not valid XML (line " + std::to_string(xml_line) +
                     ": " + xml_error.toStdString() + ").");
  const QString dir = QFileInfo(file).absolutePath();

  Project project;
  project.project_path = QFileInfo(file).absoluteFilePath().toStdString();
  const QDomElement root = doc.documentElement();
  const QDomElement mesh = root.firstChildElement("MeshGroup").firstChildElement("MLMesh");
  if (mesh.isNull() || mesh.attribute("filename").isEmpty())
    throw InputError("Project '" + mlp_path + "' has no mesh (<MeshGroup><MLMesh filename=...>).");
  project.mesh_path = absolute_in(dir, mesh.attribute("filename"));

  int index = 0;
  for (QDomElement r = root.firstChildElement("RasterGroup").firstChildElement("MLRaster"); !r.isNull();
       r = r.nextSiblingElement("MLRaster"), ++index) {
    Raster raster;
    raster.label = r.attribute("label").toStdString();
    const std::string who = "Project '" + mlp_path + "', raster " + std::to_string(index) + " ('" + raster.label + "')";
    // Like MeshLab: the camera is the FIRST child; anything else leaves the shot undefined.
    const QDomNode camera = r.firstChild();
    if (!ReadShotFromQDomNode(raster.shot, camera) || !shot_is_valid(raster.shot))
      throw InputError(who + " has no valid camera: <VCGCamera> must be the first child of <MLRaster> "
                             "with a focal length, viewport and rotation. Register the photo in MeshLab first.");
    const QDomElement plane = r.firstChildElement("Plane");
    if (plane.isNull() || plane.attribute("fileName").isEmpty())
      throw InputError(who + " has no photo (<Plane fileName=...>).");
    raster.image_path = absolute_in(dir, plane.attribute("fileName"));
    if (raster.label.empty()) raster.label = file_name_of(raster.image_path);
    project.rasters.push_back(raster);
  }
  return project;
}

} // namespace vbrdf
