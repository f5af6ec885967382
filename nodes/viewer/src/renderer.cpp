#include "vrflow/viewer/renderer.hpp"

#include <GL/gl.h>
#include <GL/osmesa.h>

#include <cmath>
#include <vector>

#include "draw_water.hpp"
#include "edge_blend.hpp"
#include "vrflow/message/eigen.hpp"
#include "vrflow/message/shape.hpp"

namespace vrflow::viewer {
namespace {

using msg::asEigen;

// Column-major 4x4 for glMultMatrixd: Eigen's default storage order.
using Matrix = Eigen::Matrix4d;

Matrix lookAt(const Camera& camera) {
  const ViewBasis b = viewBasis(camera);
  const auto f = asEigen(b.forward), s = asEigen(b.side), u = asEigen(b.up);
  const auto eye = asEigen(camera.eye);
  Matrix m = Matrix::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m.block<3, 1>(0, 3) = Eigen::Vector3d(-s.dot(eye), -u.dot(eye), f.dot(eye));
  return m;
}

Matrix rotation(const msg::Quat& q) {
  // The norm summed in x, y, z, w order (Eigen's 4-wide norm sums in pairs: other last bits).
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  const double n = std::sqrt(x * x + y * y + z * z + w * w);
  Matrix m = Matrix::Identity();
  if (!(n > 0.0) || !std::isfinite(n)) return m;
  m.topLeftCorner<3, 3>() = Eigen::Quaterniond(w / n, x / n, y / n, z / n).toRotationMatrix();
  return m;
}

// Projects onto the plane y = h along the direction towards a directional light: d I - l p^T.
Matrix shadowMatrix(double h) {
  const auto& kKeyLight = kLighting.keyDirection;
  const Eigen::Vector4d l(kKeyLight[0], kKeyLight[1], kKeyLight[2], 0.0);
  const Eigen::Vector4d p(0.0, 1.0, 0.0, -h);
  return p.dot(l) * Matrix::Identity() - l * p.transpose();
}

bool meets(const msg::Aabb& a, const msg::Aabb& b) {
  for (std::size_t k = 0; k < 3; ++k) {
    if (a.min[k] > b.max[k] || b.min[k] > a.max[k]) return false;
  }
  return true;
}

bool finite(const msg::Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

void drawMesh(const DrawMesh& mesh) {
  if (mesh.indices.empty()) return;
  glEnableClientState(GL_VERTEX_ARRAY);
  glEnableClientState(GL_NORMAL_ARRAY);
  glVertexPointer(3, GL_FLOAT, 0, mesh.xyz.data());
  glNormalPointer(GL_FLOAT, 0, mesh.normals.data());
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT,
                 mesh.indices.data());
  glDisableClientState(GL_NORMAL_ARRAY);
  glDisableClientState(GL_VERTEX_ARRAY);
}

// A net's surface with smooth (area-weighted) normals from its current positions. Triangles
// naming a mass that does not exist are left out.
DrawMesh netMesh(const CachedObject& net) {
  DrawMesh mesh;
  const std::size_t masses = net.positions.size() / 3;
  mesh.xyz.resize(masses * 3);
  mesh.normals.assign(masses * 3, 0.0f);
  for (std::size_t i = 0; i < masses * 3; ++i) {
    const double v = net.positions[i];
    mesh.xyz[i] = std::isfinite(v) ? static_cast<float>(v) : 0.0f;
  }
  for (std::size_t t = 0; t + 2 < net.surface.size(); t += 3) {
    const std::uint32_t a = net.surface[t], b = net.surface[t + 1], c = net.surface[t + 2];
    if (a >= masses || b >= masses || c >= masses) continue;
    // Doubles of the float positions, as the normals were always computed.
    const auto p = [&](std::uint32_t i) -> Eigen::Vector3d {
      return Eigen::Map<const Eigen::Vector3f>(&mesh.xyz[std::size_t{3} * i]).cast<double>();
    };
    const Eigen::Vector3f n = (p(b) - p(a)).cross(p(c) - p(a)).cast<float>();
    for (const std::uint32_t i : {a, b, c}) {
      Eigen::Map<Eigen::Vector3f>(&mesh.normals[std::size_t{3} * i]) += n;
    }
    mesh.indices.insert(mesh.indices.end(), {a, b, c});
  }
  return mesh;
}

std::array<float, 3> hsvToRgb(double h, double s, double v) {
  const double c = v * s;
  const double hp = h * 6.0;
  const double x = c * (1.0 - std::abs(std::fmod(hp, 2.0) - 1.0));
  double r = 0, g = 0, b = 0;
  if (hp < 1)
    r = c, g = x;
  else if (hp < 2)
    r = x, g = c;
  else if (hp < 3)
    g = c, b = x;
  else if (hp < 4)
    g = x, b = c;
  else if (hp < 5)
    r = x, b = c;
  else
    r = c, b = x;
  const double m = v - c;
  return {static_cast<float>(r + m), static_cast<float>(g + m), static_cast<float>(b + m)};
}

}  // namespace

std::array<float, 3> objectColour(std::uint64_t id) {
  // Ids are prefix << 32 | counter (the prefix names the module that made them), and a
  // sender's objects usually have consecutive counters: stepping the hue by the golden ratio
  // per counter keeps neighbours far apart on the colour wheel; the prefix (hashed, splitmix64)
  // shifts the whole sequence.
  std::uint64_t z = (id >> 32) + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  const double offset = static_cast<double>(z >> 11) / 9007199254740992.0;  // [0, 1)
  const double counter = static_cast<double>(id & 0xFFFFFFFFull);
  const double hue = std::fmod(offset + counter * 0.6180339887498949, 1.0);
  return hsvToRgb(hue, 0.62, 0.88);
}

struct Renderer::Impl {
  RenderSettings settings;
  OSMesaContext context = nullptr;  // headless, or
  Window* window = nullptr;         // on screen
  std::vector<std::uint8_t> rgba;   // the OSMesa colour buffer, rows from the bottom
  int bufferWidth = 0;              // settings' size times the supersampling factor
  int bufferHeight = 0;
  DrawMesh unitSphere;      // point objects
  std::string description;  // GL_RENDERER and GL_VERSION

