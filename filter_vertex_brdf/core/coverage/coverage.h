#pragma once
// Acquisition coverage (thesis 4.4.1, 4.5, 4.7): which vertices the photos taken so far cover,
// and which light to place next.
//
// A vertex is diffusely covered by a photo when the photo sees it and the sample is usable for
// the diffuse colour (lit, not grazing, no highlight, unsaturated: is_diffuse_sample), and
// specularly covered when the sample is an unsaturated lit highlight (is_specular_sample).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "inputs/camera.h"
#include "base/mesh_view.h"
#include "samples/samples.h"

namespace vbrdf {

enum CoverageClass : uint8_t {
  kUnseen = 0,             // no photo sees the vertex: needs another viewpoint
  kSeenNotDiffuse = 1,     // seen, but fewer than min_diffuse diffuse samples
  kDiffuseNoSpecular = 2,  // diffusely covered, fewer than min_specular specular samples
  kFullyCovered = 3,
};
const char *coverage_class_name(CoverageClass c);
// Display colours (RGBA8) of the classes, also given in the log legend.
std::array<uint8_t, 4> coverage_class_color(CoverageClass c);

struct CoverageCounts {
  uint16_t seen = 0, diffuse = 0, specular = 0;
};

// Per-vertex counts from a chunk's samples (out has chunk.vertex_count entries).
void count_coverage_chunk(const SampleChunk &chunk, CoverageCounts *out);

CoverageClass classify_coverage(const CoverageCounts &c, int min_diffuse = 1, int min_specular = 1);

struct LightSuggestionSettings {
  float specular_threshold = kDefaultSpecularThreshold;  // T_s
  float diffuse_threshold = kCoverageDiffuseThreshold;   // T_d
  int bins = 36;                    // latitude and longitude divisions (thesis: 36)
  float min_elevation_deg = 5.0f;   // lights must be at least this far above the camera's image plane
  float margin_deg = 2.0f;          // aim this far inside a threshold (thesis: "a small amount")
};

// Placeable lights: unit directions whose camera-frame z (towards the camera) is at least
// sin(min_elevation): in front of the object, on the camera-facing hemisphere.
bool light_is_placeable(const Shot &viewpoint, const float dir_world[3], float min_elevation_deg);

// Algorithm 1 (diffuse) and 3 (specular): the ideal light for one vertex seen from `eye_dir`
// (unit vector from the vertex to the camera), moved onto the placeable hemisphere when needed.
// Returns false when no placeable light can cover the vertex that way.
bool ideal_diffuse_light(const float normal[3], const float eye_dir[3], const Shot &viewpoint,
                         const LightSuggestionSettings &s, float out_light[3]);
bool ideal_specular_light(const float normal[3], const float eye_dir[3], const Shot &viewpoint,
                          const LightSuggestionSettings &s, float out_light[3]);

// Whether light L would give a diffuse / specular sample (ignores cast shadows, which need the
// light's depth pass: a prediction, checked when the photo arrives).
bool light_covers_diffuse(const float normal[3], const float eye_dir[3], const float light[3], const LightSuggestionSettings &s);
bool light_covers_specular(const float normal[3], const float eye_dir[3], const float light[3], const LightSuggestionSettings &s);

struct LightSuggestion {
  bool valid = false;
  float dir_world[3] = {0, 0, 0};
  float dir_cam[3] = {0, 0, 0};  // RTI convention: x right, y up, z towards the camera
  float azimuth_deg = 0;         // atan2(y, x) in the camera frame: 0 = right, 90 = up
  float elevation_deg = 0;       // asin(z): 90 = at the camera, 0 = in the image plane
  double covered_weight = 0;     // weighted number of needing vertices it covers
  size_t covered_vertices = 0;   // number of needing vertices it covers
  size_t needing_vertices = 0;   // vertices that need this kind of coverage
  size_t uncoverable_vertices = 0;  // needing vertices no placeable light covers (new viewpoint)
};

enum class CoverageKind { Diffuse, Specular };

// Greedy next light (Algorithm 2 with latitude/longitude bins). `needs[v]` > 0 is the weight of a
// vertex that needs coverage of `kind` (0: does not need it), e.g. 1 for uncovered vertices, more
// for vertices whose fit quality (DQ/SQ) is poor. Only vertices seen by `viewpoint` (visible[v])
// are considered. Speed: vertices are grouped by quantised (normal, eye direction) before the
// candidate lights are generated and scored, so the cost is O(vertices) + O(groups x bins).
LightSuggestion suggest_next_light(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                   const float *needs, CoverageKind kind, const LightSuggestionSettings &s);

// Exact reference: scores every distinct ideal light of every needing vertex against every
// needing vertex (O(n^2): tests only).
LightSuggestion suggest_next_light_brute_force(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible,
                                               const float *needs, CoverageKind kind, const LightSuggestionSettings &s);

// Number of needing vertices light `dir_world` covers (exact, per vertex).
size_t count_covered(const MeshView &mesh, const Shot &viewpoint, const uint8_t *visible, const float *needs,
                     CoverageKind kind, const float dir_world[3], const LightSuggestionSettings &s);

} // namespace vbrdf
