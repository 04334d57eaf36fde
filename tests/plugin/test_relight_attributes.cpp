// The live view's model from a MeshLab mesh (plugin/relight_attributes.h): read back from the
// float attributes the fit stores, and the message (with MeshLab's normal rendering) when they are
// missing. No GL: the drawing itself is tested in tests/unit/test_live_relight.cpp.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <common/interfaces.h>
#include <vcg/complex/algorithms/create/platonic.h>

#include "core/base/errors.h"
#include "core/io/result_schema.h"
#include "meshlab_bridge.h"
#include "relight_attributes.h"

namespace {

using namespace vbrdf_plugin;

MeshModel *sphere_mesh(MeshDocument &document) {
  MeshModel *m = document.addNewMesh("", "sphere");
  vcg::tri::Sphere(m->cm, 2);
  vcg::tri::UpdateNormal<CMeshO>::PerVertexNormalizedPerFace(m->cm);
  return m;
}

// Stores a fit on every vertex as the fit filter does (schema attributes by name).
void store_fit(MeshModel &mesh, const std::vector<std::string> &leave_out = {}) {
  const MeshArrays arrays = mesh_arrays(mesh);
  std::vector<vbrdf::VertexRecord> records(arrays.vertex_index.size());
  for (size_t v = 0; v < records.size(); ++v) {
    vbrdf::VertexFit &f = records[v].fit;
    f.color[0] = 1.0f, f.color[1] = 0.5f, f.color[2] = 0.25f;
    f.kd = 0.5f + 0.001f * float(v % 100);
    f.ks = v % 3 == 0 ? 0.0f : 0.2f;
    f.shininess = f.ks > 0 ? 30.0f : 0.0f;
    f.dq = 1.25f;
    f.sq = 0.75f;
    f.status = v % 3 == 0 ? vbrdf::kFitDiffuseOnly : vbrdf::kFitFull;
    records[v].lobe_form = 1.0f;  // N.H
    records[v].diffuse_form = 1.0f;  // coated
  }
  StoredResults stored;
  stored.paint = false;
  for (vbrdf::VertexAttribute &a : vbrdf::result_attributes(records, true)) {
    bool skip = false;
    for (const std::string &name : leave_out) skip = skip || a.name == name;
    if (!skip) stored.attributes.push_back(std::move(a));
  }
  store_results(mesh, arrays, stored);
}

TEST(RelightAttributes, ReadsTheStoredFit) {
  MeshDocument document;
  MeshModel *mesh = sphere_mesh(document);
  EXPECT_EQ(relight_model_fingerprint(*mesh), uint64_t(0));
  store_fit(*mesh);
  const RelightModel model = relight_model(*mesh);
  ASSERT_EQ(model.fits.size(), size_t(mesh->cm.vn));
  EXPECT_EQ(model.modelled, model.fits.size());
  EXPECT_EQ(model.lobe, vbrdf::LobeForm::BlinnNH);
  EXPECT_FALSE(model.diffuse.varies());
  EXPECT_EQ(model.diffuse.uniform, vbrdf::DiffuseForm::Coated);
  for (size_t v = 0; v < model.fits.size(); ++v) {
    EXPECT_FLOAT_EQ(model.fits[v].kd, 0.5f + 0.001f * float(v % 100));
    EXPECT_FLOAT_EQ(model.fits[v].color[1], 0.5f);
    EXPECT_FLOAT_EQ(model.fits[v].sq, 0.75f);
    EXPECT_EQ(model.fits[v].status, v % 3 == 0 ? vbrdf::kFitDiffuseOnly : vbrdf::kFitFull);
  }
  // A re-fit changes the fingerprint (the live view re-uploads).
  const uint64_t before = relight_model_fingerprint(*mesh);
  EXPECT_NE(before, uint64_t(0));
  auto kd = vcg::tri::Allocator<CMeshO>::FindPerVertexAttribute<float>(mesh->cm, "kd");
  kd[0] = 0.9f;
  EXPECT_NE(relight_model_fingerprint(*mesh), before);
}

// Without the model: the message names the mesh, the missing attribute and both remedies.
TEST(RelightAttributes, MissingAttributesGiveTheMessage) {
  for (const std::vector<std::string> &leave_out :
       std::vector<std::vector<std::string>>{{"kd", "ks", "shininess", "color_r", "color_g", "color_b", "fit_status"},
                                             {"shininess"}}) {
    MeshDocument document;
    MeshModel *mesh = sphere_mesh(document);
    if (leave_out.size() == 1) store_fit(*mesh, leave_out);
    try {
      relight_model(*mesh);
      ADD_FAILURE() << "no error without '" << leave_out.front() << "'";
    } catch (const vbrdf::InputError &e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("'sphere'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("'" + leave_out.front() + "'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("MeshLab's normal rendering"), std::string::npos) << msg;
      EXPECT_NE(msg.find("Vertex BRDF: load result attributes"), std::string::npos) << msg;
      EXPECT_NE(msg.find("Vertex BRDF: fit per-vertex reflectance"), std::string::npos) << msg;
    }
  }
}

} // namespace
