#pragma once
// The MeshLab 2020.09 side of the plugin's host adapter: what the shared filters (plugin/*.cpp) use
// of MeshLab where 2020.09 and 2025.07 differ, under one set of names. Its twin,
// meshlab_2025/meshlab_host.h, gives the same names for 2025.07; CMake puts exactly one of the two
// folders on the include path (docs/pymeshlab.md#one-adapter).
#include <vector>

#include <common/interfaces.h>

#include "core/inputs/camera.h"

namespace vbrdf_plugin {
namespace host {

using FilterInterface = MeshFilterInterface;
using FilterArity = MeshFilterInterface::FILTER_ARITY;
using RasterPlane = Plane;

// The document's rasters in layer order.
inline std::vector<RasterModel *> rasters(MeshDocument &document) {
  return std::vector<RasterModel *>(document.rasterList.begin(), document.rasterList.end());
}
inline std::vector<const RasterModel *> rasters(const MeshDocument &document) {
  return std::vector<const RasterModel *>(document.rasterList.begin(), document.rasterList.end());
}
// Index of MeshLab's current raster, -1 when none.
inline int current_raster_index(MeshDocument &document) { return document.rasterList.indexOf(document.rm()); }
inline bool raster_visible(const RasterModel &raster) { return raster.visible; }

// Shotm is vcg::Shot<float> here, the core's Shot.
inline vbrdf::Shot core_shot(const Shotm &shot) { return shot; }
inline Shotm host_shot(const vbrdf::Shot &shot) { return shot; }

// The text of a string or file-name parameter. False for other types.
inline bool text_value(const Value &value, QString &text) {
  if (value.isFileName()) text = value.getFileName();
  else if (value.isString()) text = value.getString();
  else return false;
  return true;
}

// A direction parameter (the relight filter's novel light).
inline RichPoint3f direction_parameter(const QString &name, const vcg::Point3f &value, const QString &label,
                                       const QString &tooltip) {
  return RichPoint3f(name, value, label, tooltip);
}
inline vcg::Point3f direction_value(const RichParameterList &params, const QString &name) {
  return params.getPoint3f(name);
}

} // namespace host
} // namespace vbrdf_plugin
