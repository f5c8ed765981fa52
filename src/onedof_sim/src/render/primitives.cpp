#include "primitives.h"

#include <cmath>

namespace onedof_sim {
namespace render {
namespace {

// Round shapes: segments around the axis, rings from pole to pole. At 64 segments a chord
// strays from the circle by 0.12 % of the radius.
constexpr int kSegments = 64, kRings = 32;

struct V {
  double x, y, z;
};

void push(std::vector<float>* out, const V& p, const V& n) {
  out->insert(out->end(), {static_cast<float>(p.x), static_cast<float>(p.y),
                           static_cast<float>(p.z), static_cast<float>(n.x),
                           static_cast<float>(n.y), static_cast<float>(n.z)});
}

void triangle(std::vector<float>* out, const V& a, const V& b, const V& c, const V& n) {
  push(out, a, n), push(out, b, n), push(out, c, n);
}

std::vector<float> box() {
  std::vector<float> out;
  // Each face: its normal axis and sign, two corners' in-plane axes wound counter-clockwise.
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      const auto at = [&](double u, double v) {
        double c[3];
        c[axis] = 0.5 * sign;
        c[(axis + 1) % 3] = u * sign;
        c[(axis + 2) % 3] = v;
        return V{c[0], c[1], c[2]};
      };
      double n[3] = {0, 0, 0};
      n[axis] = sign;
      const V normal{n[0], n[1], n[2]};
      triangle(&out, at(-0.5, -0.5), at(0.5, -0.5), at(0.5, 0.5), normal);
      triangle(&out, at(-0.5, -0.5), at(0.5, 0.5), at(-0.5, 0.5), normal);
    }
  return out;
}

std::vector<float> cylinder() {
  std::vector<float> out;
  for (int i = 0; i < kSegments; ++i) {
    const double a0 = 2 * M_PI * i / kSegments, a1 = 2 * M_PI * (i + 1) / kSegments;
    const V n0{std::cos(a0), std::sin(a0), 0}, n1{std::cos(a1), std::sin(a1), 0};
    const V b0{n0.x, n0.y, -0.5}, b1{n1.x, n1.y, -0.5}, t0{n0.x, n0.y, 0.5}, t1{n1.x, n1.y, 0.5};
    push(&out, b0, n0), push(&out, b1, n1), push(&out, t1, n1);
    push(&out, b0, n0), push(&out, t1, n1), push(&out, t0, n0);
    triangle(&out, {0, 0, 0.5}, t0, t1, {0, 0, 1});
    triangle(&out, {0, 0, -0.5}, b1, b0, {0, 0, -1});
  }
  return out;
}

std::vector<float> sphere() {
  std::vector<float> out;
  const auto at = [](int ring, int segment) {
    const double polar = M_PI * ring / kRings, around = 2 * M_PI * segment / kSegments;
    return V{std::sin(polar) * std::cos(around), std::sin(polar) * std::sin(around),
             std::cos(polar)};
  };
  for (int r = 0; r < kRings; ++r)
    for (int s = 0; s < kSegments; ++s) {
      const V a = at(r, s), b = at(r + 1, s), c = at(r + 1, s + 1), d = at(r, s + 1);
      push(&out, a, a), push(&out, b, b), push(&out, c, c);
      push(&out, a, a), push(&out, c, c), push(&out, d, d);
    }
  return out;
}

std::vector<float> plane() {
  std::vector<float> out;
  const V n{0, 0, 1};
  triangle(&out, {-0.5, -0.5, 0}, {0.5, -0.5, 0}, {0.5, 0.5, 0}, n);
  triangle(&out, {-0.5, -0.5, 0}, {0.5, 0.5, 0}, {-0.5, 0.5, 0}, n);
  return out;
}

}  // namespace

std::vector<float> unitShapeVertices(GeometryShape shape) {
  switch (shape) {
    case GeometryShape::Box: return box();
    case GeometryShape::Cylinder: return cylinder();
    case GeometryShape::Sphere: return sphere();
    case GeometryShape::Plane: return plane();
    case GeometryShape::Mesh: break;
  }
  return {};
}

std::vector<float> meshVertices(const TriangleMesh& mesh) {
  std::vector<float> out;
  out.reserve(mesh.triangles.size() * 18);
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    const V u{b.x - a.x, b.y - a.y, b.z - a.z}, w{c.x - a.x, c.y - a.y, c.z - a.z};
    V n{u.y * w.z - u.z * w.y, u.z * w.x - u.x * w.z, u.x * w.y - u.y * w.x};
    const double length = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
    if (!(length > 0)) continue;  // a degenerate triangle covers no pixel
    n = {n.x / length, n.y / length, n.z / length};
    triangle(&out, {a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}, n);
  }
  return out;
}

}  // namespace render
}  // namespace onedof_sim
