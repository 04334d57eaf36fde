#pragma once
// Writers of the synthetic project: MeshLab .mlp, RTI .lp, PLY (mesh and ground truth), CSV.
#include <string>
#include <vector>

#include "synth_camera.h"
#include "synth_scene.h"

namespace synth {

// One photo of the capture (training or held-out).
struct Photo {
  std::string file;      // path relative to the folder of its .mlp / .lp
  int view = 0;          // camera index
  std::string dir_text;  // light direction in the camera frame as written in the .lp
  V3 dir_cam;            // the same, parsed back from dir_text and normalised
  V3 dir_world;          // world frame (through the shot's rotation)
  bool point = false;    // --light-distance: an isotropic point light at pos_world
  V3 pos_world;          // centre + distance * dir_world (world frame, mesh units)
};

// Where the point lights are (--light-distance), for the light files and READMEs.
struct PointLightSetup {
  V3 centre;               // the scene's bounding-box centre
  float half_diagonal = 0; // half the bounding-box diagonal
  float distance = 0;      // of every light from the centre (--light-distance * half_diagonal)
};

struct View {
  float azimuth_deg = 0, elevation_deg = 0;
  CameraSpec spec;
  VcgCameraText text;
  Shot shot;
};

// Per-vertex ground truth beyond the material (visibility and light flags).
struct VertexTruth {
  std::vector<std::vector<uint8_t>> visible;  // [view][vertex]
  std::vector<uint8_t> visible_any;
  std::vector<std::vector<char>> lit;         // [photo][vertex]: '0' N.L<=0, 's' cast shadow, '1' lit
  std::vector<std::vector<char>> lit_heldout;
};

std::string basename_of(const std::string &path);
void make_dirs(const std::string &dir);  // mkdir -p
void write_text(const std::string &path, const std::string &text);

// Project with `mesh_path` and one raster per photo, the exact layout of spot_dir24/project.mlp.
void write_mlp(const std::string &path, const std::string &mesh_path,
               const std::vector<Photo> &photos, const std::vector<View> &views);
void write_lp(const std::string &path, const std::vector<Photo> &photos);
// lights_world.json: every light's description (directional; with `point`, also positions).
void write_lights_json(const std::string &path, const std::vector<Photo> &photos,
                       float irradiance, const PointLightSetup *point = nullptr);
// lights.json, the plugin's light-position form: {"images": [...], "position_world": [...]}
// (images named as in the .lp). Only for point lights.
void write_positions_json(const std::string &path, const std::vector<Photo> &photos);

// Binary little-endian PLY: positions and normals only (what a scanner would give).
void write_mesh_ply(const std::string &path, const Scene &s);
// Mesh + ground-truth float properties (see ground_truth/README.md).
void write_gt_ply(const std::string &path, const Scene &s, const VertexTruth &gt);
void write_gt_csv(const std::string &path, const Scene &s, const VertexTruth &gt);
void write_lit_table(const std::string &path, const std::vector<Photo> &photos,
                     const std::vector<std::vector<char>> &lit, size_t vertex_count);

} // namespace synth
