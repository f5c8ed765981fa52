// Lumping the links welded into one body: their masses, centre of mass and inertia tensors.
#include <algorithm>
#include <array>
#include <cmath>

#include "world_impl.h"

namespace onedof_sim {
namespace core {

namespace {

// A symmetric 3x3 inertia tensor, for lumping welded links into one body.
using Matrix3 = std::array<std::array<double, 3>, 3>;

Matrix3 rotationMatrix(const Quat& q) {
  Matrix3 r;
  const Vec3 columns[3] = {rotate(q, {1, 0, 0}), rotate(q, {0, 1, 0}), rotate(q, {0, 0, 1})};
  for (int c = 0; c < 3; ++c) {
    r[0][c] = columns[c].x;
    r[1][c] = columns[c].y;
    r[2][c] = columns[c].z;
  }
  return r;
}

// R I R^T: a tensor given in a frame rotated by q, expressed in the outer frame.
Matrix3 rotateTensor(const Quat& q, const Matrix3& inertia) {
  const Matrix3 r = rotationMatrix(q);
  Matrix3 out{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l) out[i][j] += r[i][k] * inertia[k][l] * r[j][l];
  return out;
}

// Parallel axes: the tensor of a point mass m at offset d, about the origin.
Matrix3 pointMassTensor(double m, const Vec3& d) {
  const double v[3] = {d.x, d.y, d.z};
  Matrix3 out{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = m * ((i == j ? dot(d, d) : 0) - v[i] * v[j]);
  return out;
}

// The smallest eigenvalue of a symmetric matrix (the trigonometric closed form).
double smallestEigenvalue(const Matrix3& m) {
  const double off = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
  if (off == 0) return std::min({m[0][0], m[1][1], m[2][2]});
  const double mean = (m[0][0] + m[1][1] + m[2][2]) / 3;
  const double a = m[0][0] - mean, b = m[1][1] - mean, c = m[2][2] - mean;
  const double p = std::sqrt((a * a + b * b + c * c + 2 * off) / 6);
  const double det = a * (b * c - m[1][2] * m[1][2]) - m[0][1] * (m[0][1] * c - m[1][2] * m[0][2]) +
                     m[0][2] * (m[0][1] * m[1][2] - b * m[0][2]);
  const double r = std::clamp(det / (2 * p * p * p), -1.0, 1.0);
  return mean + 2 * p * std::cos(std::acos(r) / 3 + 2 * M_PI / 3);
}

// Sylvester's criterion: what no rigid body violates.
bool isPositiveDefinite(const Matrix3& m) {
  const double minor2 = m[0][0] * m[1][1] - m[0][1] * m[1][0];
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  return m[0][0] > 0 && minor2 > 0 && det > 0;
}

}  // namespace

double momentAbout(const BodySpec& body, const Vec3& u) {
  return body.ixx * u.x * u.x + body.iyy * u.y * u.y + body.izz * u.z * u.z +
         2 * (body.ixy * u.x * u.y + body.ixz * u.x * u.z + body.iyz * u.y * u.z);
}

LumpFault lumpBody(ModelRecord* model, int body, BodySpec* out) {
  const LinkRecord& reference = referenceLink(*model, body);
  double mass = 0;
  Vec3 moment;
  Matrix3 tensor{};  // about the reference link's origin
  for (const LinkRecord& link : model->links) {
    const LinkDescription& d = link.desc;
    if (link.body != body || !d.has_inertial || d.mass == 0) continue;
    const Pose inertial = compose(compose(inverse(reference.desc.pose), d.pose), d.com);
    const Matrix3 own{{{d.ixx, d.ixy, d.ixz}, {d.ixy, d.iyy, d.iyz}, {d.ixz, d.iyz, d.izz}}};
    const Matrix3 rotated = rotateTensor(inertial.orientation, own);
    const Matrix3 offset = pointMassTensor(d.mass, inertial.position);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) tensor[i][j] += rotated[i][j] + offset[i][j];
    mass += d.mass;
    moment = moment + d.mass * inertial.position;
  }
  if (!(mass > 0)) return LumpFault::NoMass;
  const Vec3 com = (1 / mass) * moment;
  const Matrix3 to_com = pointMassTensor(mass, com);
  Matrix3 inertia;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) inertia[i][j] = tensor[i][j] - to_com[i][j];
  if (!isPositiveDefinite(inertia)) return LumpFault::NotPositiveDefinite;
  const double largest = std::max({inertia[0][0], inertia[1][1], inertia[2][2]});
  if (smallestEigenvalue(inertia) < kMinMoment || largest > kMaxMoment)
    return LumpFault::MomentOutOfRange;
  BodySpec spec;
  spec.mass = mass;
  spec.ixx = inertia[0][0], spec.iyy = inertia[1][1], spec.izz = inertia[2][2];
  spec.ixy = inertia[0][1], spec.ixz = inertia[0][2], spec.iyz = inertia[1][2];
  spec.gravity = reference.desc.gravity;
  // Body frame: at the COM, axes of the reference link.
  const Pose reference_inverse = inverse(reference.desc.pose);
  for (LinkRecord& link : model->links) {
    if (link.body != body) continue;
    const Pose link_in_reference = compose(reference_inverse, link.desc.pose);
    link.link_in_body = {link_in_reference.position - com, link_in_reference.orientation};
    for (const CollisionDescription& collision : link.desc.collisions) {
      ShapeSpec shape = shapeSpec(collision);
      shape.pose = compose(link.link_in_body, collision.pose);
      spec.shapes.push_back(shape);
    }
  }
  *out = spec;
  return LumpFault::None;
}

}  // namespace core
}  // namespace onedof_sim
