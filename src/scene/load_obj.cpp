/// @file scene/load_obj.cpp
/// @brief Wavefront OBJ/MTL loader on top of tinyobjloader.
///
/// tinyobjloader parses only; triangulation is done here because tinyobj's
/// own triangulation reads vertex positions through unchecked face indices.
/// Every index is checked before use. .mtl files and map_Kd textures resolve
/// only inside the .obj file's folder.

#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/file.h"
#include "core/printable.h"
#include "image/image.h"
#include "scene/scene_internal.h"

namespace lo::scene_internal {

namespace {

namespace fs = std::filesystem;

/// What an .mtl says that tinyobjloader reads otherwise than it means.
struct MtlScan {
  /// The numbers of colour and scalar statements that are not finite
  /// numbers (`Ke inf`, `Kd seven`, `Ns nan`): tinyobjloader reads them as 0
  /// without a word (H16-4-5: `Ke inf` drew black); and colours of two
  /// numbers (`Ke 1 1`), whose third it reads as 0. One warning per
  /// statement, for the first ten.
  std::vector<std::string> warnings;
  /// Colours of one number (`Kd 0.5`): grey in the MTL format, red to
  /// tinyobjloader (g and b read as 0). Each as (material, statement, value),
  /// set right after the parse.
  struct Grey {
    std::string material, key;
    double value;
  };
  std::vector<Grey> greys;
};

MtlScan scanMtl(const std::string& text, const std::string& name) {
  static const std::set<std::string> colours = {"Ka", "Kd", "Ks", "Ke", "Kt", "Tf"};
  static const std::set<std::string> scalars = {"Ns", "Ni", "d",   "Tr",    "Pr",    "Pm",
                                                "Ps", "Pc", "Pcr", "aniso", "anisor"};
  MtlScan scan;
  std::istringstream lines(text);
  std::string line, material;
  for (size_t number = 1; std::getline(lines, line); ++number) {
    std::istringstream words(line);
    std::string key, word;
    if (!(words >> key)) continue;
    if (key == "newmtl") {
      std::getline(words >> std::ws, material);
      // tinyobjloader's name: the rest of the line, without trailing space.
      while (!material.empty() && std::isspace(static_cast<unsigned char>(material.back()))) {
        material.pop_back();
      }
      continue;
    }
    const bool colour = colours.count(key) != 0;
    if (!colour && scalars.count(key) == 0) continue;
    const std::string where = name + " line " + std::to_string(number) + ": " + key;
    std::vector<double> values;
    bool other = false;  // spectral or xyz: another form of Ka/Kd/Ks/Tf
    while (words >> word) {
      if (word == "spectral" || word == "xyz") {
        other = true;
        break;
      }
      char* end = nullptr;
      const double v = std::strtod(word.c_str(), &end);
      if (end != word.c_str() + word.size() || !std::isfinite(v)) {
        if (scan.warnings.size() < 10) {
          scan.warnings.push_back(where + " '" + printableShort(word) +
                                  "' is not a finite number: read as 0");
        }
        other = true;
        break;
      }
      values.push_back(v);
    }
    if (!colour || other) continue;
    if (values.size() == 1) {
      scan.greys.push_back({material, key, values[0]});
    } else if (values.size() == 2 && scan.warnings.size() < 10) {
      scan.warnings.push_back(where +
                              " has two numbers: its blue is read as 0; write three (r g b) or "
                              "one (grey)");
    }
  }
  return scan;
}

/// Sets each one-number colour of `scan` grey in the parsed `materials`.
void applyGreys(const MtlScan& scan, const std::map<std::string, int>& byName,
                std::vector<tinyobj::material_t>& materials) {
  for (const MtlScan::Grey& g : scan.greys) {
    const auto found = byName.find(g.material);
    if (found == byName.end() || found->second < 0 || size_t(found->second) >= materials.size()) {
      continue;
    }
    tinyobj::material_t& m = materials[size_t(found->second)];
    tinyobj::real_t* c = g.key == "Ka"   ? m.ambient
                         : g.key == "Kd" ? m.diffuse
                         : g.key == "Ks" ? m.specular
                         : g.key == "Ke" ? m.emission
                                         : m.transmittance;  // Kt, Tf
    c[0] = c[1] = c[2] = tinyobj::real_t(g.value);
  }
}

/// Opens .mtl files only inside the scene folder; remembers the first refusal
/// so that the loader can raise it (tinyobj treats a missing .mtl as a warning).
class FolderMaterialReader : public tinyobj::MaterialReader {
 public:
  FolderMaterialReader(const std::string& scenePath, const std::string& baseDir)
      : scenePath_(scenePath), baseDir_(baseDir) {}

