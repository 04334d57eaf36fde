// synth_selfcheck DIR: checks a scene written by synthesize_scene, reading it back the way
// MeshLab does and evaluating the model independently of the renderer:
//  - project.mlp through vcglib's ReadShotFromQDomNode (MeshLab's reader), <VCGCamera> first;
//  - mesh.ply through vcglib's PLY importer, ground_truth/ files with small readers;
//  - for every training photo, vertices whose 1-ring is visible, lit (brute-force ray casts over
//    all triangles, no BVH), covers the pixel and is smooth: the pixel MeshLab reads for the
//    vertex, (int(x), int(H - y)) of Shot::Project, equals the model's value at the vertex within
//    one quantisation step;
//  - vertices whose whole 1-ring faces the light but is in cast shadow read exactly black;
//  - the lit / visible flags of the ground truth agree with the brute-force ray casts.
// Point lights (synthesize_scene --light-distance): when lights.json exists, each photo's light
// is the point at its "position_world"; at x, L = normalize(P - x) and the irradiance is
// E * (d / |P - x|)^2 with d = |P - the mesh's bounding-box centre| (computed here from mesh.ply);
// shadow rays stop at P.
// Exit 0 when everything holds.
#include <QDomDocument>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <vcg/complex/complex.h>
#include <wrap/io_trimesh/import_ply.h>
#include <wrap/qt/shot_qt.h>

