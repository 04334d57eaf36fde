#pragma once
// The MeshLab 2025.07 (PyMeshLab 2025.7) side of the plugin's host adapter: the same names as
// meshlab_2020/meshlab_host.h, for MeshLab's FilterPlugin interface (double precision: Scalarm is
// double, Shotm vcg::Shot<double>; private raster list; RasterPlane).
#include <vector>

#include <common/plugins/interfaces/filter_plugin.h>
#include <common/ml_document/mesh_document.h>
#include <common/ml_shared_data_context/ml_plugin_gl_context.h>
#include <common/parameters/rich_parameter_list.h>
#include <common/parameters/rich_parameters.h>

#include "core/inputs/camera.h"

namespace vbrdf_plugin {
namespace host {

using FilterInterface = FilterPlugin;
using FilterArity = FilterPlugin::FilterArity;
using RasterPlane = ::RasterPlane;

inline std::vector<RasterModel *> rasters(MeshDocument &document) {
  std::vector<RasterModel *> out;
  for (RasterModel &raster : document.rasterIterator()) out.push_back(&raster);
  return out;
}
inline std::vector<const RasterModel *> rasters(const MeshDocument &document) {
  std::vector<const RasterModel *> out;
  for (const RasterModel &raster : document.rasterIterator()) out.push_back(&raster);
  return out;
}
inline int current_raster_index(MeshDocument &document) {
  int index = 0;
  for (const RasterModel &raster : document.rasterIterator()) {
    if (&raster == document.rm()) return index;
    ++index;
  }
  return -1;
}
inline bool raster_visible(const RasterModel &raster) { return raster.isVisible(); }

// A shot in another scalar, field by field (vcglib's Camera::Construct does not compile across
// scalars: its camera-type enum differs per scalar).
template <class To, class From>
vcg::Shot<To> convert_shot(const vcg::Shot<From> &shot) {
  vcg::Shot<To> out;
  const vcg::Camera<From> &in = shot.Intrinsics;
  vcg::Camera<To> &cam = out.Intrinsics;
  cam.FocalMm = To(in.FocalMm);
  cam.ViewportPx = in.ViewportPx;
  cam.PixelSizeMm = vcg::Point2<To>::Construct(in.PixelSizeMm);
  cam.CenterPx = vcg::Point2<To>::Construct(in.CenterPx);
  cam.DistorCenterPx = vcg::Point2<To>::Construct(in.DistorCenterPx);
  for (size_t i = 0; i < cam.k.size(); ++i) cam.k[i] = To(in.k[i]);
  cam.cameraType = typename vcg::Camera<To>::CameraType(int(in.cameraType));
  out.Extrinsics.SetRot(vcg::Matrix44<To>::Construct(shot.Extrinsics.Rot()));
  out.Extrinsics.SetTra(vcg::Point3<To>::Construct(shot.Extrinsics.Tra()));
  return out;
}

// Shotm is vcg::Shot<double>; the core computes in float, as under 2020.09.
inline vbrdf::Shot core_shot(const Shotm &shot) { return convert_shot<float>(shot); }
inline Shotm host_shot(const vbrdf::Shot &shot) { return convert_shot<Scalarm>(shot); }

// The text of a string parameter (file names are strings in 2025.07). False for other types.
inline bool text_value(const Value &value, QString &text) {
  if (!value.isString()) return false;
  text = value.getString();
  return true;
}

inline RichDirection direction_parameter(const QString &name, const vcg::Point3f &value, const QString &label,
                                         const QString &tooltip) {
  return RichDirection(name, Point3m::Construct(value), label, tooltip);
}
inline vcg::Point3f direction_value(const RichParameterList &params, const QString &name) {
  return vcg::Point3f::Construct(params.getPoint3m(name));
}

} // namespace host
} // namespace vbrdf_plugin