  bool operator()(const std::string& matId, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* matMap, std::string* warn,
                  std::string* err) override {
    if (!error_.empty()) return false;
    try {
      std::string file = resolveInsideFolder(scenePath_, baseDir_, matId, "mtllib");
      const std::string problem = notRegularFile(file);
      if (!problem.empty()) {
        error_ = scenePath_ + (problem == "missing"
                                   ? ": missing material library file '" + matId + "' (not found)"
                                   : ": material library '" + matId + "' is " + problem +
                                         ", not a file");
        return false;
      }
      std::ifstream in(file);
      if (!in) {
        error_ = scenePath_ + ": cannot open material library '" + matId + "'";
        return false;
      }
      skipByteOrderMark(in);
      std::ostringstream text;
      text << in.rdbuf();
      MtlScan scan = scanMtl(text.str(), scenePath_ + ": " + printable(matId));
      for (std::string& w : scan.warnings) warnings_.push_back(std::move(w));
      std::istringstream mtl(text.str());
      tinyobj::LoadMtl(matMap, materials, &mtl, warn, err);
      applyGreys(scan, *matMap, *materials);
      return true;
    } catch (const InputError& e) {
      error_ = e.what();
      return false;
    }
  }

  const std::string& error() const { return error_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  std::string scenePath_, baseDir_, error_;
  std::vector<std::string> warnings_;
};

struct VertexKey {
  int v, n, t;
  bool operator<(const VertexKey& o) const {
    return v != o.v ? v < o.v : (n != o.n ? n < o.n : t < o.t);
  }
};

Vec3 rgb(const tinyobj::real_t c[3]) { return {float(c[0]), float(c[1]), float(c[2])}; }

/// The `v` lines of an OBJ in double (tinyobjloader parses them as float,
/// 2^-7 m apart at 1e5 m): x, y, z per vertex in file order. tinyobjloader
/// also reads what is not a number ("nan") and a coordinate that is missing
/// ("v 1 2") as 0, without a word: those are refused here, naming the line.
/// @throws InputError.
std::vector<double> readVerticesInDouble(const std::string& path) {
  std::vector<double> out;
  std::ifstream in(path);
  skipByteOrderMark(in);
  std::string line;
  size_t lineNumber = 0;
  while (std::getline(in, line)) {
    ++lineNumber;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    size_t i = line.find_first_not_of(" \t");
    if (i == std::string::npos || line[i] != 'v' || i + 1 >= line.size() ||
        (line[i + 1] != ' ' && line[i + 1] != '\t')) {
      continue;
    }
    const std::string where = "line " + std::to_string(lineNumber) + ": vertex " +
                              std::to_string(out.size() / 3 + 1) + " '" +
                              printable(line.substr(i, 60)) + "'";
    const char* c = line.c_str() + i + 1;
    for (int k = 0; k < 3; ++k) {
      char* end = nullptr;
      const double x = std::strtod(c, &end);
      if (end == c) {
        fail(path, where + " has " + std::to_string(k) + " coordinate" + (k == 1 ? "" : "s") +
                       ", not 3 numbers (x y z)");
      }
      if (!std::isfinite(x)) fail(path, where + " has a non-finite coordinate");
      out.push_back(x);
      c = end;
    }
  }
  return out;
}

/// The rebase origin (RebaseBounds) of x, y, z triples.
template <typename T>
Vec3d originOf(const std::vector<T>& xyz) {
  RebaseBounds bounds;
  for (size_t i = 0; i + 2 < xyz.size(); i += 3) bounds.extend(Vec3d(xyz[i], xyz[i + 1], xyz[i + 2]));
  return bounds.origin();
}

}  // namespace

void skipByteOrderMark(std::istream& in) {
  char head[3] = {0, 0, 0};
  in.read(head, 3);
  const bool mark = in.gcount() == 3 && head[0] == '\xEF' && head[1] == '\xBB' && head[2] == '\xBF';
  in.clear();
  in.seekg(mark ? 3 : 0);
}

Scene loadObj(const std::string& path) {
  std::string baseDir = fs::path(path).parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  std::ifstream in(path);
  if (!in) fail(path, "missing file (cannot open)");
  skipByteOrderMark(in);

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> objMaterials;
  std::string warn, err;
  FolderMaterialReader reader(path, baseDir);
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &objMaterials, &warn, &err, &in, &reader,
                             /*triangulate=*/false, /*default_vcols_fallback=*/false);
  if (!reader.error().empty()) throw InputError(reader.error());
  if (!ok) {
    while (!err.empty() && err.back() == '\n') err.pop_back();
    fail(path, "invalid OBJ: " + (err.empty() ? std::string("parse failed") : err));
  }

