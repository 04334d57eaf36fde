#pragma once
// Camera registration refined from the photos, per viewpoint (the rasters that share one camera and
// differ only in light). A scan registered to its photos by hand or by mutual information is good
// to a pixel or two; a fit made through such a camera reads each vertex's colour from a neighbouring
// pixel, across albedo edges and silhouettes. This stage measures how far each camera's projection
// of the mesh is from its photos and corrects it:
//  1. the photos' light-normalised normal map (normal_map.h: photometric stereo per pixel, which
//     neither the light nor the albedo changes);
//  2. the image-plane warp that carries each visible vertex onto the pixel showing its own normal
//     (image_alignment.h): shift first, then roll and focal length where the data determine them;
//  3. applied to the shot as a turn of the camera about its centre (pitch, yaw, roll) and a change of
//     focal length, when the measured misregistration is above the threshold; then measured again.
// Cameras, not the mesh, move: visibility, samples and the result all follow the corrected shots.
#include <string>
#include <vector>

#include "base/callbacks.h"
#include "base/mesh_view.h"
#include "inputs/camera.h"
#include "inputs/light_source.h"
#include "inputs/photo.h"
#include "registration/image_alignment.h"
#include "visibility/visibility.h"

namespace vbrdf {

struct RegistrationSettings {
  // Off by default. The measurement alone is not trusted with a correction: on the synthetic
  // captures of synthesize_scene, whose cameras are exact, it reads up to 1.3 px (open mesh borders
  // and broad glossy lobes bias the Lambertian normal map: docs/method.md#registration-refined-from-the-photos);
  // the fit checks each correction against the fitted model's residual, which refuses those
  // (fit/residual_alignment.h, run/fit_run.cpp). But on a mesh smoother than the surface the map
  // reads false shifts of 0.4-0.6 px (three of the seven real reliefs smoothed by 3.5 deg) that the
  // residual, made with the same normals, cannot refuse (docs/decisions/registration.md), so it
  // stays the user's choice.
  bool enabled = false;
  // A viewpoint whose measured misregistration (RMS displacement of its visible vertices, pixels)
  // is below this keeps its camera: the estimate on exact cameras stays under it
  // (docs/benchmark.md#real-captures-cameras-off-and-smoothed-normals).
  float threshold_px = 0.25f;
  // Beyond this the registration is not "a pixel or two off" and no local refinement is trusted:
  // the camera is kept and a warning asks for a registration in MeshLab.
  float max_correction_px = 8.0f;
  int min_photos = 4;         // photometric stereo needs at least 4 lights
  size_t min_vertices = 200;  // visible vertices a viewpoint needs to be measured
  // Visible vertices used (evenly strided beyond it): 20 000 fix a shift to far below the bias
  // of the normal map itself (docs/benchmark.md#real-captures-cameras-off-and-smoothed-normals).
  size_t max_points = 20000;
  // Photos of a viewpoint the normal map uses, their lights spread evenly (0: all): the map's cost
  // grows with them, its accuracy hardly beyond a few dozen. 16 read the shared scenes' exact cameras
  // as all their photos do (within 0.01 px) but left a small object's roll noisier (spot: 0.153
  // against 0.176 deg of 0.2); 24 does not.
  size_t max_photos = 24;
  NormalMapSettings normal_map;
  AlignmentSettings alignment;
};

struct ViewpointRegistration {
  std::vector<size_t> rasters;  // raster indices of the viewpoint
  std::string label;            // its first raster's label
  bool measured = false;
  std::string not_measured;     // why, when !measured
  size_t points = 0;            // visible vertices on determined pixels
  size_t map_photos = 0;        // photos the normal map was made from
  double before_px = 0;         // measured misregistration at the given camera
  double after_px = 0;          // measured again at the corrected camera (before_px when unchanged)
  ImageWarp correction;         // what was applied (identity when unchanged)
  double shift_x = 0, shift_y = 0;  // where the correction moves the principal point (pixels)
  bool roll_determined = false, scale_determined = false;
  bool applied = false;
  bool too_large = false;       // above max_correction_px: kept, with a warning
  Shot given, corrected;        // the viewpoint's shot as given and as corrected (equal unless applied)
  // Checked by the fitted model's residual (fit/residual_alignment.h; mean absolute RGB error of
  // per-vertex fits with the mesh's normals), when a correction was applied:
  bool residual_checked = false;
  size_t residual_vertices = 0;
  double residual_given = 0, residual_corrected = 0, residual_final = 0;
  bool refused = false;             // the corrected camera's residual was clearly higher: camera kept
  double refined_x = 0, refined_y = 0;  // the shift the residual added to the correction (pixels)
  double refined_roll = 0;              // and the roll (radians)
  // The residual's minimum lay farther from the correction than it is trusted to refine (the mesh's
  // normals are then taken to be off): where, and the trusted distance; nothing refined.
  bool residual_beyond_trust = false;
  double residual_found_x = 0, residual_found_y = 0, residual_trusted_px = 0;
};

struct RegistrationResult {
  std::vector<Raster> rasters;  // the rasters with corrected shots (the input's where unchanged)
  std::vector<ViewpointRegistration> viewpoints;
  std::vector<std::string> warnings;  // "WARNING: ..." lines
  double seconds = 0;
  bool any_applied() const;
  // The corrected shot of the viewpoint whose given shot is `shot` (same_shot), or null when that
  // viewpoint kept its camera or is not one of them: for rasters outside the fit (hidden ones).
  const Shot *corrected_for(const Shot &shot) const;
};

// Measures and corrects every viewpoint's camera (see above). lights[r] is raster r's light (its
// direction from the object's centre is used for point lights). `visibility` runs one camera pass
// per viewpoint (its GL context, if any, must be current). Photos come from `photos` (decoded as
// the samples are). Viewpoints that cannot be measured (fewer than min_photos photos, lights in
// one plane, point lights, too few visible vertices) keep their camera and say why. Logs one line per viewpoint.
RegistrationResult refine_registration(const MeshView &mesh, const std::vector<Raster> &rasters,
                                       const std::vector<LightSource> &lights, PhotoCache &photos,
                                       VisibilityBackend &visibility, const RegistrationSettings &settings,
                                       const LogFn &log);

// The shot that projects every point where `warp` carries the given shot's projection: the camera
// turned about its centre by the warp's rotation and its focal length scaled (exact for a pinhole
// camera; lens distortion is kept as it is).
Shot warped_shot(const Shot &shot, const ImageWarp &warp);

// The principal point of a shot in image pixels (top-left origin, y down), and its focal length in
// pixels (the mean over the two axes of the pixel size).
void principal_point(const Shot &shot, double out[2]);
double focal_pixels(const Shot &shot);

// One report line per viewpoint: "viewpoint 'label' (N photos): ..." (measured, corrected or why not).
std::string describe_registration(const ViewpointRegistration &v, const RegistrationSettings &settings);

} // namespace vbrdf
