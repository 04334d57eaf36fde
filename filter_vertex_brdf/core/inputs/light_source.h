#pragma once
// The light of one photo, in the mesh's world frame: either directional (one direction for the
// whole object, the RTI .lp model) or a point light at a position (RTI domes, a flash or a lamp
// close to the object), whose direction and irradiance change across the object.
//
// Irradiance model (point light): E(x) = intensity * (reference_distance / |P - x|)^2, an
// isotropic source (no lamp fall-off with angle). reference_distance is one constant for all the
// photos of a fit (the median distance of the lights from the object's centre), so E = intensity
// at the object's centre for a light at the median distance: k_d and k_s keep the scale of a
// directional fit (unit light) and lights at different distances keep their true ratio.
#include <array>
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "inputs/camera.h"

namespace vbrdf {

struct LightSource {
  bool positional = false;
  // Unit vector towards the light. Directional: exact. Point: from the object's centre (used
  // only where one direction per photo is needed: colour-chart shading, logs, light suggestion).
  std::array<float, 3> direction{{0, 0, 1}};
  std::array<float, 3> position{{0, 0, 0}};  // point light, world frame, mesh units
  float reference_distance = 1;              // point light: see the irradiance model above (> 0)
  float intensity = 1;                       // relative radiant intensity (> 0)

  static LightSource directional(const std::array<float, 3> &towards_light);
};

// Unit direction from world point x towards the light. A point light at x itself (distance below
// 1e-12 of reference_distance) returns `direction`, never NaN.
void light_direction_at(const LightSource &light, const float x[3], float out[3]);

// Irradiance factor at x: `intensity` for a directional light; for a point light the model above,
// with the distance clamped below at 1e-3 * reference_distance (finite everywhere).
float light_irradiance_at(const LightSource &light, const float x[3]);

// True when any light of the set is a point light (the stages that only a point light needs, such
// as the per-sample fall-off, are skipped otherwise).
bool any_positional(const std::vector<LightSource> &lights);

// Directional lights from world-frame directions towards the light (normalised).
std::vector<LightSource> directional_lights(const std::vector<std::array<float, 3>> &towards_light);

// The world-frame directions of a set of lights (LightSource::direction).
std::vector<std::array<float, 3>> light_directions(const std::vector<LightSource> &lights);

// Where the object is, to place lights given relative to it and to check positions.
struct LightPlacement {
  Bounds box;  // the mesh's bounding box (world); empty (no mesh) only serves directional .lp files
  // > 0: directions from an .lp become point lights on a dome of this radius (mesh units) around
  // the bounding box's centre. 0: directions stay directional.
  float dome_radius = 0;
  // Mesh units per unit of the positions in the light file: 1 for our .json (mesh units); a
  // Relight .dome is in cm and needs the scale of the mesh (e.g. 10 for a mesh in mm).
  // 0 = not given (a .dome then fails with a message that asks for it).
  float unit_scale = 0;
};

// The placement of a mesh: its bounding box, dome radius and unit scale as given.
LightPlacement light_placement_of(const MeshView &mesh, float dome_radius, float unit_scale);

// Reads the lights of every raster from `path`, in one of three forms (docs/parameters.md#light-file):
//  - RTI .lp (RTIBuilder / Relight): per photo a direction in its camera frame. Directional, or
//    point lights on a dome when placement.dome_radius > 0.
//  - .json (our plain form): {"images": [...], "position_world": [[x,y,z], ...]} in the mesh's
//    world frame, or "position_camera" in the camera frame of each photo's raster (x right, y up,
//    z towards the viewer, origin at the camera centre), mesh units times placement.unit_scale
//    (0 = 1); optional "intensity": a number or one per image.
//  - Relight .dome (JSON): lightConfiguration "directional" (directions), "spherical"
//    (positionsSphere, or directions * domeDiameter / 2 + verticalOffset on z) or "lights3d"
//    (positions3d), in Relight's frame (origin where the optical axis meets the object, here the
//    depth of the bounding box's centre; x right, y up in the image, z towards the camera; cm,
//    times placement.unit_scale). Lights belong to the photos in file-name order, as in Relight.
// Lights are matched to rasters by image file name (light_file.h: find_light_for_image).
// Throws InputError naming the file (and raster or entry) for: unreadable or malformed file, a
// raster without a light, entries that match no raster, a .dome without unit_scale, a point light
// inside the mesh's bounding box or nearer to it than half its diagonal (the model of a small
// source does not hold there), non-finite values.
std::vector<LightSource> resolve_lights(const std::vector<Raster> &rasters, const std::string &path,
                                        const LightPlacement &placement);

// Writes our .json form ("images" + "position_world", mesh frame and units) atomically; `rms`
// (optional, one per image) is written as "position_rms_world", how far the rays that located each
// light miss it (readers ignore it). Throws InputError for mismatched sizes or non-finite values,
// ProcessingError on I/O.
void write_light_positions(const std::string &path, const std::vector<std::string> &images,
                           const std::vector<std::array<float, 3>> &positions_world,
                           const std::vector<float> &rms = {});

// Checks positional lights against the placement (the rule above); throws InputError naming
// `path` and the photo of the first bad light. Directional lights always pass.
void check_light_positions(const std::vector<LightSource> &lights, const std::vector<Raster> &rasters,
                           const LightPlacement &placement, const std::string &path);

// Sets reference_distance of every point light to the median distance of the point lights from
// the bounding box's centre (the irradiance model above); no-op without point lights.
void set_reference_distance(std::vector<LightSource> &lights, const LightPlacement &placement);

// One line for logs and reports: "16 directional lights" / "16 point lights, 2.9-3.1 mesh units
// from the object's centre (the object subtends up to 24 degrees from the nearest)".
std::string describe_lights(const std::vector<LightSource> &lights, const LightPlacement &placement);

} // namespace vbrdf