  // The reader keeps a face's vertex count in 8 bits: a face of 256 or more
  // vertices would shift every later face and material. Its counts then do
  // not sum to its indices.
  for (const tinyobj::shape_t& shape : shapes) {
    size_t sum = 0;
    for (unsigned char n : shape.mesh.num_face_vertices) sum += n;
    if (sum != shape.mesh.indices.size()) {
      fail(path, "object '" + printable(shape.name) +
                     "' has a face of more than 255 vertices, which the OBJ reader cannot "
                     "hold: triangulate it (Blender: Triangulate Faces) or save it as glTF");
    }
  }

  Scene scene;
  scene.warnings = reader.warnings();
  // usemtl with a name no .mtl defines: tinyobjloader gives those faces no
  // material (they get the default, grey); the user hears it once per name.
  {
    std::istringstream lines(warn);
    std::string line;
    std::set<std::string> named;
    while (std::getline(lines, line)) {
      const std::string head = "material [ ", tail = " ] not found in .mtl";
      if (line.rfind(head, 0) != 0 || line.size() < head.size() + tail.size() ||
          line.compare(line.size() - tail.size(), tail.size(), tail) != 0) {
        continue;
      }
      std::string name = line.substr(head.size(), line.size() - head.size() - tail.size());
      if (name.size() >= 2 && name.front() == '\'' && name.back() == '\'') {
        name = name.substr(1, name.size() - 2);
      }
      if (!named.insert(name).second) continue;
      scene.warnings.push_back(path + ": usemtl '" + name +
                               "' names no material of the .mtl files; its faces get the "
                               "default material (grey, base colour 0.8, untextured)");
    }
  }
  const std::vector<tinyobj::real_t>& v = attrib.vertices;
  // A scene far from the origin is stored relative to its centre
  // (Scene::origin), its vertices read again in double for it.
  std::vector<double> far = readVerticesInDouble(path);  // checks every `v` line
  scene.origin = originOf(v);
  if (scene.rebased() && far.size() == v.size()) {
    scene.origin = originOf(far);
  } else {
    far.clear();
  }
  const std::vector<tinyobj::real_t>& vn = attrib.normals;
  const std::vector<tinyobj::real_t>& vt = attrib.texcoords;
  size_t nv = v.size() / 3, nn = vn.size() / 3, nt = vt.size() / 2;

