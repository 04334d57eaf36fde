#pragma once
// Reads a GLB written by build_web_glb back with tinygltf and checks it against the result PLY it
// came from, float32 bit for bit: POSITION, NORMAL, indices, COLOR_0 (clamped k_d C), _ALBEDO
// (present exactly when some k_d C channel exceeds 1), _KS, _SHININESS, _DIFFUSE_FORM, _FIT_STATUS,
// _DQ, _SQ, and the model's declaration in the primitive's extras. Returns "" when everything
// matches, else the first difference.
#include <cstdint>
#include <string>
#include <vector>

namespace vbrdf {

std::string check_glb_against_result(const std::string &result_ply, const std::string &glb_path);
std::string check_glb_bytes_against_result(const std::string &result_ply, const std::vector<uint8_t> &glb);

} // namespace vbrdf
