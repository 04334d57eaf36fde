#version 430
// Per-vertex tests against a depth map that stays on the GPU (visibility/visibility_gl.cpp): the
// camera pass's code of each vertex (visibility.h: kCameraHidden, kCameraClear, or
// kFootprintPartial | mask of own-surface footprint texels) or the light pass's lit (1) / cast
// shadow (0). Four vertices per invocation, packed into one uint (byte k = vertex 4 i + k), so
// that one byte per vertex comes back instead of the whole depth map.
//
// The lookups are those of visibility_gl.cpp's CPU path (depth_clear, footprint_code), which the
// GL back end keeps for contexts without compute shaders; unit tests hold both paths against the
// CPU ray caster. Camera pass: window coordinates come from the undistorted projection the depth
// pass was rasterised with; a vertex outside that image or behind the camera is kCameraClear (the
// frustum is not this pass's concern: samples.cpp tests it with the distorted projection). The
// camera map may have one texel per u_divisor x u_divisor photo pixels (visibility/pass_size.h):
// window coordinates are map texels, footprints stay in photo pixels.
layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer Positions { float positions[]; };  // x y z per vertex, origin-relative
layout(std430, binding = 1) writeonly buffer Codes { uint codes[]; };
// Light pass with u_only != 0: bit v % 32 of only[v / 32] marks the vertices to test (those a
// photo sees: VisibilityBackend::light_pass's `only`); the others get 1 untested.
layout(std430, binding = 2) readonly buffer Only { uint only[]; };
uniform int u_only;

uniform uint u_vertex_count;
uniform uint u_first_word;       // words (groups of 4 vertices) before this dispatch
uniform int u_light_pass;        // 0: camera pass, 1: light pass
uniform mat4 u_view;             // on origin-relative positions
uniform mat4 u_projection;       // camera pass
uniform int u_width, u_height;  // depth map size in texels
uniform float u_tolerance;       // depth tolerance, world units
uniform float u_slack_per_depth; // camera pass: own_surface_depth_slack = tolerance + this * depth
uniform float u_light_scale;     // light pass: window mapping of light_view.h
uniform int u_perspective;       // light pass: 1 for a point light (w = depth)
uniform sampler2D u_depth;       // R32F linear depth, GL rows (row 0 = bottom of the image), or:
uniform int u_window_depth;      // 1: u_depth is a depth texture of window depth (light pass, orthographic)
uniform vec4 u_unproject;        // then: P[2][2], P[3][2], P[2][3], P[3][3] of u_projection (gl_depth.h)
uniform int u_divisor;           // camera pass: photo pixels per map texel, per axis
uniform int u_photo_width, u_photo_height;  // camera pass: photo size in pixels

ivec2 map_size() { return ivec2(u_width, u_height); }

// The view depth at texel (x, y): gl_depth.cpp's linear_depth_from_window for window depth.
float texel(int x, int y) {
  float t = texelFetch(u_depth, ivec2(x, y), 0).r;
  if (u_window_depth == 0) return t;
  float ndc = 2.0 * t - 1.0;
  return -(u_unproject.y - ndc * u_unproject.w) / (ndc * u_unproject.z - u_unproject.x);
}

// depth is at most the tolerance behind the farthest of the 2x2 texels nearest to window point w.
bool depth_clear(vec2 w, float depth) {
  int i0 = int(floor(w.x - 0.5)), j0 = int(floor(w.y - 0.5));
  int xa = clamp(i0, 0, map_size().x - 1), xb = clamp(i0 + 1, 0, map_size().x - 1);
  int ya = clamp(j0, 0, map_size().y - 1), yb = clamp(j0 + 1, 0, map_size().y - 1);
  float far_depth = max(max(texel(xa, ya), texel(xb, ya)), max(texel(xa, yb), texel(xb, yb)));
  return depth <= far_depth + u_tolerance;
}

bool own(int x, int y, float depth, float allowed) { return abs(texel(x, y) - depth) <= allowed; }

// The 2x2 bilinear footprint of photo point img (photo pixels, y down): which texels show the
// vertex's own surface. With u_divisor > 1 a photo texel is own surface only when the four map
// texels around its centre all are (conservative: visibility_gl.cpp's footprint_code).
uint footprint_code(vec2 img, float depth) {
  float allowed = u_tolerance + u_slack_per_depth * depth;
  int x0 = int(floor(img.x - 0.5)), y0 = int(floor(img.y - 0.5));
  ivec2 last = map_size() - 1;
  uint mask = 0u;
  for (int k = 0; k < 4; ++k) {
    int px = x0 + k % 2, py = y0 + k / 2;
    if (px < 0 || py < 0 || px >= u_photo_width || py >= u_photo_height) continue;
    bool is_own;
    if (u_divisor <= 1) {
      is_own = own(px, u_photo_height - 1 - py, depth, allowed);
    } else {
      vec2 w = (vec2(float(px) + 0.5, float(u_photo_height - py) - 0.5)) / float(u_divisor);
      int i0 = int(floor(w.x - 0.5)), j0 = int(floor(w.y - 0.5));
      int xa = clamp(i0, 0, last.x), xb = clamp(i0 + 1, 0, last.x);
      int ya = clamp(j0, 0, last.y), yb = clamp(j0 + 1, 0, last.y);
      is_own = own(xa, ya, depth, allowed) && own(xb, ya, depth, allowed) && own(xa, yb, depth, allowed) &&
               own(xb, yb, depth, allowed);
    }
    if (is_own) mask |= 1u << uint(k);
  }
  return mask == 15u ? 1u : (16u | mask);
}

uint camera_code(vec3 p) {
  vec4 view_pos = u_view * vec4(p, 1.0);
  float depth = -view_pos.z;
  vec4 clip = u_projection * view_pos;
  if (!(clip.w > 0.0) || !(depth > 0.0)) return 1u;
  vec2 w = (clip.xy / clip.w * 0.5 + 0.5) * vec2(map_size());  // map texels
  vec2 img = vec2(w.x * float(u_divisor), float(u_photo_height) - w.y * float(u_divisor));  // photo pixels
  if (!(img.x >= 0.0 && img.x < float(u_photo_width) && img.y >= 0.0 && img.y < float(u_photo_height))) return 1u;
  if (!depth_clear(w, depth)) return 0u;
  return footprint_code(img, depth);
}

uint light_code(vec3 p) {
  vec3 q = (u_view * vec4(p, 1.0)).xyz;
  float depth = -q.z;
  if (u_perspective != 0 && !(depth > 0.0)) return 1u;  // behind a point light: nothing in between
  float w = u_perspective != 0 ? depth : 1.0;
  vec2 win = (u_light_scale * q.xy / w + 1.0) * 0.5 * vec2(map_size());
  return depth_clear(win, depth) ? 1u : 0u;
}

void main() {
  uint word = u_first_word + gl_GlobalInvocationID.x;
  uint first = 4u * word;
  if (first >= u_vertex_count) return;
  uint bytes = 0u;
  for (uint k = 0u; k < 4u; ++k) {
    uint v = first + k;
    if (v >= u_vertex_count) break;
    if (u_light_pass != 0 && u_only != 0 && ((only[v / 32u] >> (v % 32u)) & 1u) == 0u) {
      bytes |= 1u << (8u * k);
      continue;
    }
    vec3 p = vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
    uint code = u_light_pass != 0 ? light_code(p) : camera_code(p);
    bytes |= code << (8u * k);
  }
  codes[word] = bytes;
}
