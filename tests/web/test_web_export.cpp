// The web export (publish/web_export.h, web_viewer.h): exact read-back, refusals, the pages.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>

#include <tiny_gltf.h>
#include <unistd.h>

#include "base/errors.h"
#include "io/output_ply.h"
#include "io/result_schema.h"
#include "publish/web_export.h"
#include "publish/web_viewer.h"
#include "test_scenes.h"
#include "web_glb_check.h"

using namespace vbrdf;

namespace {

std::string temp_dir() {
  static std::string dir;
  if (dir.empty()) {
    char tmpl[] = "/tmp/vbrdf_web_test_XXXXXX";
    dir = mkdtemp(tmpl);
  }
  return dir;
}

// A sphere with a varied fit (one vertex without a model, some k_d C above 1 when `bright`).
std::string write_result(const std::string &name, bool bright, bool with_fit = true) {
  const float c[3] = {0.1f, -0.2f, 0.3f};
  const MeshData mesh = test::make_sphere(c, 0.7f, 12, 16);
  const size_t n = mesh.positions.size() / 3;
  std::vector<VertexRecord> records(n);
  for (size_t v = 0; v < n; ++v) {
    VertexRecord &r = records[v];
    r.fit.color[0] = 1.0f;
    r.fit.color[1] = 0.25f + 0.5f * float(v % 7) / 7.0f;
    r.fit.color[2] = 0.1f + 0.3f * float(v % 5) / 5.0f;
    r.fit.kd = bright && v % 9 == 0 ? 1.7f : 0.2f + 0.6f * float(v % 11) / 11.0f;
    r.fit.ks = v % 3 ? 0.1f + 0.01f * float(v % 13) : 0.0f;
    r.fit.shininess = r.fit.ks > 0 ? 3.0f + float(v % 17) * 7.1f : 0.0f;
    r.fit.dq = 0.1f * float(v % 21);
    r.fit.sq = 0.07f * float(v % 29);
    r.fit.status = v == 5 ? kFitNone : r.fit.ks > 0 ? kFitFull : kFitDiffuseOnly;
    r.lobe_form = 2;
    r.diffuse_form = v % 2 ? 1.0f : 0.0f;
  }
  const std::string path = temp_dir() + "/" + name;
  write_result_ply(path, mesh.view(), std::vector<uint8_t>(4 * n, 128), result_attributes(records, with_fit));
  return path;
}

std::vector<uint8_t> read_bytes(const std::string &path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

} // namespace

TEST(WebExport, GlbReadsBackToTheResultExactly) {
  const std::string ply = write_result("bright.ply", true);
  const WebGlb glb = build_web_glb(read_result_ply(ply), ply, WebCapture());
  EXPECT_TRUE(glb.albedo_written);
  EXPECT_EQ(glb.lobe, LobeForm::GgxNH);
  EXPECT_EQ(check_glb_bytes_against_result(ply, glb.bytes), "");
}

TEST(WebExport, NoAlbedoAttributeWhenEveryValueIsWithinRange) {
  const std::string ply = write_result("plain.ply", false);
  const WebGlb glb = build_web_glb(read_result_ply(ply), ply, WebCapture());
  EXPECT_FALSE(glb.albedo_written);
  EXPECT_EQ(check_glb_bytes_against_result(ply, glb.bytes), "");
}

// The check can fail: a GLB with an attribute dropped, or one value changed, is caught.
TEST(WebExport, CheckCatchesADroppedAttributeAndAChangedValue) {
  const std::string ply = write_result("drop.ply", true);
  const WebGlb glb = build_web_glb(read_result_ply(ply), ply, WebCapture());
  tinygltf::Model m;
  tinygltf::TinyGLTF io;
  std::string err, warn;
  ASSERT_TRUE(io.LoadBinaryFromMemory(&m, &err, &warn, glb.bytes.data(), unsigned(glb.bytes.size())));
  tinygltf::Model dropped = m;
  dropped.meshes[0].primitives[0].attributes.erase("_KS");
  std::ostringstream s1(std::ios::binary);
  ASSERT_TRUE(io.WriteGltfSceneToStream(&dropped, s1, false, true));
  const std::string b1 = s1.str();
  EXPECT_NE(check_glb_bytes_against_result(ply, std::vector<uint8_t>(b1.begin(), b1.end())).find("_KS missing"),
            std::string::npos);
  tinygltf::Model changed = m;
  const tinygltf::Accessor &a = changed.accessors[size_t(changed.meshes[0].primitives[0].attributes["_SHININESS"])];
  float *first = reinterpret_cast<float *>(changed.buffers[0].data.data() + changed.bufferViews[size_t(a.bufferView)].byteOffset);
  first[1] = std::nextafter(first[1], 1e9f);
  std::ostringstream s2(std::ios::binary);
  ASSERT_TRUE(io.WriteGltfSceneToStream(&changed, s2, false, true));
  const std::string b2 = s2.str();
  EXPECT_NE(check_glb_bytes_against_result(ply, std::vector<uint8_t>(b2.begin(), b2.end())).find("_SHININESS differs at vertex 1"),
            std::string::npos);
}

TEST(WebExport, AResultWithoutAModelIsRefusedNamingTheFileAndTheRemedy) {
  const std::string ply = write_result("nomodel.ply", false, false);
  try {
    build_web_glb(read_result_ply(ply), ply, WebCapture());
    FAIL() << "no error";
  } catch (const InputError &e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(ply), std::string::npos) << msg;
    EXPECT_NE(msg.find("kd"), std::string::npos) << msg;
  }
}