namespace {

class CVertex;
class CFace;
struct CUsedTypes : public vcg::UsedTypes<vcg::Use<CVertex>::AsVertexType, vcg::Use<CFace>::AsFaceType> {};
class CVertex : public vcg::Vertex<CUsedTypes, vcg::vertex::Coord3f, vcg::vertex::Normal3f,
                                   vcg::vertex::BitFlags> {};
class CFace : public vcg::Face<CUsedTypes, vcg::face::VertexRef, vcg::face::BitFlags> {};
class CMesh : public vcg::tri::TriMesh<std::vector<CVertex>, std::vector<CFace>> {};

using P3 = vcg::Point3f;
using Shot = vcg::Shot<float>;

const float kEps = 2e-4f;  // ray origin offset along the normal (the generator's convention)

int g_failures = 0;
void fail(const std::string &msg) {
  if (++g_failures <= 20) std::fprintf(stderr, "FAIL: %s\n", msg.c_str());
  if (g_failures == 21) std::fprintf(stderr, "FAIL: ... (further failures not shown)\n");
}

struct Raster {
  std::string image;
  Shot shot;
  cv::Mat pixels;
  P3 light;  // world direction towards the light (a point light: from the box centre)
  bool point = false;
  P3 position;          // point light (world)
  float reference = 1;  // point light: its distance from the mesh's bounding-box centre
};

// What a point x receives from the raster's light: unit direction, distance (1e30 for a
// directional light) and irradiance factor.
struct LightAt {
  P3 L;
  float distance;
  float falloff;
};
LightAt light_at(const Raster &r, P3 x) {
  if (!r.point) return {r.light, 1e30f, 1.0f};
  const P3 d = r.position - x;
  const float dist = d.Norm();
  return {d / dist, dist, (r.reference / dist) * (r.reference / dist)};
}

struct Capture {
  float irradiance = 1;  // E of the model
  float noise = 0;       // pixel values are only checked without noise
};

struct Truth {
  std::vector<float> kd, ks, shininess;
  std::vector<P3> color;
  std::vector<std::vector<int>> visible;  // [view][vertex] from gt_vertex.csv
  std::vector<std::string> lit;           // [vertex] -> one char per photo, gt_lit.txt
};

std::string read_all(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The model, written again here on purpose (not shared with the renderer).
P3 model(const Truth &t, float E, int v, P3 N, P3 L, P3 V) {
  const float nl = N * L;
  if (nl <= 0) return P3(0, 0, 0);
  const P3 R = N * (2 * nl) - L;
  const float rv = std::max(R * V, 0.0f);
  const float spec = t.ks[v] > 0 ? t.ks[v] * std::pow(rv, t.shininess[v]) : 0.0f;
  return P3(t.kd[v] * nl * t.color[v][0] + spec, t.kd[v] * nl * t.color[v][1] + spec,
            t.kd[v] * nl * t.color[v][2] + spec) * E;
}

// irradiance and noise_sigma from expected.txt (key: value lines).
Capture load_capture(const std::string &dir) {
  Capture c;
  std::istringstream in(read_all(dir + "/expected.txt"));
  std::string line;
  while (std::getline(in, line)) {
    const size_t colon = line.find(':');
    if (line.empty() || line[0] == '#' || colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    if (key == "irradiance") c.irradiance = std::stof(line.substr(colon + 1));
    if (key == "noise_sigma") c.noise = std::stof(line.substr(colon + 1));
  }
  return c;
}

float srgb(float x) {
  x = std::min(std::max(x, 0.0f), 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1 / 2.4f) - 0.055f;
}

// Brute force over all triangles: does the segment o + t d, 0 < t < tmax, hit one?
bool blocked(const CMesh &m, P3 o, P3 d, float tmax) {
  for (const CFace &f : m.face) {
    const P3 a = f.cV(0)->cP(), e1 = f.cV(1)->cP() - a, e2 = f.cV(2)->cP() - a;
    const P3 p = d ^ e2;
    const float det = e1 * p;
    if (std::fabs(det) < 1e-12f) continue;
    const P3 s = o - a;
    const float u = (s * p) / det;
    if (u < 0 || u > 1) continue;
    const P3 q = s ^ e1;
    const float v = (d * q) / det;
    if (v < 0 || u + v > 1) continue;
    const float t = (e2 * q) / det;
    if (t > 0 && t < tmax) return true;
  }
  return false;
}

bool lit_brute(const CMesh &m, int v, const Raster &r) {
  const P3 n = m.vert[v].cN(), L = light_at(r, m.vert[v].cP()).L;
  if (!(n * L > 0)) return false;
  const P3 o = m.vert[v].cP() + n * kEps;
  if (!r.point) return !blocked(m, o, L, 1e30f);
  const P3 d = r.position - o;
  return !blocked(m, o, d / d.Norm(), d.Norm());
}

bool visible_brute(const CMesh &m, int v, const Shot &shot) {
  const P3 n = m.vert[v].cN(), o = m.vert[v].cP() + n * kEps, d = shot.GetViewPoint() - o;
  return n * d > 0 && !blocked(m, o, d / d.Norm(), d.Norm());
}

// MeshLab's lookup of a vertex's pixel; false outside the image.
bool pixel_of(const Shot &shot, P3 p, int &x, int &y) {
  if (!(shot.Depth(p) > 0)) return false;
  const vcg::Point2f q = shot.Project(p);
  const int W = shot.Intrinsics.ViewportPx[0], H = shot.Intrinsics.ViewportPx[1];
  const float fy = H - q[1];
  if (q[0] < 0 || fy < 0 || q[0] >= W || fy >= H) return false;
  x = int(q[0]);
  y = int(fy);
  return true;
}

std::vector<Raster> load_project(const std::string &dir, std::string &mesh_file) {
  QFile file(QString::fromStdString(dir + "/project.mlp"));
  QDomDocument doc;
  if (!file.open(QIODevice::ReadOnly) || !doc.setContent(&file)) throw std::runtime_error("bad project.mlp");
  mesh_file = doc.elementsByTagName("MLMesh").at(0).toElement().attribute("filename").toStdString();
  std::vector<Raster> rasters;
  const QDomNodeList list = doc.elementsByTagName("MLRaster");
  for (int i = 0; i < list.size(); ++i) {
    const QDomNode first = list.at(i).firstChild();  // MeshLab reads the shot from firstChild()
    if (first.nodeName() != "VCGCamera") fail("MLRaster's first child is not VCGCamera");
    Raster r;
    if (!ReadShotFromQDomNode(r.shot, first)) fail("ReadShotFromQDomNode failed");
    const QDomElement plane = list.at(i).firstChildElement("Plane");
    if (plane.attribute("semantic") != "1") fail("Plane semantic is not 1");
    r.image = plane.attribute("fileName").toStdString();
    r.pixels = cv::imread(dir + "/" + r.image, cv::IMREAD_UNCHANGED);
    if (r.pixels.empty()) throw std::runtime_error("cannot read " + r.image);
    if (r.pixels.cols != r.shot.Intrinsics.ViewportPx[0] || r.pixels.rows != r.shot.Intrinsics.ViewportPx[1])
      fail(r.image + ": size differs from ViewportPx");
    rasters.push_back(r);
  }
  return rasters;
}

// lights.lp: directions in the camera frame of each photo, to world with its shot.
void load_lights(const std::string &dir, std::vector<Raster> &rasters) {
  std::istringstream in(read_all(dir + "/lights.lp"));
  size_t n = 0;
  in >> n;
  if (n != rasters.size()) fail("lights.lp count differs from the rasters");
  std::map<std::string, P3> dirs;
  for (size_t i = 0; i < n; ++i) {
    std::string name;
    float x, y, z;
    in >> name >> x >> y >> z;
    dirs[name] = P3(x, y, z).Normalize();
  }
  for (Raster &r : rasters) {
    if (!dirs.count(r.image)) throw std::runtime_error("no light for " + r.image);
    const P3 d = dirs[r.image];
    vcg::Matrix44f R = r.shot.Extrinsics.Rot();
    r.light = (R.GetRow3(0) * d[0] + R.GetRow3(1) * d[1] + R.GetRow3(2) * d[2]).Normalize();
  }
}

// lights.json (point lights), when present: "images" and "position_world"; the reference
// distance of each light is its distance from the mesh's bounding-box centre.
void load_positions(const std::string &dir, const CMesh &m, std::vector<Raster> &rasters) {
  QFile file(QString::fromStdString(dir + "/lights.json"));
  if (!file.exists()) return;
  if (!file.open(QIODevice::ReadOnly)) throw std::runtime_error("cannot read lights.json");
  const QJsonObject root = QJsonDocument::fromJson(file.readAll()).object();
  const QJsonArray images = root["images"].toArray(), pos = root["position_world"].toArray();
  if (images.size() != int(rasters.size()) || pos.size() != images.size())
    return fail("lights.json: images / position_world counts differ from the rasters");
  vcg::Box3f box;
  for (const CVertex &v : m.vert) box.Add(v.cP());
  std::map<std::string, P3> at;
  for (int i = 0; i < images.size(); ++i) {
    const QJsonArray p = pos[i].toArray();
    at[images[i].toString().toStdString()] = P3(float(p[0].toDouble()), float(p[1].toDouble()), float(p[2].toDouble()));
  }
  for (Raster &r : rasters) {
    if (!at.count(r.image)) throw std::runtime_error("lights.json has no position for " + r.image);
    r.point = true;
    r.position = at[r.image];
    r.reference = (r.position - box.Center()).Norm();
    if ((r.position - box.Center()).Normalize() * r.light < 0.9999f)
      fail(r.image + ": lights.lp direction is not the one from the bounding-box centre to lights.json's position");
  }
}

Truth load_truth(const std::string &dir, size_t vertices, size_t photos) {
  Truth t;
  std::istringstream csv(read_all(dir + "/ground_truth/gt_vertex.csv"));
  std::string line;
  std::getline(csv, line);
  std::map<std::string, int> col;
  {
    std::istringstream h(line);
    std::string name;
    for (int i = 0; std::getline(h, name, ','); ++i) col[name] = i;
  }
  for (int k = 0; col.count("visible_view" + std::to_string(k)); ++k) t.visible.emplace_back();
  while (std::getline(csv, line)) {
    std::vector<float> f;
    std::istringstream l(line);
    std::string cell;
    while (std::getline(l, cell, ',')) f.push_back(std::stof(cell));
    t.kd.push_back(f[col["kd"]]);
    t.ks.push_back(f[col["ks"]]);
    t.shininess.push_back(f[col["shininess"]]);
    t.color.emplace_back(f[col["color_r"]], f[col["color_g"]], f[col["color_b"]]);
    for (size_t k = 0; k < t.visible.size(); ++k)
      t.visible[k].push_back(int(f[col["visible_view" + std::to_string(k)]]));
  }
  if (t.kd.size() != vertices) fail("gt_vertex.csv has another vertex count than mesh.ply");
  std::istringstream lit(read_all(dir + "/ground_truth/gt_lit.txt"));
  while (std::getline(lit, line))
    if (!line.empty() && line[0] != '#') t.lit.push_back(line);
  if (t.lit.size() != vertices || t.lit[0].size() != photos) fail("gt_lit.txt has a wrong shape");
  return t;
}

// gt_vertex.ply, read with a minimal binary PLY reader (vcglib 2020.09's importer does not load
// custom attributes: PlyInfo::AddPerVertexFloatAttribute copies them over the vertex itself):
// its float properties must equal the CSV's.
void check_gt_ply(const std::string &dir, const Truth &t, const CMesh &m) {
  std::ifstream in(dir + "/ground_truth/gt_vertex.ply", std::ios::binary);
  std::string line, element;
  size_t count = 0, stride = 0;
  std::map<std::string, size_t> offset;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream l(line);
    std::string word, type, name;
    l >> word;
    if (word == "element") {
      size_t n = 0;
      l >> element >> n;
      if (element == "vertex") count = n;
    }
    if (word != "property" || element != "vertex") continue;
    l >> type >> name;
    offset[name] = stride;
    stride += type == "uchar" ? 1 : 4;
  }
  if (count != t.kd.size() || !offset.count("kd") || !offset.count("shininess") ||
      !offset.count("visible_any"))
    return fail("gt_vertex.ply: wrong vertex count or missing properties");
  std::vector<char> data(count * stride);
  in.read(data.data(), std::streamsize(data.size()));
  auto get = [&](size_t v, const char *name) {
    float f;
    std::memcpy(&f, data.data() + v * stride + offset[name], 4);
    return f;
  };
  for (size_t v = 0; v < count; ++v)
    if (std::fabs(get(v, "kd") - t.kd[v]) > 1e-5f || std::fabs(get(v, "x") - m.vert[v].cP()[0]) > 0 ||
        std::fabs(get(v, "shininess") - t.shininess[v]) > 1e-3f * t.shininess[v])
      return fail("gt_vertex.ply disagrees with gt_vertex.csv / mesh.ply at vertex " + std::to_string(v));
}

struct Ring {
  std::vector<std::vector<int>> tris;  // incident faces per vertex
};
Ring build_ring(const CMesh &m) {
  Ring r;
  r.tris.resize(m.vert.size());
  for (size_t f = 0; f < m.face.size(); ++f)
    for (int k = 0; k < 3; ++k) r.tris[vcg::tri::Index(m, m.face[f].cV(k))].push_back(int(f));
  return r;
}

// Distance from 2D point p to the line through a and b.
float line_distance(vcg::Point2f p, vcg::Point2f a, vcg::Point2f b) {
  const vcg::Point2f d = b - a;
  const float len = d.Norm();
  return len > 0 ? std::fabs(d[0] * (p[1] - a[1]) - d[1] * (p[0] - a[0])) / len : 0.0f;
}

struct Counts {
  int exact_diffuse = 0, exact_glossy = 0;  // constant 1-ring: pixel == model at the vertex
  int bounded = 0;                          // varying diffuse 1-ring: pixel within its range
  int shadow = 0;
  int lit_checked = 0, lit_mismatch = 0, vis_checked = 0, vis_mismatch = 0;
  float worst = 0;  // largest |pixel - model| of the exact checks, in steps of 1/255
};

// v is interior to its 1-ring: every edge at v is shared by exactly two of its faces.
bool interior(const CMesh &m, const Ring &ring, int v) {
  std::map<int, int> edges;
  for (int f : ring.tris[v])
    for (int k = 0; k < 3; ++k) {
      const int u = int(vcg::tri::Index(m, m.face[f].cV(k)));
      if (u != v) edges[u]++;
    }
  for (const auto &e : edges)
    if (e.second != 2) return false;
  return !edges.empty();
}

P3 face_normal(const CFace &F) {
  return (F.cV(1)->cP() - F.cV(0)->cP()) ^ (F.cV(2)->cP() - F.cV(0)->cP());
}

// The 1-ring of v as the camera sees it: v interior, every face facing the camera, every vertex
// visible, and the ring covering a disk of 1.5 px around v's projection (all samples of v's
// pixel then fall on these faces). `verts` gets v and its neighbours.
bool ring_seen(const CMesh &m, const Ring &ring, int v, const Shot &shot, std::vector<int> &verts) {
  if (!interior(m, ring, v)) return false;
  const P3 eye = shot.GetViewPoint();
  const vcg::Point2f pv = shot.Project(m.vert[v].cP());
  verts.assign(1, v);
  for (int f : ring.tris[v]) {
    const CFace &F = m.face[f];
    if (face_normal(F) * (eye - F.cV(0)->cP()) <= 0) return false;
    std::vector<vcg::Point2f> opp;
    for (int k = 0; k < 3; ++k) {
      const int u = int(vcg::tri::Index(m, F.cV(k)));
      if (u == v) continue;
      opp.push_back(shot.Project(F.cV(k)->cP()));
      if (std::find(verts.begin(), verts.end(), u) == verts.end()) verts.push_back(u);
    }
    if (line_distance(pv, opp[0], opp[1]) < 1.5f) return false;
  }
  for (int u : verts)
    if (!visible_brute(m, u, shot)) return false;
  return true;
}

// Every face and vertex normal of v's ring faces the light (no attached-shadow edge near).
bool ring_faces_light(const CMesh &m, const Ring &ring, int v, const Raster &r) {
  for (int f : ring.tris[v]) {
    const CFace &F = m.face[f];
    if (face_normal(F) * light_at(r, F.cV(0)->cP()).L <= 0) return false;
    for (int k = 0; k < 3; ++k)
      if (F.cV(k)->cN() * light_at(r, F.cV(k)->cP()).L < 0.1f) return false;
  }
  return true;
}

void check_photo(const CMesh &m, const Ring &ring, const Truth &t, const Capture &cap,
                 const Raster &r, int photo, int view, Counts &c) {
  const bool wide = r.pixels.depth() == CV_16U;
  const float maxcode = wide ? 65535.0f : 255.0f;
  // Compared in the stored domain (sRGB or linear), in units of 1/255.
  auto encode = [&](float x) { return 255.0f * (wide ? std::min(std::max(x, 0.0f), 1.0f) : srgb(x)); };
  const P3 eye = r.shot.GetViewPoint();
  std::vector<int> verts;
  for (size_t v = 0; v < m.vert.size(); ++v) {
    const P3 p = m.vert[v].cP(), n = m.vert[v].cN();
    const LightAt in = light_at(r, p);
    const P3 L = in.L;
    int x, y;
    if (!pixel_of(r.shot, p, x, y) || n * (eye - p).Normalize() < 0.3f) continue;
    // Ground-truth flags against brute force, on a subset (every 7th vertex).
    if (v % 7 == 0) {
      c.lit_checked++;
      c.lit_mismatch += lit_brute(m, int(v), r) != (t.lit[v][photo] == '1');
      c.vis_checked++;
      c.vis_mismatch += visible_brute(m, int(v), r.shot) != bool(t.visible[view][v]);
    }
    if (cap.noise > 0) continue;  // pixel values are not exact then
    if (n * L < 0.3f || !ring_faces_light(m, ring, int(v), r) || !ring_seen(m, ring, int(v), r.shot, verts))
      continue;
    int lit_count = 0;
    for (int u : verts) lit_count += lit_brute(m, u, r);
    float pix[3];
    for (int ch = 0; ch < 3; ++ch)
      pix[ch] = 255.0f / maxcode * (wide ? r.pixels.at<cv::Vec3w>(y, x)[2 - ch] : r.pixels.at<cv::Vec3b>(y, x)[2 - ch]);
    const std::string where = r.image + ": vertex " + std::to_string(v);
    if (lit_count == 0) {  // the whole ring in a cast shadow: exactly black
      c.shadow++;
      if (pix[0] + pix[1] + pix[2] != 0) fail(where + " is in cast shadow but not black");
      continue;
    }
    if (lit_count != int(verts.size())) continue;  // a shadow edge crosses the ring
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    bool glossy = false;
    for (int u : verts) {
      const LightAt iu = light_at(r, m.vert[u].cP());
      const P3 val = model(t, cap.irradiance * iu.falloff, u, m.vert[u].cN(), iu.L, (eye - m.vert[u].cP()).Normalize());
      glossy |= t.ks[u] > 0;
      for (int ch = 0; ch < 3; ++ch) {
        lo[ch] = std::min(lo[ch], encode(val[ch]));
        hi[ch] = std::max(hi[ch], encode(val[ch]));
      }
    }
    float spread = 0;
    for (int ch = 0; ch < 3; ++ch) spread = std::max(spread, hi[ch] - lo[ch]);
    if (std::max({hi[0], hi[1], hi[2]}) >= 254.5f) continue;  // saturated
    const P3 val = model(t, cap.irradiance * in.falloff, int(v), n, L, (eye - p).Normalize());
    char buf[160];
    if (spread <= 0.5f) {
      // Constant ring: the pixel is the model at the vertex, to quantisation.
      for (int ch = 0; ch < 3; ++ch) {
        const float steps = std::fabs(pix[ch] - encode(val[ch]));
        c.worst = std::max(c.worst, steps);
        std::snprintf(buf, sizeof buf, " channel %d: pixel %.2f, model %.2f (/255, %s)", ch,
                      pix[ch], encode(val[ch]), glossy ? "glossy" : "diffuse");
        if (steps > 1.0f) fail(where + buf);
      }
      (glossy ? c.exact_glossy : c.exact_diffuse)++;
    } else if (spread <= 16.0f && !glossy) {
      // Smoothly varying diffuse ring: the pixel lies within the ring's values, up to one step
      // plus the small non-linearity of kd * C and of the renormalised normal (a highlight can
      // peak between vertices, so glossy rings have no such bound).
      const float slack = 1.0f + 0.1f * spread;
      for (int ch = 0; ch < 3; ++ch) {
        std::snprintf(buf, sizeof buf, " channel %d: pixel %.2f outside the ring's [%.2f, %.2f] (/255)",
                      ch, pix[ch], lo[ch], hi[ch]);
        if (pix[ch] < lo[ch] - slack || pix[ch] > hi[ch] + slack) fail(where + buf);
      }
      c.bounded++;
    }
  }
}

} // namespace

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: synth_selfcheck SCENE_DIR\n");
    return 2;
  }
  try {
    const std::string dir = argv[1];
    std::string mesh_file;
    std::vector<Raster> rasters = load_project(dir, mesh_file);
    load_lights(dir, rasters);
    CMesh m;
    int mask = 0;
    if (vcg::tri::io::ImporterPLY<CMesh>::Open(m, (dir + "/" + mesh_file).c_str(), mask) != 0)
      throw std::runtime_error("vcglib cannot open " + mesh_file);
    if (!(mask & vcg::tri::io::Mask::IOM_VERTNORMAL)) fail("mesh.ply has no vertex normals");
    load_positions(dir, m, rasters);
    const Truth t = load_truth(dir, m.vert.size(), rasters.size());
    const Capture cap = load_capture(dir);
    check_gt_ply(dir, t, m);
    const Ring ring = build_ring(m);

    // Views in order of first appearance of a distinct shot (the generator's view order).
    std::vector<P3> centres;
    Counts c;
    for (size_t i = 0; i < rasters.size(); ++i) {
      const P3 centre = rasters[i].shot.GetViewPoint();
      size_t view = 0;
      while (view < centres.size() && (centres[view] - centre).Norm() > 1e-6f) ++view;
      if (view == centres.size()) centres.push_back(centre);
      check_photo(m, ring, t, cap, rasters[i], int(i), int(view), c);
    }
    std::printf("synth_selfcheck: %zu photos (%s lights), %zu views; pixel == model at %d diffuse + %d glossy "
                "vertices (worst %.2f/255), within the diffuse 1-ring's range at %d; %d cast-shadow "
                "vertices black; flag mismatches: lit %d/%d, visible %d/%d\n",
                rasters.size(), !rasters.empty() && rasters[0].point ? "point" : "directional",
                centres.size(), c.exact_diffuse, c.exact_glossy, c.worst,
                c.bounded, c.shadow, c.lit_mismatch, c.lit_checked, c.vis_mismatch, c.vis_checked);
    if (centres.size() != t.visible.size()) fail("number of distinct shots differs from the views");
    if (cap.noise > 0) {
      std::printf("synth_selfcheck: noise %g: pixel values not checked\n", cap.noise);
    } else {
      // Point lights: direction and irradiance change across every 1-ring, so no ring is
      // constant; the ring-range check carries the pixel test (a 5 % irradiance error fails it).
      const bool point = !rasters.empty() && rasters[0].point;
      if (!point && c.exact_diffuse < 20) fail("fewer than 20 diffuse vertices could be checked exactly");
      if (c.bounded < (point ? 100 : 50))
        fail("fewer than " + std::to_string(point ? 100 : 50) + " vertices could be checked against their ring");
      if (c.shadow < 3) fail("fewer than 3 cast-shadow vertices could be checked");
    }
    if (c.lit_mismatch * 200 > c.lit_checked) fail("gt_lit.txt disagrees with brute-force rays");
    if (c.vis_mismatch * 200 > c.vis_checked) fail("visible_view* disagrees with brute-force rays");
  } catch (const std::exception &e) {
    fail(e.what());
  }
  if (g_failures) std::fprintf(stderr, "synth_selfcheck: %d failure(s)\n", g_failures);
  return g_failures ? 1 : 0;
}
