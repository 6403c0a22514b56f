#include "render/mesh_loader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace convoy::render {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& path, const std::string& why) {
  throw std::runtime_error("load_mesh: " + path + ": " + why);
}

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void read_color(const aiMaterial* m, const char* key, unsigned type, unsigned index, Rgba* out) {
  aiColor4D c;
  if (m->Get(key, type, index, c) == AI_SUCCESS) *out = {c.r, c.g, c.b, c.a};
}

std::string texture_file(const aiMaterial* m, const fs::path& folder) {
  aiString name;
  if (m->GetTextureCount(aiTextureType_DIFFUSE) == 0 ||
      m->GetTexture(aiTextureType_DIFFUSE, 0, &name) != AI_SUCCESS) {
    return "";
  }
  std::string file = name.C_Str();
  if (file.empty() || file[0] == '*') return "";  // embedded in the mesh file
  if (file.rfind("file://", 0) == 0) file = file.substr(7);
  std::replace(file.begin(), file.end(), '\\', '/');
  fs::path p(file);
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

LoadedMesh convert(const aiMesh* in, const aiMaterial* material, const fs::path& folder,
                   bool y_up_to_z_up, const std::array<float, 3>& scale) {
  LoadedMesh out;
  MeshData& m = out.mesh;
  const unsigned n = in->mNumVertices;
  m.positions.reserve(3 * n);
  if (in->HasNormals()) m.normals.reserve(3 * n);
  if (in->HasTextureCoords(0)) m.uvs.reserve(2 * n);
  for (unsigned i = 0; i < n; ++i) {
    aiVector3D p = in->mVertices[i];
    if (y_up_to_z_up) p = aiVector3D(p.x, -p.z, p.y);
    m.positions.insert(m.positions.end(), {p.x * scale[0], p.y * scale[1], p.z * scale[2]});
    if (in->HasNormals()) {
      aiVector3D q = in->mNormals[i];
      if (y_up_to_z_up) q = aiVector3D(q.x, -q.z, q.y);
      // Normals transform by the inverse transpose: divide by the scale, renormalise.
      const double nx = q.x / scale[0], ny = q.y / scale[1], nz = q.z / scale[2];
      const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
      if (len > 0) {
        m.normals.insert(m.normals.end(),
                         {static_cast<float>(nx / len), static_cast<float>(ny / len),
                          static_cast<float>(nz / len)});
      } else {
        m.normals.insert(m.normals.end(), {0.0f, 0.0f, 1.0f});
      }
    }
    if (in->HasTextureCoords(0)) {
      m.uvs.insert(m.uvs.end(), {in->mTextureCoords[0][i].x, in->mTextureCoords[0][i].y});
    }
  }
  // A mirroring scale turns the faces inside out; swap two corners to keep them facing out.
  const bool mirrored = scale[0] * scale[1] * scale[2] < 0;
  for (unsigned f = 0; f < in->mNumFaces; ++f) {
    const aiFace& face = in->mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines
    const unsigned* k = face.mIndices;
    if (mirrored) {
      m.indices.insert(m.indices.end(), {k[0], k[2], k[1]});
    } else {
      m.indices.insert(m.indices.end(), {k[0], k[1], k[2]});
    }
  }
  if (m.normals.empty()) compute_normals(&m);

  if (material) {
    read_color(material, AI_MATKEY_COLOR_DIFFUSE, &out.diffuse);
    read_color(material, AI_MATKEY_COLOR_AMBIENT, &out.ambient);
    read_color(material, AI_MATKEY_COLOR_SPECULAR, &out.specular);
    read_color(material, AI_MATKEY_COLOR_EMISSIVE, &out.emissive);
    float opacity = 1, shininess = 0;
    if (material->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) out.diffuse[3] = opacity;
    if (material->Get(AI_MATKEY_SHININESS, shininess) == AI_SUCCESS && shininess > 0) {
      out.shininess = shininess;
    }
    out.texture_path = texture_file(material, folder);
  }
  return out;
}

}  // namespace

Material LoadedMesh::material(int texture) const {
  Material m;
  m.diffuse = diffuse;
  m.ambient = ambient;
  m.specular = specular;
  m.emissive = emissive;
  m.shininess = shininess;
  m.texture = texture;
  return m;
}

std::vector<LoadedMesh> load_mesh(const std::string& path, const std::array<float, 3>& scale) {
  for (float s : scale) {
    if (s == 0 || !std::isfinite(s)) fail(path, "scale must be finite and non-zero");
  }
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) fail(path, "no such file");
  const std::string ext = lower_extension(path);
  if (ext != ".dae" && ext != ".obj" && ext != ".stl") {
    fail(path, "unsupported mesh format '" + ext + "' (.dae, .obj and .stl are)");
  }

  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                  aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                                  aiProcess_SortByPType | aiProcess_ValidateDataStructure);
  if (!scene || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || scene->mNumMeshes == 0) {
    const std::string why = importer.GetErrorString();
    fail(path, why.empty() ? "no triangle meshes in the file" : why);
  }

  // Assimp turns every COLLADA file Y-up (rotating a Z_UP file's root); Gazebo keeps Z up.
  const bool y_up_to_z_up = ext == ".dae";
  const fs::path folder = fs::path(path).parent_path();
  std::vector<LoadedMesh> parts;
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* mesh = scene->mMeshes[i];
    const aiMaterial* material = mesh->mMaterialIndex < scene->mNumMaterials
                                     ? scene->mMaterials[mesh->mMaterialIndex]
                                     : nullptr;
    LoadedMesh part = convert(mesh, material, folder, y_up_to_z_up, scale);
    if (!part.mesh.indices.empty()) parts.push_back(std::move(part));
  }
  if (parts.empty()) fail(path, "no triangles in the file");
  return parts;
}

const std::vector<MeshLevels>& LoadedMesh::drawables() const {
  if (drawables_) return *drawables_;
  std::vector<MeshLevels> out;
  if (horizontal_extent(mesh) > kTileAbove) {
    MeshData whole = mesh;
    if (whole.normals.empty()) compute_normals(&whole);
    for (auto& tile : split_into_tiles(whole, kTile))
      out.push_back(MeshLevels{{std::move(tile)}, {0.0f}, false});
  } else {
    out.push_back(simplified_levels(mesh));
  }
  drawables_ = std::make_shared<const std::vector<MeshLevels>>(std::move(out));
  return *drawables_;
}

const std::vector<LoadedMesh>& MeshFileCache::load(const std::string& path,
                                                   const std::array<float, 3>& scale) {
  const auto key = std::make_pair(path, scale);
  if (auto it = meshes_.find(key); it != meshes_.end()) return it->second;
  std::vector<LoadedMesh> parts = load_mesh(path, scale);
  ++files_read_;
  return meshes_.emplace(key, std::move(parts)).first->second;
}

}  // namespace convoy::render
