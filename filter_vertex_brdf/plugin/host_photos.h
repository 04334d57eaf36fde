#pragma once
// MeshLab's decoded raster images handed to the core's photo cache (issue 13: decode each photo
// once). MeshLab 2020.09 decodes every raster's photo into a QImage when it opens a project
// (Plane::Plane: QImage(path)); the fit reads those pixels in place instead of decoding the file a
// second time and holding it twice in memory.
#include <memory>

#include <common/interfaces.h>

#include "core/inputs/photo.h"

namespace vbrdf_plugin {

// The pixels of `image` as the core reads them (no copy: the result shares the QImage's data and
// keeps it alive). False for layouts the core does not read in place (indexed colour, premultiplied
// alpha, packed 16-bit formats, ...): the core then decodes the file itself.
bool host_pixels_of(const QImage &image, vbrdf::HostPixels &out);

// The first image plane of every raster of `document` that host_pixels_of takes, by the plane's
// path (what document_rasters reports as the raster's image_path).
std::shared_ptr<const vbrdf::HostPhotos> host_photos(const MeshDocument &document);

} // namespace vbrdf_plugin