TEST(WebExport, NonFiniteValuesNeverReachTheFile) {
  const std::string ply = write_result("nan.ply", false);
  ResultPly result = read_result_ply(ply);
  result.vertex_properties["dq"][3] = std::nanf("");
  try {
    build_web_glb(result, ply, WebCapture());
    FAIL() << "no error";
  } catch (const InputError &e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("vertex 3's 'dq' is not finite"), std::string::npos) << msg;
    EXPECT_NE(msg.find(ply), std::string::npos) << msg;
  }
  result = read_result_ply(ply);
  result.mesh.normals[6] = result.mesh.normals[7] = result.mesh.normals[8] = 0;
  EXPECT_THROW(build_web_glb(result, ply, WebCapture()), InputError);
}

TEST(WebExport, OutputsAreRefusedWhenTheyExistAndOverwriteIsOff) {
  const std::string ply = write_result("out.ply", false);
  const WebGlb glb = build_web_glb(read_result_ply(ply), ply, WebCapture());
  const std::string out = temp_dir() + "/out_web.glb";
  write_web_outputs(glb, out, false, OverwritePolicy::Refuse, "t");
  EXPECT_EQ(read_bytes(out), glb.bytes);
  EXPECT_THROW(write_web_outputs(glb, out, false, OverwritePolicy::Refuse, "t"), InputError);
  EXPECT_NO_THROW(write_web_outputs(glb, out, false, OverwritePolicy::Replace, "t"));
}

TEST(WebExport, ViewerPagesCarryTheGlbOrItsUrlAndTheModelText) {
  if (!web_viewer_available()) GTEST_SKIP() << web_viewer_missing_reason();
  const std::string ply = write_result("page.ply", false);
  const WebGlb glb = build_web_glb(read_result_ply(ply), ply, WebCapture());
  const WebOutputPaths paths = write_web_outputs(glb, temp_dir() + "/page_web.glb", true, OverwritePolicy::Replace,
                                                 "a <title> & @@VBRDF_GLB_URL@@");
  std::ifstream h(paths.html), hh(paths.hosted_html), model(VBRDF_MODEL_GLSL);
  const std::string html((std::istreambuf_iterator<char>(h)), std::istreambuf_iterator<char>());
  const std::string hosted((std::istreambuf_iterator<char>(hh)), std::istreambuf_iterator<char>());
  const std::string glsl((std::istreambuf_iterator<char>(model)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(glsl.empty());
  EXPECT_NE(html.find(base64_encode(glb.bytes.data(), glb.bytes.size())), std::string::npos);
  EXPECT_NE(html.find(glsl), std::string::npos) << "the page does not carry " << VBRDF_MODEL_GLSL << " verbatim";
  EXPECT_NE(hosted.find(">page_web.glb</script>"), std::string::npos);
  EXPECT_EQ(hosted.find(base64_encode(glb.bytes.data(), 30)), std::string::npos);
  EXPECT_NE(html.find("<title>a &lt;title&gt; &amp; &#64;&#64;VBRDF_GLB_URL&#64;&#64;</title>"), std::string::npos);
}

TEST(WebExport, Base64) {
  const uint8_t b[] = {'f', 'o', 'o', 'b', 'a', 'r'};
  EXPECT_EQ(base64_encode(b, 0), "");
  EXPECT_EQ(base64_encode(b, 1), "Zg==");
  EXPECT_EQ(base64_encode(b, 2), "Zm8=");
  EXPECT_EQ(base64_encode(b, 3), "Zm9v");
  EXPECT_EQ(base64_encode(b, 6), "Zm9vYmFy");
}
