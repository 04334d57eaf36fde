// The viewer page (contract in web_viewer.h).
#include "publish/web_viewer.h"

#include "base/errors.h"
#include "vbrdf_web_viewer_template.h"

namespace vbrdf {

namespace {

// Placeholders of the template (build_viewer.mjs writes each exactly once).
const char *const kGlbData = "@@VBRDF_GLB_BASE64@@";
const char *const kGlbUrl = "@@VBRDF_GLB_URL@@";
const char *const kTitle = "@@VBRDF_TITLE@@";

std::string html_escape(const std::string &s) {
  std::string out;
  for (char c : s) {
    switch (c) {
    case '&': out += "&amp;"; break;
    case '<': out += "&lt;"; break;
    case '>': out += "&gt;"; break;
    case '"': out += "&quot;"; break;
    case '\'': out += "&#39;"; break;
    case '@': out += "&#64;"; break;
    default: out += c;
    }
  }
  return out;
}

void replace_once(std::string &page, const char *placeholder, const std::string &value) {
  const size_t at = page.find(placeholder);
  if (at == std::string::npos)
    throw ProcessingError(std::string("The web viewer template lacks ") + placeholder + ": rebuild the plugin.");
  page.replace(at, std::char_traits<char>::length(placeholder), value);
}

} // namespace

bool web_viewer_available() { return web_viewer_template::size > 0; }

std::string web_viewer_missing_reason() { return web_viewer_available() ? "" : web_viewer_template::missing_reason; }

std::string base64_encode(const uint8_t *data, size_t size) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const uint32_t v = uint32_t(data[i]) << 16 | uint32_t(data[i + 1]) << 8 | data[i + 2];
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += kDigits[(v >> 6) & 63];
    out += kDigits[v & 63];
  }
  if (i < size) {
    const uint32_t v = uint32_t(data[i]) << 16 | (i + 1 < size ? uint32_t(data[i + 1]) << 8 : 0u);
    out += kDigits[v >> 18];
    out += kDigits[(v >> 12) & 63];
    out += i + 1 < size ? kDigits[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string web_viewer_page(const std::vector<uint8_t> &glb, const std::string &glb_url, const std::string &title) {
  if (!web_viewer_available())
    throw InputError("This build has no web viewer (" + web_viewer_missing_reason() +
                     "): rebuild after 'npm ci' in filter_vertex_brdf/web.");
  std::string page(web_viewer_template::text, web_viewer_template::size);
  replace_once(page, kTitle, html_escape(title));
  replace_once(page, kGlbUrl, glb.empty() ? html_escape(glb_url) : "");
  replace_once(page, kGlbData, glb.empty() ? "" : base64_encode(glb.data(), glb.size()));
  return page;
}

} // namespace vbrdf