  ~Impl() {
    if (context) OSMesaDestroyContext(context);
  }

  bool bind();
  void setUpFrame(const Camera& camera, const Frustum& f) const;
  void drawGround() const;
  void drawObjects(const SceneCache& scene, bool shadowPass, const msg::Aabb* within) const;
};

bool Renderer::Impl::bind() {
  if (window) {
    window->makeCurrent();
    return true;
  }
  return OSMesaMakeCurrent(context, rgba.data(), GL_UNSIGNED_BYTE, bufferWidth, bufferHeight);
}

void Renderer::Impl::setUpFrame(const Camera& camera, const Frustum& f) const {
  const auto& s = settings;
  glViewport(0, 0, bufferWidth, bufferHeight);
  glClearColor(s.background[0], s.background[1], s.background[2], 1.0f);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glFrustum(f.left, f.right, f.bottom, f.top, f.nearPlane, f.farPlane);
  glMatrixMode(GL_MODELVIEW);
  const Matrix view = lookAt(camera);
  glLoadMatrixd(view.data());

  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glShadeModel(GL_SMOOTH);
  glEnable(GL_NORMALIZE);
  glEnable(GL_LIGHTING);
  const float ambient[4] = {kLighting.ambient, kLighting.ambient, kLighting.ambient, 1.0f};
  glLightModelfv(GL_LIGHT_MODEL_AMBIENT, ambient);
  glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);  // the net is seen from both sides
  const float key[4] = {kLighting.key, kLighting.key, kLighting.key, 1.0f};
  const float fill[4] = {kLighting.fill, kLighting.fill, kLighting.fill, 1.0f};
  const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  glEnable(GL_LIGHT0);
  const float keyPosition[4] = {kLighting.keyDirection[0], kLighting.keyDirection[1],
                                kLighting.keyDirection[2], 0.0f};
  glLightfv(GL_LIGHT0, GL_POSITION, keyPosition);  // in world space: after the view
  glLightfv(GL_LIGHT0, GL_DIFFUSE, key);
  glLightfv(GL_LIGHT0, GL_AMBIENT, black);
  glLightfv(GL_LIGHT0, GL_SPECULAR, black);
  glEnable(GL_LIGHT1);
  const float fillPosition[4] = {kLighting.fillDirection[0], kLighting.fillDirection[1],
                                 kLighting.fillDirection[2], 0.0f};
  glLightfv(GL_LIGHT1, GL_POSITION, fillPosition);
  glLightfv(GL_LIGHT1, GL_DIFFUSE, fill);
  glLightfv(GL_LIGHT1, GL_AMBIENT, black);
  glLightfv(GL_LIGHT1, GL_SPECULAR, black);
  glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, black);
  glEnable(GL_COLOR_MATERIAL);
  glColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
}

