#pragma once
// How large the GL visibility depth passes are (visibility_gl.cpp): sized to what they must
// resolve, the mesh's edges as each pass sees them, not the photo's pixel count.
//
//  - Light pass (shadow map): texels per side so that the median projected length of the edges
//    of the faces turned to the light spans kShadowTexelsPerEdge texels. A shadow edge is then
//    placed to within a quarter of a vertex spacing (the 2x2 farthest-texel test moves it by at
//    most one texel). A projected edge is never longer than the edge, so a texel is never coarser
//    than the former per-mesh rule's "texel <= edge / 4"; what shrinks is its power-of-two
//    rounding and the margin of lights that see the surface obliquely. Never more than
//    resolved_shadow_map_size (that former size, also the relighting renderer's), never less than
//    kMinShadowMapSize, a multiple of 64.
//  - Camera pass: rendered at 1/d of the photo's resolution per axis (d = the camera divisor),
//    d the largest integer <= median projected edge (photo pixels, faces turned to the camera,
//    inside the image) / kCameraPixelsPerEdge, at most kMaxCameraDivisor, and d = 1 (photo
//    resolution, the exact former pass) unless the pass keeps >= kMinCameraPassSide texels on its
//    long side. Vertex lookups are mapped (photo pixel p -> map texel p / d). The occlusion test
//    keeps its tolerance; an occluder's silhouette moves by at most one map texel (d photo
//    pixels). The photo-resolution footprint (VisibilityMasks::footprints, kRimFootprint) is kept
//    conservative: a photo texel counts as the vertex's own surface only when all four map texels
//    around its centre do, within the photo-resolution depth slack, so a footprint that straddles
//    a depth jump wider than a map texel is never reported clean; some texels next to a silhouette
//    (a band <= d pixels wide) or on steep faces are reported as not own that a photo-resolution
//    pass would call own: their samples become rim samples (used where a vertex has < 2 clean).
//    kCameraPixelsPerEdge is 3 (d = 2 from 6-pixel edges): at 1.5 the 1 M-vertex benchmark at
//    4000x3000 (3.2-pixel edges, d = 2) raised the albedo error from 0.46 to 0.59
//    (docs/decisions/visibility_and_speed.md).
#include <string>
#include <vector>

#include "base/mesh_view.h"
#include "gl/light_view.h"
#include "inputs/camera.h"
#include "visibility/visibility.h"

namespace vbrdf {

constexpr float kShadowTexelsPerEdge = 4.0f;
constexpr int kMinShadowMapSize = 1024;
constexpr int kMaxShadowMapSize = 4096;
constexpr float kCameraPixelsPerEdge = 3.0f;
constexpr int kMaxCameraDivisor = 4;
constexpr int kMinCameraPassSide = 512;

// Up to ~4096 triangle edges spread over the mesh (one per sampled face), relative to `origin`:
// midpoint, edge vector and unit face normal (zero for a degenerate face), 3 floats each.
struct EdgeSample {
  std::vector<float> mid, vec, normal;
  size_t size() const { return mid.size() / 3; }
};
EdgeSample sample_edges(const MeshView &mesh, const float origin[3]);

// The shadow-map size of one light pass (see above): settings.shadow_map_size when positive;
// for 0, from the edges as the light view `lv` sees them, clamped to [kMinShadowMapSize,
// max_size]. max_size: resolved_shadow_map_size for the mesh.
int light_pass_size(const EdgeSample &edges, const LightView &lv, const VisibilitySettings &settings, int max_size);

// The camera divisor d for `shot` (see above): settings.camera_pass_divisor when positive; for 0,
// from the edges as the camera sees them. `view` maps origin-relative positions to the camera's
// view space (GL convention: looking along -z). Throws InputError when the setting is negative.
int camera_pass_divisor(const EdgeSample &edges, const Shot &shot, const float view_col_major[16],
                        const VisibilitySettings &settings);

// The camera the depth pass renders for divisor d: the same frustum over ceil(W/d) x ceil(H/d)
// pixels, d times larger (VCG pixel coordinates divide by d).
Shot divided_shot(const Shot &shot, int divisor);

// "camera 2000x1500 (photo / 2), shadow maps 1088-1536" ("/ 1-2" when divisors vary); "" when
// no depth map was rendered.
std::string describe_pass_sizes(const VisibilityBackend::PassSizes &sizes);

} // namespace vbrdf
