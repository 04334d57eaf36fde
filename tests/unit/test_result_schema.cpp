// Result schema (core/result_schema.h): the PLY writer and reader address every per-vertex
// attribute by name; a write/read round trip keeps each one, and the file format stays the one
// existing result files, tools and the README table use.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <gtest/gtest.h>
#include <set>
#include <sstream>

#include "base/errors.h"
#include "io/output_ply.h"
#include "io/result_ply.h"
#include "io/result_schema.h"
#include "test_paths.h"
#include "test_scenes.h"

using namespace vbrdf;

namespace {
// A record whose every stored field holds a value no other field holds (per vertex v).
VertexRecord distinct_record(size_t v) {
  const float o = 0.001f * float(v);
  VertexRecord r;
  r.diffuse[0] = 0.11f + o, r.diffuse[1] = 0.12f + o, r.diffuse[2] = 0.13f + o;
  r.n_visible = 21.0f + float(v), r.n_diffuse = 22.0f + float(v), r.n_specular = 23.0f + float(v);
  r.coloured = float(v % 4);
  r.fit.kd = 1.1f + o, r.fit.ks = 1.2f + o, r.fit.shininess = 1.3f + o;
  r.fit.color[0] = 1.41f + o, r.fit.color[1] = 1.42f + o, r.fit.color[2] = 1.43f + o;
  r.fit.dq = 1.5f + o, r.fit.sq = 1.6f + o, r.fit.rmse = 1.7f + o;
  r.fit.status = uint8_t(v % 5);
  r.fit.iterations = uint16_t(31 + v);
  r.diffuse_form = float(v % 2);
  r.diffuse_deconvolved = float((v / 2) % 2);  // not equal to diffuse_form at every vertex
  return r;
}

// The PLY's property names, in header order, after x y z nx ny nz red green blue alpha.
std::vector<std::string> vertex_property_names(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> names;
  std::string line;
  bool vertex = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string word, type, name;
    ls >> word;
    if (word == "element") ls >> name, vertex = name == "vertex";
    if (word == "property" && vertex) ls >> type >> name, names.push_back(type + " " + name);
  }
  return names;
}
} // namespace

TEST(ResultSchema, FileFormatIsTheDocumentedOne) {
  // The format existing files, tools and the README's output table use: names, order and type.
  const std::vector<std::string> expected = {
      "float diffuse_r", "float diffuse_g", "float diffuse_b", "float n_visible", "float n_diffuse",
      "float n_specular", "float coloured", "float kd", "float ks", "float shininess", "float color_r",
      "float color_g", "float color_b", "float dq", "float sq", "float fit_rmse", "float fit_status",
      "float fit_iterations", "float material", "float lobe_form", "float diffuse_form",
      "float diffuse_deconvolved", "float mesh_nx", "float mesh_ny", "float mesh_nz", "float normal_moved"};
  const MeshData mesh = test::make_grid(2, 1.0f, 0.0f);
  const size_t n = mesh.positions.size() / 3;
  const std::string dir = test::scratch_dir("schema_format");
  std::vector<VertexRecord> records;
  for (size_t v = 0; v < n; ++v) records.push_back(distinct_record(v));
  write_result_ply(dir + "/full.ply", mesh.view(), std::vector<uint8_t>(4 * n, 9), result_attributes(records, true));
  std::vector<std::string> names = vertex_property_names(dir + "/full.ply");
  ASSERT_GE(names.size(), 10u);
  EXPECT_EQ(std::vector<std::string>(names.begin() + 10, names.end()), expected);
  // Without the reflectance fit: only the first seven.
  write_result_ply(dir + "/basic.ply", mesh.view(), std::vector<uint8_t>(4 * n, 9), result_attributes(records, false));
  names = vertex_property_names(dir + "/basic.ply");
  ASSERT_GE(names.size(), 10u);
  EXPECT_EQ(std::vector<std::string>(names.begin() + 10, names.end()),
            std::vector<std::string>(expected.begin(), expected.begin() + 7));
}

