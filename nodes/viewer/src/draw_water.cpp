#include "draw_water.hpp"

#include <GL/gl.h>

#include <cmath>

namespace vrflow::viewer {

DrawMesh waterMesh(const std::vector<float>& xyz, const std::vector<std::uint32_t>& indices) {
  DrawMesh mesh;
  const std::size_t vertices = xyz.size() / 3;
  mesh.xyz.assign(xyz.begin(), xyz.begin() + static_cast<std::ptrdiff_t>(vertices * 3));
  for (float& v : mesh.xyz) {
    if (!std::isfinite(v)) v = 0.0f;
  }
  mesh.normals.assign(vertices * 3, 0.0f);
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const std::uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a >= vertices || b >= vertices || c >= vertices) continue;
    const float* p = &mesh.xyz[3 * a];
    const float* q = &mesh.xyz[3 * b];
    const float* r = &mesh.xyz[3 * c];
    const float u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    const float v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
    // The cross product's length is twice the area: the sum weighs triangles by area.
    const float n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0]};
    for (const std::uint32_t i : {a, b, c}) {
      for (std::size_t k = 0; k < 3; ++k) mesh.normals[3 * i + k] += n[k];
    }
    mesh.indices.insert(mesh.indices.end(), {a, b, c});
  }
  return mesh;
}

void drawSmoothMesh(const SceneCache& scene, std::uint64_t meshId, bool shadowPass,
                    const std::array<float, 4>& colour) {
  const auto* xyz = scene.particles(meshId);
  const auto* indices = scene.meshIndices(meshId);
  if (xyz == nullptr || indices == nullptr) return;
  const DrawMesh mesh = waterMesh(*xyz, *indices);
  if (mesh.indices.empty()) return;
  glEnableClientState(GL_VERTEX_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, mesh.xyz.data());
  if (shadowPass) {
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT,
                   mesh.indices.data());
    glDisableClientState(GL_VERTEX_ARRAY);
    return;
  }
  glEnableClientState(GL_NORMAL_ARRAY);
  glNormalPointer(GL_FLOAT, 0, mesh.normals.data());
  // A highlight from the key light (the lights have no specular term otherwise), blended over
  // what lies behind; both restored afterwards.
  const float white[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  const float shine[4] = {0.55f, 0.55f, 0.55f, 1.0f};
  const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  glLightfv(GL_LIGHT0, GL_SPECULAR, white);
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, shine);
  glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 48.0f);
  const bool blend = colour[3] < 1.0f;
  if (blend) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  }
  glColor4f(colour[0], colour[1], colour[2], colour[3]);
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT,
                 mesh.indices.data());
  if (blend) glDisable(GL_BLEND);
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, black);
  glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, 0.0f);
  glLightfv(GL_LIGHT0, GL_SPECULAR, black);
  glDisableClientState(GL_NORMAL_ARRAY);
  glDisableClientState(GL_VERTEX_ARRAY);
}

}  // namespace vrflow::viewer
