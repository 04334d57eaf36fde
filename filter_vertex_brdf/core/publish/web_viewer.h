#pragma once
// The viewer page of a published fit: one self-contained HTML file (three.js, the viewer and the
// product's GLSL model, shaders/reflectance_model.glsl, bundled at build time by
// filter_vertex_brdf/web/build_viewer.mjs into a template compiled into the library), with the GLB
// either embedded (base64: opens from file:// with no server and no network) or loaded by URL
// (the hosted variant, for a web server). Nothing is fetched from anywhere else at run time.
// How the page works: docs/web.md#the-viewer.
#include <cstdint>
#include <string>
#include <vector>

namespace vbrdf {

// False in a build made without the viewer bundle (no node_modules when it was configured).
bool web_viewer_available();
// Why the viewer is missing ("" when available), for messages.
std::string web_viewer_missing_reason();

// The page: with `glb` non-empty the GLB is embedded; else the page loads `glb_url` (relative to
// the page). `title` is the page's title (HTML-escaped here). Throws InputError when the viewer is
// not available in this build.
std::string web_viewer_page(const std::vector<uint8_t> &glb, const std::string &glb_url, const std::string &title);

// Standard base64 (RFC 4648, with padding).
std::string base64_encode(const uint8_t *data, size_t size);

} // namespace vbrdf