TEST(ResultSchema, EachPropertyHoldsItsOwnField) {
  // Read back by literal names (not through the schema): a swap of two entries' accessors fails.
  const MeshData mesh = test::make_grid(2, 1.0f, 0.0f);
  const size_t n = mesh.positions.size() / 3;
  std::vector<VertexRecord> records;
  for (size_t v = 0; v < n; ++v) records.push_back(distinct_record(v));
  const std::string path = test::scratch_dir("schema_fields") + "/r.ply";
  write_result_ply(path, mesh.view(), std::vector<uint8_t>(4 * n, 9), result_attributes(records, true));
  const ResultPly back = read_result_ply(path);
  for (size_t v = 0; v < n; ++v) {
    const VertexRecord &r = records[v];
    const auto at = [&](const char *name) { return back.vertex_properties.at(name).at(v); };
    EXPECT_FLOAT_EQ(at("diffuse_r"), r.diffuse[0]);
    EXPECT_FLOAT_EQ(at("diffuse_g"), r.diffuse[1]);
    EXPECT_FLOAT_EQ(at("diffuse_b"), r.diffuse[2]);
    EXPECT_FLOAT_EQ(at("n_visible"), r.n_visible);
    EXPECT_FLOAT_EQ(at("n_diffuse"), r.n_diffuse);
    EXPECT_FLOAT_EQ(at("n_specular"), r.n_specular);
    EXPECT_FLOAT_EQ(at("coloured"), r.coloured);
    EXPECT_FLOAT_EQ(at("kd"), r.fit.kd);
    EXPECT_FLOAT_EQ(at("ks"), r.fit.ks);
    EXPECT_FLOAT_EQ(at("shininess"), r.fit.shininess);
    EXPECT_FLOAT_EQ(at("color_r"), r.fit.color[0]);
    EXPECT_FLOAT_EQ(at("color_g"), r.fit.color[1]);
    EXPECT_FLOAT_EQ(at("color_b"), r.fit.color[2]);
    EXPECT_FLOAT_EQ(at("dq"), r.fit.dq);
    EXPECT_FLOAT_EQ(at("sq"), r.fit.sq);
    EXPECT_FLOAT_EQ(at("fit_rmse"), r.fit.rmse);
    EXPECT_FLOAT_EQ(at("fit_status"), float(r.fit.status));
    EXPECT_FLOAT_EQ(at("fit_iterations"), float(r.fit.iterations));
    EXPECT_FLOAT_EQ(at("diffuse_form"), r.diffuse_form);
    EXPECT_FLOAT_EQ(at("diffuse_deconvolved"), r.diffuse_deconvolved);
  }
  // fits_from_result hands the deconvolution flags back (absent: 0 everywhere).
  std::vector<uint8_t> flags;
  fits_from_result(back, path, nullptr, nullptr, &flags);
  ASSERT_EQ(flags.size(), n);
  for (size_t v = 0; v < n; ++v) EXPECT_EQ(flags[v], records[v].diffuse_deconvolved > 0.5f ? 1 : 0);
  ResultPly without = back;
  without.vertex_properties.erase("diffuse_deconvolved");
  fits_from_result(without, path, nullptr, nullptr, &flags);
  EXPECT_EQ(std::count(flags.begin(), flags.end(), uint8_t(1)), 0);
}

// diffuse_form: one form when every modelled vertex has it (unmodelled ones do not count), else a
// per-vertex coat map.
TEST(ResultSchema, DiffuseFormsAreUniformOrPerVertex) {
  std::vector<VertexRecord> records(4);
  for (VertexRecord &r : records) r.fit.status = kFitFull, r.diffuse_form = 1;
  records[3].fit.status = kFitNone, records[3].diffuse_form = 0;
  const DiffuseForms uniform = diffuse_forms_of(records);
  EXPECT_FALSE(uniform.varies());
  EXPECT_EQ(uniform.uniform, DiffuseForm::Coated);
  records[1].diffuse_form = 0;
  const DiffuseForms map = diffuse_forms_of(records);
  ASSERT_TRUE(map.varies());
  EXPECT_EQ(map.at(0), DiffuseForm::Coated);
  EXPECT_EQ(map.at(1), DiffuseForm::Lambert);
  EXPECT_EQ(map.at(2), DiffuseForm::Coated);
}

