#define GL_GLEXT_PROTOTYPES 1
#include "renderer.h"

#include <GL/glcorearb.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <sstream>

#include "egl_context.h"
#include "materials.h"
#include "onedof_sim/pose_math.h"
#include "primitives.h"

namespace onedof_sim {
namespace render {
namespace {

// Gazebo's default world: <scene><ambient> 0.4, <background> 0.7; the sun's diffuse 0.8 and
// direction.
constexpr float kSceneAmbient = 0.4f, kBackground = 0.7f, kSunDiffuse = 0.8f;
constexpr double kSunDirection[3] = {-0.5, 0.1, -0.9};

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
uniform mat4 model_view;
uniform mat4 projection;
uniform mat3 normal_to_world;
out vec3 world_normal;
out float optical_depth;
void main() {
  vec4 eye = model_view * vec4(position, 1.0);
  world_normal = normal_to_world * normal;
  optical_depth = -eye.z;
  gl_Position = projection * eye;
}
)";

const char* kFragmentShader = R"(#version 330 core
in vec3 world_normal;
in float optical_depth;
uniform vec3 ambient;
uniform vec3 diffuse;
uniform vec3 emissive;
uniform vec3 to_sun;
uniform float scene_ambient;
uniform float sun_diffuse;
layout(location = 0) out vec4 color;
layout(location = 1) out float depth;
void main() {
  vec3 n = normalize(world_normal);
  if (!gl_FrontFacing) n = -n;
  float lit = max(dot(n, to_sun), 0.0);
  color = vec4(clamp(ambient * scene_ambient + diffuse * sun_diffuse * lit + emissive, 0.0, 1.0),
               1.0);
  depth = optical_depth;
}
)";

using Mat4 = std::array<double, 16>;  // column-major, as OpenGL takes it

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 out{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) out[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return out;
}

// The rotation matrix of a unit quaternion, row-major.
std::array<double, 9> rotation(const Quat& q) {
  const Quat u = normalized(q);
  const double w = u.w, x = u.x, y = u.y, z = u.z;
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

// The pose's transform with a scale along its own axes first.
Mat4 poseMatrix(const Pose& pose, const Vec3& scale) {
  const auto r = rotation(pose.orientation);
  const double s[3] = {scale.x, scale.y, scale.z};
  Mat4 m{};
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[row * 3 + c] * s[c];
  m[12] = pose.position.x, m[13] = pose.position.y, m[14] = pose.position.z, m[15] = 1;
  return m;
}

// World to OpenGL's eye frame: into the camera frame, then x_eye = -y, y_eye = z, z_eye = -x.
Mat4 viewMatrix(const Pose& camera) {
  const auto r = rotation(camera.orientation);
  const double p[3] = {camera.position.x, camera.position.y, camera.position.z};
  // Rows of the world-to-camera rotation are the columns of r.
  const auto row = [&](int axis, double sign, int out_row, Mat4* m) {
    double t = 0;
    for (int k = 0; k < 3; ++k) {
      (*m)[k * 4 + out_row] = sign * r[k * 3 + axis];
      t += sign * r[k * 3 + axis] * p[k];
    }
    (*m)[12 + out_row] = -t;
  };
  Mat4 m{};
  row(1, -1, 0, &m);
  row(2, 1, 1, &m);
  row(0, -1, 2, &m);
  m[15] = 1;
  return m;
}

Mat4 projectionMatrix(const CameraSpec& camera) {
  const double fx = 1 / std::tan(camera.horizontal_fov / 2);
  const double fy = fx * camera.width / camera.height;
  const double n = camera.near_clip, f = camera.far_clip;
  Mat4 m{};
  m[0] = fx;
  m[5] = fy;
  m[10] = (f + n) / (n - f);
  m[11] = -1;
  m[14] = 2 * f * n / (n - f);
  return m;
}

std::array<float, 16> toFloat(const Mat4& m) {
  std::array<float, 16> out;
  for (int i = 0; i < 16; ++i) out[i] = static_cast<float>(m[i]);
  return out;
}

struct GpuShape {
  GLuint array = 0, buffer = 0;
  GLsizei vertices = 0;
};

GLuint compile(GLenum type, const char* source, std::string* error) {
  GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {0};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    *error = std::string("a shader does not compile: ") + log;
    glDeleteShader(shader);
    return 0;
  }
  return shader;
}

bool finitePositive(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

struct Renderer::Impl {
  std::unique_ptr<EglContext> context;
  GLuint program = 0;
  GLint model_view = -1, projection = -1, normal_to_world = -1, ambient = -1, diffuse = -1,
        emissive = -1, to_sun = -1, scene_ambient = -1, sun_diffuse = -1;
  std::map<GeometryShape, GpuShape> unit_shapes;
  std::map<std::string, GpuShape> meshes;  // key: file and scale
  std::set<std::string> failed_meshes;
  GLuint framebuffer = 0, color = 0, depth_out = 0, depth_test = 0;
  int width = 0, height = 0, channel_bits = 0;
  std::set<std::string> reported;
  std::vector<std::string> problems;
  // The pixels as read back (bottom row first), kept from frame to frame.
  std::vector<uint8_t> rgb_rows;
  std::vector<uint16_t> rgb16_rows;
  std::vector<float> depth_rows;

  GpuShape upload(const std::vector<float>& vertices) {
    GpuShape shape;
    glGenVertexArrays(1, &shape.array);
    glBindVertexArray(shape.array);
    glGenBuffers(1, &shape.buffer);
    glBindBuffer(GL_ARRAY_BUFFER, shape.buffer);
    glBufferData(GL_ARRAY_BUFFER, vertices.size() * sizeof(float), vertices.data(),
                 GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    shape.vertices = static_cast<GLsizei>(vertices.size() / 6);
    return shape;
  }

  void report(const VisualShape& visual, const std::string& why) {
    const std::string name = visual.model + "::" + visual.link + "::" + visual.name;
    if (reported.insert(name + ": " + why).second) problems.push_back(name + ": " + why);
  }

  // The shape to draw for the visual, or null (reported) when it cannot be drawn.
  const GpuShape* shapeFor(const VisualShape& visual) {
    const Vec3& s = visual.size;
    if (visual.shape != GeometryShape::Mesh) {
      const bool ok = visual.shape == GeometryShape::Box ? finitePositive(s.x) &&
                                                               finitePositive(s.y) &&
                                                               finitePositive(s.z)
                      : visual.shape == GeometryShape::Cylinder
                          ? finitePositive(s.x) && finitePositive(s.z)
                      : visual.shape == GeometryShape::Plane
                          ? finitePositive(s.x) && finitePositive(s.y)
                          : finitePositive(s.x);
      if (!ok) {
        report(visual, "not drawn: its size is not positive and finite");
        return nullptr;
      }
      auto found = unit_shapes.find(visual.shape);
      if (found == unit_shapes.end())
        found = unit_shapes.emplace(visual.shape, upload(unitShapeVertices(visual.shape))).first;
      return &found->second;
    }
    if (visual.mesh_file.empty()) {
      report(visual, "not drawn: its mesh '" + visual.mesh_uri + "' is not found");
      return nullptr;
    }
    std::ostringstream key;
    key.precision(17);
    key << visual.mesh_file << ' ' << s.x << ' ' << s.y << ' ' << s.z;
    auto found = meshes.find(key.str());
    if (found != meshes.end()) return &found->second;
    if (failed_meshes.count(key.str())) return nullptr;
    std::shared_ptr<const TriangleMesh> mesh;
    const Status status = readVisualMesh(visual.mesh_file, s, &mesh);
    if (!status.ok()) {
      failed_meshes.insert(key.str());
      report(visual, "not drawn: " + status.subject);
      return nullptr;
    }
    return &meshes.emplace(key.str(), upload(meshVertices(*mesh))).first->second;
  }

  void resize(int w, int h, int bits) {
    if (w == width && h == height && bits == channel_bits) return;
    if (framebuffer) {
      glDeleteFramebuffers(1, &framebuffer);
      glDeleteRenderbuffers(1, &color);
      glDeleteRenderbuffers(1, &depth_out);
      glDeleteRenderbuffers(1, &depth_test);
    }
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    const auto attach = [&](GLuint* buffer, GLenum format, GLenum attachment) {
      glGenRenderbuffers(1, buffer);
      glBindRenderbuffer(GL_RENDERBUFFER, *buffer);
      glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, *buffer);
    };
    attach(&color, bits == 16 ? GL_RGBA16 : GL_RGBA8, GL_COLOR_ATTACHMENT0);
    attach(&depth_out, GL_R32F, GL_COLOR_ATTACHMENT1);
    attach(&depth_test, GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT);
    const GLenum outputs[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, outputs);
    width = w, height = h, channel_bits = bits;
  }
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Renderer::~Renderer() {
  if (!impl_->context || !impl_->context->makeCurrent()) return;
  for (auto* shapes : {&impl_->unit_shapes})
    for (auto& [kind, shape] : *shapes) {
      glDeleteBuffers(1, &shape.buffer);
      glDeleteVertexArrays(1, &shape.array);
    }
  for (auto& [key, shape] : impl_->meshes) {
    glDeleteBuffers(1, &shape.buffer);
    glDeleteVertexArrays(1, &shape.array);
  }
  if (impl_->framebuffer) {
    glDeleteFramebuffers(1, &impl_->framebuffer);
    glDeleteRenderbuffers(1, &impl_->color);
    glDeleteRenderbuffers(1, &impl_->depth_out);
    glDeleteRenderbuffers(1, &impl_->depth_test);
  }
  if (impl_->program) glDeleteProgram(impl_->program);
}

std::unique_ptr<Renderer> Renderer::create(std::string* error) {
  auto impl = std::make_unique<Impl>();
  impl->context = EglContext::create(error);
  if (!impl->context) return nullptr;
  const GLuint vertex = compile(GL_VERTEX_SHADER, kVertexShader, error);
  if (!vertex) return nullptr;
  const GLuint fragment = compile(GL_FRAGMENT_SHADER, kFragmentShader, error);
  if (!fragment) return nullptr;
  const GLuint program = glCreateProgram();
  glAttachShader(program, vertex);
  glAttachShader(program, fragment);
  glLinkProgram(program);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  GLint linked = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  if (!linked) {
    *error = "the shaders do not link";
    glDeleteProgram(program);
    return nullptr;
  }
  impl->program = program;
  const auto uniform = [&](const char* name) { return glGetUniformLocation(program, name); };
  impl->model_view = uniform("model_view");
  impl->projection = uniform("projection");
  impl->normal_to_world = uniform("normal_to_world");
  impl->ambient = uniform("ambient");
  impl->diffuse = uniform("diffuse");
  impl->emissive = uniform("emissive");
  impl->to_sun = uniform("to_sun");
  impl->scene_ambient = uniform("scene_ambient");
  impl->sun_diffuse = uniform("sun_diffuse");
  return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

std::string Renderer::description() const {
  if (!impl_->context->makeCurrent()) return "";
  return std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) + "; " +
         reinterpret_cast<const char*>(glGetString(GL_VERSION));
}

std::vector<std::string> Renderer::takeProblems() {
  std::vector<std::string> out;
  out.swap(impl_->problems);
  return out;
}

bool Renderer::render(const std::vector<VisualShape>& visuals, const CameraSpec& camera,
                      Frame* frame, std::string* error) {
  if (!(camera.horizontal_fov > 0 && camera.horizontal_fov < M_PI)) {
    *error = "horizontal_fov must be in (0, pi) rad";
    return false;
  }
  if (camera.width < 1 || camera.height < 1 || camera.width > kMaxSide ||
      camera.height > kMaxSide) {
    *error = "width and height must be in [1, " + std::to_string(kMaxSide) + "] pixels";
    return false;
  }
  if (!(camera.near_clip > 0 && camera.far_clip > camera.near_clip &&
        std::isfinite(camera.far_clip))) {
    *error = "near and far clip must be finite with 0 < near < far";
    return false;
  }
  if (camera.channel_bits != 8 && camera.channel_bits != 16) {
    *error = "channel_bits must be 8 or 16";
    return false;
  }
  if (!impl_->context->makeCurrent()) {
    *error = "the renderer's EGL context cannot be made current";
    return false;
  }
  Impl& gl = *impl_;
  gl.resize(camera.width, camera.height, camera.channel_bits);
  glBindFramebuffer(GL_FRAMEBUFFER, gl.framebuffer);
  glViewport(0, 0, camera.width, camera.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glCullFace(GL_BACK);  // faces wound counter-clockwise seen from outside are the front
  const float background[4] = {kBackground, kBackground, kBackground, 1};
  const float far_clip[4] = {static_cast<float>(camera.far_clip), 0, 0, 0};
  const float farthest = 1;
  glClearBufferfv(GL_COLOR, 0, background);
  glClearBufferfv(GL_COLOR, 1, far_clip);
  glClearBufferfv(GL_DEPTH, 0, &farthest);

  glUseProgram(gl.program);
  const Mat4 view = viewMatrix(camera.pose);
  glUniformMatrix4fv(gl.projection, 1, GL_FALSE, toFloat(projectionMatrix(camera)).data());
  const double sun_length = std::sqrt(kSunDirection[0] * kSunDirection[0] +
                                      kSunDirection[1] * kSunDirection[1] +
                                      kSunDirection[2] * kSunDirection[2]);
  glUniform3f(gl.to_sun, static_cast<float>(-kSunDirection[0] / sun_length),
              static_cast<float>(-kSunDirection[1] / sun_length),
              static_cast<float>(-kSunDirection[2] / sun_length));
  glUniform1f(gl.scene_ambient, kSceneAmbient);
  glUniform1f(gl.sun_diffuse, kSunDiffuse);
  for (const VisualShape& visual : visuals) {
    const GpuShape* shape = gl.shapeFor(visual);
    if (!shape) continue;
    bool known = true;
    const SurfaceColors colors = resolveMaterial(visual.material, &known);
    if (!known)
      gl.report(visual, "material '" + visual.material.script +
                            "' is not one of Gazebo's the renderer has; drawn in its given "
                            "colours, else white");
    Vec3 scale{1, 1, 1};
    if (visual.shape == GeometryShape::Box) scale = visual.size;
    if (visual.shape == GeometryShape::Cylinder) scale = {visual.size.x, visual.size.x, visual.size.z};
    if (visual.shape == GeometryShape::Sphere) scale = {visual.size.x, visual.size.x, visual.size.x};
    if (visual.shape == GeometryShape::Plane) scale = {visual.size.x, visual.size.y, 1};
    // Closed solids show their outside only, as OGRE's default culling draws them in Gazebo: a
    // camera inside its own case (a box around the lens) sees out of it. Planes and meshes (which
    // may be open) show both sides.
    if (visual.shape == GeometryShape::Plane || visual.shape == GeometryShape::Mesh)
      glDisable(GL_CULL_FACE);
    else
      glEnable(GL_CULL_FACE);
    const Mat4 model = poseMatrix(visual.pose, scale);
    glUniformMatrix4fv(gl.model_view, 1, GL_FALSE, toFloat(multiply(view, model)).data());
    // Normals to the world: the rotation times the inverse scale (the inverse transpose of R S).
    const auto r = rotation(visual.pose.orientation);
    float normal_matrix[9];
    const double s[3] = {scale.x, scale.y, scale.z};
    for (int c = 0; c < 3; ++c)
      for (int row = 0; row < 3; ++row)
        normal_matrix[c * 3 + row] = static_cast<float>(r[row * 3 + c] / s[c]);
    glUniformMatrix3fv(gl.normal_to_world, 1, GL_FALSE, normal_matrix);
    glUniform3f(gl.ambient, colors.ambient.r, colors.ambient.g, colors.ambient.b);
    glUniform3f(gl.diffuse, colors.diffuse.r, colors.diffuse.g, colors.diffuse.b);
    glUniform3f(gl.emissive, colors.emissive.r, colors.emissive.g, colors.emissive.b);
    glBindVertexArray(shape->array);
    glDrawArrays(GL_TRIANGLES, 0, shape->vertices);
  }

  // OpenGL's rows run bottom-up; the image's top-down.
  const int w = camera.width, h = camera.height;
  const bool deep = camera.channel_bits == 16;
  const size_t row_values = static_cast<size_t>(w) * 3;
  std::vector<float>& depth = gl.depth_rows;
  depth.resize(static_cast<size_t>(w) * h);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  if (deep) {
    gl.rgb16_rows.resize(row_values * h);
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_SHORT, gl.rgb16_rows.data());
  } else {
    gl.rgb_rows.resize(row_values * h);
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, gl.rgb_rows.data());
  }
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  glReadPixels(0, 0, w, h, GL_RED, GL_FLOAT, depth.data());
  frame->width = w, frame->height = h;
  frame->rgb.resize(deep ? 0 : row_values * h);
  frame->rgb16.resize(deep ? row_values * h : 0);
  frame->depth.resize(depth.size());
  for (int row = 0; row < h; ++row) {
    const size_t from = static_cast<size_t>(h - 1 - row), to = static_cast<size_t>(row);
    if (deep)
      std::copy_n(gl.rgb16_rows.data() + from * row_values, row_values,
                  frame->rgb16.data() + to * row_values);
    else
      std::copy_n(gl.rgb_rows.data() + from * row_values, row_values,
                  frame->rgb.data() + to * row_values);
    std::copy_n(depth.data() + from * w, w, frame->depth.data() + to * w);
  }
  const GLenum gl_error = glGetError();
  if (gl_error != GL_NO_ERROR) {
    std::ostringstream text;
    text << "OpenGL error 0x" << std::hex << gl_error;
    *error = text.str();
    return false;
  }
  return true;
}

}  // namespace render
}  // namespace onedof_sim
