#pragma once
// MeshLab's decoded raster images handed to the core's photo cache, so that each photo is decoded
// once. MeshLab 2020.09 decodes every raster's photo into a QImage when it opens a project
// (Plane::Plane: QImage(path)); the fit reads those pixels in place instead of decoding the file a
// second time and holding it twice in memory.
#include <memory>
#include <string>

#include "meshlab_host.h"

#include "core/inputs/photo.h"

namespace vbrdf_plugin {

// The pixels of `image` as the core reads them (no copy: the result shares the QImage's data and
// keeps it alive). False for layouts the core does not read in place (indexed colour, premultiplied
// alpha, packed 16-bit formats, ...): the core then decodes the file itself.
bool host_pixels_of(const QImage &image, vbrdf::HostPixels &out);

// True when the file is a PNG or a JPEG (by its signature, not its name): Qt (>= 5.12) decodes
// those at the file's own depth (16-bit PNG as RGBA64 / Grayscale16), as the core's decoder does.
// Other formats (TIFF through an optional Qt plugin, ...) may come out of Qt at another depth, so
// the core decodes those files itself. False for a file that cannot be read.
bool qt_keeps_the_photos_depth(const std::string &path);

// The first image plane of every raster of `document` whose file qt_keeps_the_photos_depth and
// whose image host_pixels_of takes, by the plane's path (what document_rasters reports as the
// raster's image_path).
std::shared_ptr<const vbrdf::HostPhotos> host_photos(const MeshDocument &document);

} // namespace vbrdf_plugin