  // Materials, in .mtl order; a shared default for faces without usemtl.
  std::map<std::string, int> textureByFile;
  std::vector<PendingTexture> pendingTextures;
  for (size_t i = 0; i < objMaterials.size(); ++i) {
    const tinyobj::material_t& o = objMaterials[i];
    Material m;
    m.name = o.name;
    m.backFaceCulling = false;  // OBJ has no single-sided faces
    m.baseColor = rgb(o.diffuse);
    m.emission = rgb(o.emission);
    m.metallic = float(o.metallic);
    // Phong exponent -> roughness, Ks -> the specular layer's weight
    // (docs/scene.md). A material without a specular colour (Ks 0 0 0, or no
    // Ks) has no glossy lobe at all: Lambertian.
    const float ks = maxComponent(rgb(o.specular));
    const bool hasSpecular = ks > 0;
    m.specular = hasSpecular ? std::min(ks, 1.0f) : 0.0f;
    m.roughness =
        hasSpecular ? std::sqrt(2.0f / (std::max(float(o.shininess), 0.0f) + 2.0f)) : 1.0f;
    if (o.dissolve < 1) m.transmission = 1.0f - std::max(float(o.dissolve), 0.0f);
    if (o.ior > 0) m.ior = float(o.ior);
    if (!isFinite(m.baseColor) || !isFinite(m.emission) || !std::isfinite(m.roughness) ||
        !std::isfinite(m.ior) || !std::isfinite(m.transmission)) {
      fail(path, "material '" + o.name + "' has a non-finite value");
    }
    if (!o.diffuse_texname.empty()) {
      auto it = textureByFile.find(o.diffuse_texname);
      if (it != textureByFile.end()) {
        m.baseColorTexture = it->second;
      } else {
        std::string what = "map_Kd '" + o.diffuse_texname + "'";
        std::string file = resolveInsideFolder(path, baseDir, o.diffuse_texname, what);
        const std::string problem = notRegularFile(file);
        if (!problem.empty()) {
          // Warned once; the materials that use it show their Kd alone.
          scene.warnings.push_back(
              path + ": texture file " + what +
              (problem == "missing" ? " is missing" : " is " + problem + ", not an image file") +
              "; the materials using it show their Kd alone");
          textureByFile[o.diffuse_texname] = -1;
          scene.materials.push_back(std::move(m));
          continue;
        }
        auto bytes = std::make_shared<const std::vector<unsigned char>>(
            readFileBytes(path, file, "texture"));
        Texture t;  // decoded with the others (decodeTextures: their total memory first)
        t.name = o.diffuse_texname;
        m.baseColorTexture = int(scene.textures.size());
        textureByFile[o.diffuse_texname] = m.baseColorTexture;
        scene.textures.push_back(std::move(t));
        pendingTextures.push_back({m.baseColorTexture, bytes, "(" + what + ")", true});
      }
    }
    scene.materials.push_back(std::move(m));
  }
  decodeTextures(scene, path, pendingTextures);
  int defaultMaterial = -1;

  // Faces, grouped by material (usemtl), in file order within a material.
  struct FaceRef {
    size_t shape, firstIndex, count;
  };
  std::map<int, std::vector<FaceRef>> facesByMaterial;
  for (size_t s = 0; s < shapes.size(); ++s) {
    const tinyobj::mesh_t& mesh = shapes[s].mesh;
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      size_t count = mesh.num_face_vertices[f];
      if (offset + count > mesh.indices.size()) fail(path, "face index list is truncated");
      int mat = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
      if (mat >= int(scene.materials.size())) {
        fail(path, "face material id " + std::to_string(mat) + " out of range");
      }
      if (count >= 3) facesByMaterial[mat].push_back({s, offset, count});
      offset += count;
    }
  }

  std::map<VertexKey, uint32_t> vertexOf;
  std::vector<char> hasNormal;
  std::vector<float> uv;
  // Vertex colours (`v x y z r g b`, the extension MeshLab and others
  // write), when every `v` line has one: display (sRGB) values in [0, 1],
  // as the tools that write them mean them, decoded to linear for
  // Scene::colors.
  const bool vertexColors = attrib.colors.size() == v.size() && !v.empty();
  std::vector<float> rgba;
  bool anyNormals = false, anyUv = false;
  auto vertex = [&](const tinyobj::index_t& ix) -> uint32_t {
    if (ix.vertex_index < 0 || size_t(ix.vertex_index) >= nv) {
      fail(path, "vertex index " + std::to_string(ix.vertex_index + 1) + " out of range (" +
                     std::to_string(nv) + " vertices)");
    }
    if (ix.normal_index < -1 || (ix.normal_index >= 0 && size_t(ix.normal_index) >= nn)) {
      fail(path, "normal index " + std::to_string(ix.normal_index + 1) + " out of range (" +
                     std::to_string(nn) + " normals)");
    }
    if (ix.texcoord_index < -1 || (ix.texcoord_index >= 0 && size_t(ix.texcoord_index) >= nt)) {
      fail(path, "texcoord index " + std::to_string(ix.texcoord_index + 1) + " out of range (" +
                     std::to_string(nt) + " texcoords)");
    }
    VertexKey key{ix.vertex_index, ix.normal_index, ix.texcoord_index};
    auto it = vertexOf.find(key);
    if (it != vertexOf.end()) return it->second;
    uint32_t id = uint32_t(scene.positions.size());
    size_t p = size_t(ix.vertex_index);
    const Vec3d world = far.empty() ? Vec3d(v[3 * p], v[3 * p + 1], v[3 * p + 2])
                                    : Vec3d(far[3 * p], far[3 * p + 1], far[3 * p + 2]);
    const Vec3 pos = scene.toLocal(world);
    if (!isFinite(pos)) {
      fail(path, "non-finite vertex position (v " + std::to_string(p + 1) + ")");
    }
    scene.positions.push_back(pos);
    if (vertexColors) {
      for (size_t a = 0; a < 3; ++a) {
        const float c = float(attrib.colors[3 * p + a]);
        if (!std::isfinite(c)) fail(path, "non-finite vertex colour (v " + std::to_string(p + 1) + ")");
        rgba.push_back(srgbToLinear(std::clamp(c, 0.0f, 1.0f)));
      }
      rgba.push_back(1.0f);
    }
    Vec3 n{};
    if (ix.normal_index >= 0) {
      size_t q = size_t(ix.normal_index);
      n = normalize(Vec3{float(vn[3 * q]), float(vn[3 * q + 1]), float(vn[3 * q + 2])});
      if (!isFinite(n)) fail(path, "non-finite normal (vn " + std::to_string(q + 1) + ")");
      anyNormals = true;
    }
    scene.normals.push_back(n);
    hasNormal.push_back(ix.normal_index >= 0);
    float u = 0, w = 0;
    if (ix.texcoord_index >= 0) {
      // OBJ puts v = 0 at the bottom of the image; Scene uses glTF's top-left origin.
      size_t q = size_t(ix.texcoord_index);
      u = float(vt[2 * q]);
      w = 1.0f - float(vt[2 * q + 1]);
      anyUv = true;
    }
    uv.push_back(u);
    uv.push_back(w);
    vertexOf[key] = id;
    return id;
  };