TEST(ResultSchema, WriteReadRoundTripKeepsEveryAttribute) {
  const MeshData mesh = test::make_grid(3, 1.0f, 0.0f);
  const size_t n = mesh.positions.size() / 3;
  std::vector<VertexRecord> records;
  for (size_t v = 0; v < n; ++v) records.push_back(distinct_record(v));
  const std::string path = test::scratch_dir("schema_rt") + "/r.ply";
  write_result_ply(path, mesh.view(), std::vector<uint8_t>(4 * n, 9), result_attributes(records, true));
  const ResultPly back = read_result_ply(path);
  const std::vector<VertexRecord> read = records_from_columns(back.vertex_properties, path);
  ASSERT_EQ(read.size(), n);
  // Every schema entry, through its own accessor: a reader that skips one leaves the default 0,
  // which differs from distinct_record's value on most vertices.
  for (const ResultAttribute &a : result_schema()) {
    ASSERT_TRUE(back.vertex_properties.count(a.name)) << a.name << " was not written";
    for (size_t v = 0; v < n; ++v) EXPECT_FLOAT_EQ(a.get(read[v]), a.get(records[v])) << a.name << ", vertex " << v;
  }
  // ... and the fits the relight and evaluation read, field by field.
  const std::vector<VertexFit> fits = fits_from_result(back, path);
  ASSERT_EQ(fits.size(), n);
  for (size_t v = 0; v < n; ++v) {
    const VertexFit &f = fits[v], &w = records[v].fit;
    EXPECT_FLOAT_EQ(f.kd, w.kd);
    EXPECT_FLOAT_EQ(f.ks, w.ks);
    EXPECT_FLOAT_EQ(f.shininess, w.shininess);
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(f.color[c], w.color[c]);
    EXPECT_FLOAT_EQ(f.dq, w.dq);
    EXPECT_FLOAT_EQ(f.sq, w.sq);
    EXPECT_FLOAT_EQ(f.rmse, w.rmse);
    EXPECT_EQ(f.status, w.status);
    EXPECT_EQ(f.iterations, w.iterations);
  }
}

TEST(ResultSchema, EveryNameIsUniqueAndDescribedInTheReadme) {
  std::ifstream in(test::source_dir() + "/README.md");
  ASSERT_TRUE(in) << "README.md not found beside the sources";
  const std::string readme((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::set<std::string> seen;
  for (const ResultAttribute &a : result_schema()) {
    EXPECT_TRUE(seen.insert(a.name).second) << a.name << " appears twice";
    EXPECT_EQ(find_result_attribute(a.name), &a);
    std::string name = a.name;
    // The README writes colour triples as `x_r/g/b`.
    if (name.size() > 2 && (name.compare(name.size() - 2, 2, "_r") == 0 || name.compare(name.size() - 2, 2, "_g") == 0 ||
                            name.compare(name.size() - 2, 2, "_b") == 0))
      name = name.substr(0, name.size() - 2) + "_r/g/b";
    EXPECT_NE(readme.find("`" + name + "`"), std::string::npos) << a.name << " is not in the README's output table";
    EXPECT_NE(std::string(a.meaning), "");
  }
  EXPECT_EQ(find_result_attribute("no_such"), nullptr);
}

TEST(ResultSchema, MissingModelAttributeIsNamedAndShortColumnsRefused) {
  ResultColumns columns;
  EXPECT_EQ(first_missing_model_attribute(columns), "kd");
  for (const ResultAttribute &a : result_schema())
    if (a.needed_for_model) columns[a.name] = std::vector<float>(4, 1.0f);
  EXPECT_EQ(first_missing_model_attribute(columns), "");
  columns.erase("fit_status");
  EXPECT_EQ(first_missing_model_attribute(columns), "fit_status");
  columns["fit_status"] = {2.0f, -3.0f, 1e9f, std::nanf("")};  // clamped into uint8, NaN gives 0
  const auto records = records_from_columns(columns, "test");
  ASSERT_EQ(records.size(), 4u);
  EXPECT_EQ(records[0].fit.status, 2);
  EXPECT_EQ(records[1].fit.status, 0);
  EXPECT_EQ(records[2].fit.status, 255);
  EXPECT_EQ(records[3].fit.status, 0);
  columns["dq"] = std::vector<float>(3, 0.5f);
  EXPECT_THROW(records_from_columns(columns, "test"), InputError);
}
