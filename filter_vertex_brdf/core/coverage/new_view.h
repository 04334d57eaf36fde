#pragma once
// The vertices only a new viewpoint can cover, and where to put that camera: the part of the
// acquisition feedback that looks beyond the registered viewpoints (thesis 4.7).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "base/mesh_view.h"
#include "coverage/coverage.h"
#include "inputs/viewpoints.h"

namespace vbrdf {

// Why a vertex can only be covered from a new viewpoint.
enum NewViewReason : uint8_t {
  kNewViewUnseen = 1,    // no photo sees it
  kNewViewDiffuse = 2,   // needs diffuse samples; no placeable light of any viewpoint gives one
  kNewViewSpecular = 4,  // needs specular samples; no placeable light of any viewpoint gives one
};

// Per vertex, the NewViewReason of a vertex only a new viewpoint can cover (0: a registered one
// can): unseen (class kUnseen), or needing diffuse (specular) samples while no viewpoint that sees
// it cleanly (visible[i][v], one mask per viewpoint) has a placeable light that would give one.
std::vector<uint8_t> new_view_reasons(const MeshView &mesh, const std::vector<uint8_t> &classes,
                                      const std::vector<std::vector<uint8_t>> &visible,
                                      const std::vector<Viewpoint> &viewpoints, const LightSuggestionSettings &s);

// A direction from the object (`out`, world) that faces (N.D >= 0.5) the most of `vertices`: a
// hint where to put the next camera (occlusion is not considered). `facing` receives how many
// face it. False when no vertex faces any candidate. Normals are binned first, so the cost is
// O(vertices) + O(cells x candidates).
bool new_view_hint(const MeshView &mesh, const std::vector<uint32_t> &vertices, float out[3], size_t &facing);

} // namespace vbrdf