  for (auto& [mat, faces] : facesByMaterial) {
    int material = mat;
    if (material < 0) {
      if (defaultMaterial < 0) {
        defaultMaterial = int(scene.materials.size());
        Material m;
        m.name = "default";
        m.backFaceCulling = false;
        scene.materials.push_back(m);
      }
      material = defaultMaterial;
    }
    for (const FaceRef& f : faces) {
      const std::vector<tinyobj::index_t>& idx = shapes[f.shape].mesh.indices;
      std::vector<uint32_t> poly(f.count);
      for (size_t k = 0; k < f.count; ++k) poly[k] = vertex(idx[f.firstIndex + k]);
      std::vector<std::array<uint32_t, 3>> tris;
      if (f.count == 4) {
        // Split a quad along its shorter diagonal (better for the slightly
        // non-planar quads of scanned rooms such as the Cornell box).
        const auto& P = scene.positions;
        float d02 = lengthSquared(P[poly[2]] - P[poly[0]]);
        float d13 = lengthSquared(P[poly[3]] - P[poly[1]]);
        if (d02 <= d13)
          tris = {{poly[0], poly[1], poly[2]}, {poly[0], poly[2], poly[3]}};
        else
          tris = {{poly[0], poly[1], poly[3]}, {poly[1], poly[2], poly[3]}};
      } else {
        // Polygons are fan-triangulated: assumed convex (docs/scene.md).
        for (size_t k = 1; k + 1 < f.count; ++k) tris.push_back({poly[0], poly[k], poly[k + 1]});
      }
      for (const auto& t : tris) {
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
        for (uint32_t i : t) scene.indices.push_back(i);
        scene.triangleMaterial.push_back(material);
      }
    }
  }

  if (!anyNormals) {
    scene.normals.clear();
  } else {
    // Vertices without a `vn` get the area-weighted normal of their faces.
    std::vector<Vec3> acc(scene.positions.size(), Vec3{});
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
      uint32_t a = scene.indices[3 * t], b = scene.indices[3 * t + 1], c = scene.indices[3 * t + 2];
      Vec3 n =
          cross(scene.positions[b] - scene.positions[a], scene.positions[c] - scene.positions[a]);
      acc[a] += n;
      acc[b] += n;
      acc[c] += n;
    }
    for (size_t i = 0; i < scene.normals.size(); ++i)
      if (!hasNormal[i]) scene.normals[i] = normalize(acc[i]);
  }
  if (anyUv) scene.texcoords0 = std::move(uv);
  if (vertexColors) scene.colors = std::move(rgba);
  return scene;
}

}  // namespace lo::scene_internal
