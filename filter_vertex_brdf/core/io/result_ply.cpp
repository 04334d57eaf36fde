#include "io/result_ply.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include "base/errors.h"
#include "io/result_schema.h"

namespace vbrdf {

namespace {
struct Property {
  std::string name, type, count_type;  // count_type non-empty for lists
};
struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> properties;
};

size_t type_size(const std::string &t, const std::string &path) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  throw InputError("PLY '" + path + "': unknown property type '" + t + "'.");
}

double read_value(const char *p, const std::string &t) {
  if (t == "char" || t == "int8") return double(*reinterpret_cast<const int8_t *>(p));
  if (t == "uchar" || t == "uint8") return double(*reinterpret_cast<const uint8_t *>(p));
  int16_t i16; uint16_t u16; int32_t i32; uint32_t u32; float f; double d;
  if (t == "short" || t == "int16") return std::memcpy(&i16, p, 2), double(i16);
  if (t == "ushort" || t == "uint16") return std::memcpy(&u16, p, 2), double(u16);
  if (t == "int" || t == "int32") return std::memcpy(&i32, p, 4), double(i32);
  if (t == "uint" || t == "uint32") return std::memcpy(&u32, p, 4), double(u32);
  if (t == "float" || t == "float32") return std::memcpy(&f, p, 4), double(f);
  return std::memcpy(&d, p, 8), d;
}

std::vector<Element> parse_header(std::istream &in, const std::string &path) {
  std::string line;
  if (!std::getline(in, line) || line.compare(0, 3, "ply") != 0) throw InputError("'" + path + "' is not a PLY file.");
  std::vector<Element> elements;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string format;
      ls >> format;
      if (format != "binary_little_endian")
        throw InputError("PLY '" + path + "' is " + format + "; only binary_little_endian result files are read.");
    } else if (word == "element") {
      Element e;
      ls >> e.name >> e.count;
      elements.push_back(e);
    } else if (word == "property" && !elements.empty()) {
      Property p;
      ls >> p.type;
      if (p.type == "list") ls >> p.count_type >> p.type;
      ls >> p.name;
      elements.back().properties.push_back(p);
    } else if (word == "end_header") {
      return elements;
    }
  }
  throw InputError("PLY '" + path + "' has no end_header.");
}
} // namespace

ResultPly read_result_ply(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("Cannot open result '" + path + "'.");
  const std::vector<Element> elements = parse_header(in, path);
  const std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const char *p = body.data(), *end = body.data() + body.size();
  auto need = [&](size_t bytes) {
    if (size_t(end - p) < bytes) throw InputError("PLY '" + path + "' is truncated.");
  };
  ResultPly r;
  for (const Element &e : elements) {
    const bool vertex = e.name == "vertex", face = e.name == "face";
    for (size_t i = 0; i < e.count; ++i)
      for (const Property &prop : e.properties) {
        if (!prop.count_type.empty()) {
          need(type_size(prop.count_type, path));
          const size_t n = size_t(read_value(p, prop.count_type));
          p += type_size(prop.count_type, path);
          need(n * type_size(prop.type, path));
          for (size_t k = 0; k < n; ++k, p += type_size(prop.type, path))
            if (face && n == 3) r.mesh.indices.push_back(uint32_t(read_value(p, prop.type)));
          continue;
        }
        need(type_size(prop.type, path));
        const double v = read_value(p, prop.type);
        p += type_size(prop.type, path);
        if (vertex) r.vertex_properties[prop.name].push_back(float(v));
      }
  }
  auto take = [&](const char *name) { auto it = r.vertex_properties.find(name); return it == r.vertex_properties.end() ? nullptr : &it->second; };
  const auto *x = take("x"), *y = take("y"), *z = take("z");
  if (!x || !y || !z) throw InputError("PLY '" + path + "' has no vertex positions.");
  const auto *nx = take("nx"), *ny = take("ny"), *nz = take("nz");
  const auto *red = take("red"), *green = take("green"), *blue = take("blue"), *alpha = take("alpha");
  for (size_t v = 0; v < x->size(); ++v) {
    r.mesh.positions.insert(r.mesh.positions.end(), {(*x)[v], (*y)[v], (*z)[v]});
    r.mesh.normals.insert(r.mesh.normals.end(), {nx ? (*nx)[v] : 0.0f, ny ? (*ny)[v] : 0.0f, nz ? (*nz)[v] : 0.0f});
    if (red && green && blue)
      r.mesh.colors.insert(r.mesh.colors.end(), {uint8_t((*red)[v]), uint8_t((*green)[v]), uint8_t((*blue)[v]),
                                                 uint8_t(alpha ? (*alpha)[v] : 255.0f)});
  }
  return r;
}

std::vector<VertexFit> fits_from_result(const ResultPly &result, const std::string &path, LobeForm *lobe,
                                        DiffuseForms *diffuse, std::vector<uint8_t> *deconvolved) {
  const std::string missing = first_missing_model_attribute(result.vertex_properties);
  if (!missing.empty())
    throw InputError("Result '" + path + "' has no per-vertex '" + missing +
                     "': run the fit with 'Fit reflectance' on first.");
  std::vector<VertexFit> fits;
  const std::vector<VertexRecord> records = records_from_columns(result.vertex_properties, path);
  for (const VertexRecord &record : records) fits.push_back(record.fit);
  if (lobe) *lobe = lobe_form_of(records, path);
  if (diffuse) *diffuse = diffuse_forms_of(records);
  if (deconvolved) {
    deconvolved->resize(records.size());
    for (size_t v = 0; v < records.size(); ++v) (*deconvolved)[v] = records[v].diffuse_deconvolved > 0.5f;
  }
  return fits;
}

} // namespace vbrdf
