// Where a vertex shader puts its projected vertex: on the 1/16-pixel grid that every GL
// rasteriser resolves (GL and GLES guarantee at least 4 sub-pixel bits). Rasterisers differ in
// how finely they place vertices (Mesa's llvmpipe 1/256 pixel, SwiftShader 1/16), and at 1/32 pixel
// a sharp highlight or a crease moves by an 8-bit level; with the vertices already on the coarsest
// grid both draw the same pixels from the same positions. Used by every renderer of the model:
// the relight renderer (core/relight/relight_render.cpp), the live view (live_relight.cpp) and the
// web viewer (filter_vertex_brdf/web), whose images are compared pixel for pixel
// (docs/web.md#checked-in-a-browser). No #version here: the callers put it first
// (relight/reflectance_model_source.h vertex_program_source, the viewer page).

// `clip`: the clip-space position; `viewport`: the target's size in pixels. A vertex behind the
// eye (w <= 0) is left as it is: clipping, not the grid, decides what it draws.
vec4 snap_to_subpixel_grid(vec4 clip, vec2 viewport) {
  if (!(clip.w > 0.0)) return clip;
  vec2 px = (clip.xy / clip.w * 0.5 + 0.5) * viewport;
  px = floor(px * 16.0 + 0.5) / 16.0;
  return vec4((px / viewport * 2.0 - 1.0) * clip.w, clip.zw);
}