void Renderer::Impl::drawGround() const {
  const auto& s = settings;
  // Ground pixels get stencil 1, so that shadows land on the ground only and once.
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_ALWAYS, 1, 0xFF);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  const double tile = s.groundTile;
  const int tiles = static_cast<int>(std::ceil(s.groundHalfSize / tile));
  const double y = s.groundHeight;
  glNormal3d(0.0, 1.0, 0.0);
  glBegin(GL_QUADS);
  for (int i = -tiles; i < tiles; ++i) {
    for (int k = -tiles; k < tiles; ++k) {
      const auto& c = ((i + k) & 1) == 0 ? s.groundLight : s.groundDark;
      glColor3f(c[0], c[1], c[2]);
      const double x0 = i * tile, z0 = k * tile;
      // Counter-clockwise seen from above.
      glVertex3d(x0, y, z0);
      glVertex3d(x0, y, z0 + tile);
      glVertex3d(x0 + tile, y, z0 + tile);
      glVertex3d(x0 + tile, y, z0);
    }
  }
  glEnd();
  glDisable(GL_STENCIL_TEST);
}

void Renderer::Impl::drawObjects(const SceneCache& scene, bool shadowPass,
                                 const msg::Aabb* within) const {
  for (const auto& [id, object] : scene.objects()) {
    if (within != nullptr && object.bounds && !meets(*object.bounds, *within)) continue;
    if (!shadowPass) {
      const auto colour = objectColour(id);
      glColor3f(colour[0], colour[1], colour[2]);
    }
    switch (object.kind) {
      case ObjectKind::Rigid: {
        const DrawMesh* mesh = scene.shapeMesh(object.shapeId);
        if (!mesh || !finite(object.position)) break;
        glPushMatrix();
        glTranslated(object.position[0], object.position[1], object.position[2]);
        const Matrix r = rotation(object.orientation);
        glMultMatrixd(r.data());
        drawMesh(*mesh);
        glPopMatrix();
        break;
      }
      case ObjectKind::Point: {
        if (!finite(object.position)) break;
        glPushMatrix();
        glTranslated(object.position[0], object.position[1], object.position[2]);
        glScaled(settings.pointRadius, settings.pointRadius, settings.pointRadius);
        drawMesh(unitSphere);
        glPopMatrix();
        break;
      }
      case ObjectKind::MassSpring: {
        const DrawMesh mesh = netMesh(object);
        if (!mesh.indices.empty() && (shadowPass || !settings.netLines)) {
          drawMesh(mesh);
        } else if (!mesh.indices.empty()) {
          // The surface pushed back a little in depth, then its edges, darker, on top.
          glEnable(GL_POLYGON_OFFSET_FILL);
          glPolygonOffset(1.0f, 1.0f);
          drawMesh(mesh);
          glDisable(GL_POLYGON_OFFSET_FILL);
          const auto colour = objectColour(id);
          glDisable(GL_LIGHTING);
          glColor3f(colour[0] * 0.45f, colour[1] * 0.45f, colour[2] * 0.45f);
          glLineWidth(static_cast<float>(settings.supersample));
          glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
          drawMesh(mesh);
          glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
          glEnable(GL_LIGHTING);
        } else if (!shadowPass && !mesh.xyz.empty()) {
          // No surface: the masses as dots.
          glDisable(GL_LIGHTING);
          glPointSize(4.0f * static_cast<float>(settings.supersample));
          glEnableClientState(GL_VERTEX_ARRAY);
          glVertexPointer(3, GL_FLOAT, 0, mesh.xyz.data());
          glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(mesh.xyz.size() / 3));
          glDisableClientState(GL_VERTEX_ARRAY);
          glEnable(GL_LIGHTING);
        }
        break;
      }
      case ObjectKind::Fluid: {
        if (object.surfaceId != 0) {
          drawWater(scene, object.surfaceId, shadowPass);
          break;
        }
        const auto* xyz = scene.particles(object.particlesId);
        if (!xyz || xyz->empty() || shadowPass) break;
        const auto& c = settings.particleColour;
        glDisable(GL_LIGHTING);
        glColor3f(c[0], c[1], c[2]);
        glPointSize(settings.particleSize * static_cast<float>(settings.supersample));
        glEnableClientState(GL_VERTEX_ARRAY);
        glVertexPointer(3, GL_FLOAT, 0, xyz->data());
        glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(xyz->size() / 3));
        glDisableClientState(GL_VERTEX_ARRAY);
        glEnable(GL_LIGHTING);
        break;
      }
      case ObjectKind::User:
        drawSmoothMesh(scene, object.surfaceId, shadowPass, kUserColour);
        break;
    }
  }
}

Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
Renderer::~Renderer() = default;

