#pragma once
// Cameras of registered photos: MeshLab's vcg::Shot (perspective, per-raster intrinsics and
// extrinsics). Projection always goes through vcglib's Shot::Project.
//
// Pixel conventions:
//  - VCG pixels (what Shot::Project returns, CenterPx in .mlp): origin at the bottom-left image
//    corner, y up.
//  - Image pixels (what every function here returns, and how photos are indexed): origin at the
//    top-left corner, x right, y down, pixel centres at integer + 0.5. image.y = height - vcg.y.
#include <string>
#include <vcg/math/shot.h>

namespace vbrdf {

using Shot = vcg::Shot<float>;

// One registered photo: what the .mlp / MeshLab's RasterModel gives.
struct Raster {
  std::string label;       // raster label (MeshLab layer name)
  std::string image_path;  // absolute path of the photo file
  Shot shot;
  int width() const { return shot.Intrinsics.ViewportPx[0]; }
  int height() const { return shot.Intrinsics.ViewportPx[1]; }
};

// True when the shot can project: positive focal length, pixel size and viewport, finite values.
bool shot_is_valid(const Shot &shot);

// True when the shot's pose is exactly the identity (at the world origin, axes along the world's):
// the pose of a raster that was never registered (a .mlp written by hand or by a tool that had
// no registration); a registration never lands there exactly.
bool shot_is_identity(const Shot &shot);

// True when two shots are one registration (photos of one viewpoint): equal viewport, and focal
// length, pixel size, principal point, radial distortion, rotation and translation equal to 1e-6
// relative (absolute below magnitude 1). Symmetric; false when any value is NaN.
bool same_shot(const Shot &a, const Shot &b);

struct ImagePoint {
  float x = 0, y = 0;      // image pixels (top-left origin, y down)
  bool in_front = false;   // point is in front of the camera (positive depth)
};

// Projects a world point with vcglib's Shot::Project and converts to image pixels.
ImagePoint project_to_image(const Shot &shot, const float world[3]);

// Depth of a world point along the camera's viewing axis (positive in front).
float view_depth(const Shot &shot, const float world[3]);

// Camera centre in world coordinates.
void camera_centre(const Shot &shot, float out[3]);

// Direction given in the camera frame (x right, y up, z towards the viewer: RTI .lp convention)
// converted to world coordinates with the shot's rotation; returned normalised.
void camera_to_world_direction(const Shot &shot, const float dir_cam[3], float out_world[3]);
void world_to_camera_direction(const Shot &shot, const float dir_world[3], float out_cam[3]);

// OpenGL view and projection matrices (column-major) reproducing Shot::Project without lens
// distortion: a point rasterised into a width x height viewport lands on the same pixel as
// project_to_image (GL window y up == VCG pixel y). near/far are positive distances.
void gl_view_matrix(const Shot &shot, float out_col_major[16]);
void gl_projection_matrix(const Shot &shot, float near_dist, float far_dist, float out_col_major[16]);

} // namespace vbrdf
