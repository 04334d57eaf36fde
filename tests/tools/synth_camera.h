#pragma once
// Cameras of the synthetic captures as MeshLab vcg::Shot<float>s, and their .mlp text.
// The renderer uses the shot parsed back from the exact .mlp attribute text (the way MeshLab reads
// it), so that what MeshLab projects and what was rendered agree to float rounding.
#include <string>

#include <vcg/math/shot.h>

#include "synth_math.h"

namespace synth {

using Shot = vcg::Shot<float>;

// Computed in double so that the .mlp text is the exact decimal of the intended camera.
struct CameraSpec {
  double centre[3];                  // world
  double right[3], up[3], back[3];   // camera axes in world (the camera looks along -back)
  int width = 640, height = 480;
  double focal_mm = 0, pixel_mm = 0;
  double cx = 0, cy = 0;             // principal point, VCG pixels (origin bottom-left, y up)
};

// Camera at `distance` from `target`, seen from azimuth (around +y, 0 = +z) and elevation
// (degrees), horizontal field of view fov_x; principal point offset in pixels (x right, y up).
CameraSpec look_at(V3 target, float distance, float azimuth_deg, float elevation_deg, int width,
                   int height, float fov_x_deg, float offset_x, float offset_y);

// Distance at which a sphere of `radius` around the target fits the smaller field of view.
float framing_distance(float radius, int width, int height, float fov_x_deg);

// <VCGCamera> attribute values, formatted like spot_dir24/project.mlp (%.10g).
struct VcgCameraText {
  std::string translation, lens_distortion, viewport, pixel_size, center, focal, rotation;
};
VcgCameraText format_camera(const CameraSpec &spec);

// The shot MeshLab builds from that text (vcglib's ReadShotFromQDomNode, non-binary branch).
Shot shot_from_text(const VcgCameraText &text);

// Rows of the shot's rotation (camera axes in world) and its centre.
V3 shot_axis(const Shot &shot, int row);
V3 shot_centre(const Shot &shot);

// Camera-frame direction (x right, y up, z towards the viewer) to world, normalised.
V3 camera_to_world(const Shot &shot, V3 dir_cam);

} // namespace synth