const RenderSettings& Renderer::settings() const {
  return impl_->settings;
}

const std::string& Renderer::description() const {
  return impl_->description;
}

namespace {

Status checkSettings(const RenderSettings& settings) {
  if (settings.width < 1 || settings.height < 1 || settings.width > 8192 ||
      settings.height > 8192) {
    return makeError("image size must be 1..8192 pixels each way, got " +
                     std::to_string(settings.width) + "x" + std::to_string(settings.height));
  }
  if (settings.supersample < 1 || settings.supersample > 4 ||
      settings.width * settings.supersample > 8192 ||
      settings.height * settings.supersample > 8192) {
    return makeError("supersample must be 1..4 and keep the drawn size within 8192 pixels, got " +
                     std::to_string(settings.supersample));
  }
  if (!settings.blendMask.empty() &&
      settings.blendMask.size() != static_cast<std::size_t>(settings.width) * settings.height) {
    return makeError("the blend mask has " + std::to_string(settings.blendMask.size()) +
                     " bytes, not one per pixel of the image");
  }
  const Tile& t = settings.tile;
  if (t.cols < 1 || t.rows < 1 || t.col < 0 || t.row < 0 || t.col >= t.cols || t.row >= t.rows) {
    return makeError("tile " + std::to_string(t.col) + " " + std::to_string(t.row) + " of " +
                     std::to_string(t.cols) + " x " + std::to_string(t.rows) + " is not a tile");
  }
  return {};
}

}  // namespace

Result<Renderer> Renderer::create(const RenderSettings& settings) {
  if (auto valid = checkSettings(settings); !valid) return valid.error();
  auto impl = std::make_unique<Impl>();
  impl->settings = settings;
  impl->context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!impl->context) return makeError("OSMesa could not create an RGBA context with 24-bit depth");
  impl->bufferWidth = settings.width * settings.supersample;
  impl->bufferHeight = settings.height * settings.supersample;
  impl->rgba.resize(static_cast<std::size_t>(impl->bufferWidth) * impl->bufferHeight * 4);
  if (!OSMesaMakeCurrent(impl->context, impl->rgba.data(), GL_UNSIGNED_BYTE, impl->bufferWidth,
                         impl->bufferHeight)) {
    return makeError("OSMesa could not bind a " + std::to_string(impl->bufferWidth) + "x" +
                     std::to_string(impl->bufferHeight) + " frame buffer");
  }
  return Renderer(std::move(impl));
}

Result<Renderer> Renderer::create(const RenderSettings& settings, Window& window) {
  if (auto valid = checkSettings(settings); !valid) return valid.error();
  if (settings.supersample != 1) {
    return makeError("supersample must be 1 on screen, got " +
                     std::to_string(settings.supersample));
  }
  if (window.width() != settings.width || window.height() != settings.height) {
    return makeError("the window is " + std::to_string(window.width()) + "x" +
                     std::to_string(window.height()) + " pixels, not " +
                     std::to_string(settings.width) + "x" + std::to_string(settings.height));
  }
  auto impl = std::make_unique<Impl>();
  impl->settings = settings;
  impl->window = &window;
  impl->bufferWidth = settings.width;
  impl->bufferHeight = settings.height;
  impl->rgba.resize(static_cast<std::size_t>(impl->bufferWidth) * impl->bufferHeight * 4);
  impl->bind();
  return Renderer(std::move(impl));
}

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {
  const auto glString = [](GLenum name) {
    const auto* text = reinterpret_cast<const char*>(glGetString(name));
    return std::string(text ? text : "?");
  };
  impl_->description = glString(GL_RENDERER) + ", OpenGL " + glString(GL_VERSION);
  const auto sphere = msg::renderMesh(msg::Shape::sphere(1.0), 16);
  impl_->unitSphere = buildDrawMesh(sphere.xyz, sphere.indices);
}

Result<Image> Renderer::render(const SceneCache& scene, const Camera& camera,
                               const msg::Aabb* within) {
  // The tile's share of the whole view's window (the whole window for the default tile).
  const auto& s = impl_->settings;
  return render(scene, camera, tileFrustum(camera, s.tile, s.width, s.height), within);
}

Result<Image> Renderer::render(const SceneCache& scene, const Camera& camera,
                               const Frustum& frustum, const msg::Aabb* within) {
  Impl& r = *impl_;
  const auto& s = r.settings;
  if (!r.bind()) return makeError("OSMesa could not bind the frame buffer");
  if (!finite(camera.eye) || !finite(camera.target) || camera.eye == camera.target) {
    return makeError("camera eye and target must be finite and distinct");
  }
  r.setUpFrame(camera, frustum);
  if (s.ground) r.drawGround();
  r.drawObjects(scene, false, within);
  if (s.ground && s.shadows) {
    // Flattened objects, dark and translucent, on ground pixels not yet shadowed.
    glDisable(GL_LIGHTING);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_EQUAL, 1, 0xFF);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-1.0f, -4.0f);
    glDisable(GL_COLOR_MATERIAL);
    glColor4f(0.05f, 0.05f, 0.08f, 0.35f);
    glPushMatrix();
    const Matrix shadow = shadowMatrix(s.groundHeight);
    glMultMatrixd(shadow.data());
    r.drawObjects(scene, true, within);
    glPopMatrix();
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
  }
  if (!s.blendMask.empty()) applyBlendMask(s.blendMask, s.width, s.height, s.supersample);
  glFinish();
  if (r.window) {
    // The back buffer, before the caller swaps it to the front (rows from the bottom).
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, r.bufferWidth, r.bufferHeight, GL_RGBA, GL_UNSIGNED_BYTE, r.rgba.data());
  }
  if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
    return makeError("OpenGL error " + std::to_string(error) + " while rendering");
  }
  Image image;
  image.width = s.width;
  image.height = s.height;
  image.rgb.resize(static_cast<std::size_t>(s.width) * s.height * 3);
  // Rows from the top, each pixel the mean of its k x k drawn samples.
  const int k = s.supersample;
  const std::size_t rowBytes = static_cast<std::size_t>(r.bufferWidth) * 4;
  for (int y = 0; y < s.height; ++y) {
    std::uint8_t* to = image.rgb.data() + static_cast<std::size_t>(y) * s.width * 3;
    for (int x = 0; x < s.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        int sum = 0;
        for (int dy = 0; dy < k; ++dy) {
          const std::size_t row = static_cast<std::size_t>(r.bufferHeight - 1 - (y * k + dy));
          const std::uint8_t* from = r.rgba.data() + row * rowBytes;
          for (int dx = 0; dx < k; ++dx) sum += from[static_cast<std::size_t>(x * k + dx) * 4 + c];
        }
        to[3 * x + c] = static_cast<std::uint8_t>((sum + k * k / 2) / (k * k));
      }
    }
  }
  return image;
}

}  // namespace vrflow::viewer
