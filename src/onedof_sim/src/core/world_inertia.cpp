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

// B^-1 for a positive definite B (the adjugate over the determinant).
Matrix3 inverse(const Matrix3& b) {
  Matrix3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
      out[i][j] = b[i1][j1] * b[i2][j2] - b[i1][j2] * b[i2][j1];
    }
  const double det = b[0][0] * out[0][0] + b[0][1] * out[1][0] + b[0][2] * out[2][0];
  for (auto& row : out)
    for (double& value : row) value /= det;
  return out;
}

double quadratic(const Matrix3& b, const Vec3& u, const Vec3& v) {
  const double uu[3] = {u.x, u.y, u.z}, vv[3] = {v.x, v.y, v.z};
  double sum = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) sum += uu[i] * b[i][j] * vv[j];
  return sum;
}

// The lever ratio of a point p (from the centre of mass) of a body of mass m and inverse inertia
// tensor b: how much faster a force at p, across the line to p, moves p by turning the body than
// by moving it, at the worst direction of the force (m |p|^2 times the largest eigenvalue of b
// on the plane normal to p). A point on a uniform solid has about 2 to 8.
double leverRatio(double m, const Matrix3& b, const Vec3& p) {
  const double length = norm(p);
  if (length == 0) return 0;
  const Vec3 n = (1 / length) * p;
  const Vec3 away = std::abs(n.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 across = cross(n, away);
  const Vec3 a = (1 / norm(across)) * across;
  const Vec3 c = cross(n, a);
  const double aa = quadratic(b, a, a), cc = quadratic(b, c, c), ac = quadratic(b, a, c);
  const double largest = (aa + cc) / 2 + std::hypot((aa - cc) / 2, ac);
  return m * length * length * largest;
}

// The largest lever ratio over the corners of each shape's bounding box (for a cylinder or a
// sphere a little beyond the shape, which errs on the accepting side by at most 3; for a mesh,
// the box that bounds its vertices).
double largestLeverRatio(const BodySpec& body, const Matrix3& inertia) {
  const Matrix3 b = inverse(inertia);
  double largest = 0;
  for (const ShapeSpec& shape : body.shapes) {
    const Vec3 half = shape.shape == GeometryShape::Box
                          ? 0.5 * shape.size
                          : shape.shape == GeometryShape::Cylinder
                                ? Vec3{shape.size.x, shape.size.x, shape.size.z / 2}
                                : Vec3{shape.size.x, shape.size.x, shape.size.x};
    const Vec3 low = shape.mesh ? shape.mesh->min : -1.0 * half;
    const Vec3 high = shape.mesh ? shape.mesh->max : half;
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 local{corner & 1 ? high.x : low.x, corner & 2 ? high.y : low.y,
                       corner & 4 ? high.z : low.z};
      const Vec3 p = transformPoint(shape.pose, local);
      largest = std::max(largest, leverRatio(body.mass, b, p));
    }
  }
  return largest;
}

}  // namespace

double momentAbout(const BodySpec& body, const Vec3& u) {
  return body.ixx * u.x * u.x + body.iyy * u.y * u.y + body.izz * u.z * u.z +
         2 * (body.ixy * u.x * u.y + body.ixz * u.x * u.z + body.iyz * u.y * u.z);
}

LumpFault lumpBody(ModelRecord* model, int body, BodySpec* out, MomentBounds* bounds) {
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
  const double smallest = smallestEigenvalue(inertia);
  if (bounds) *bounds = {smallest, kMinMoment, kMaxMoment};
  if (smallest < kMinMoment || largest > kMaxMoment) return LumpFault::MomentOutOfRange;
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
      if (isAnchored(link, collision)) continue;
      ShapeSpec shape = shapeSpec(collision);
      shape.pose = compose(link.link_in_body, collision.pose);
      spec.shapes.push_back(shape);
    }
  }
  // Scaling the tensor by s scales every lever ratio by 1/s: the smallest moment that brings the
  // largest ratio down to kMaxLeverRatio is the present one times their quotient.
  const double lever = largestLeverRatio(spec, inertia);
  if (bounds && lever > kMaxLeverRatio) bounds->least_for_shapes = smallest * lever / kMaxLeverRatio;
  *out = spec;
  return LumpFault::None;
}

std::optional<InertiaWarning> inertiaWarning(const ModelRecord& model, int body,
                                             const MomentBounds& bounds) {
  if (!(bounds.least_for_shapes > 0)) return std::nullopt;
  return InertiaWarning{referenceLink(model, body).desc.name, bounds.smallest,
                        bounds.least_for_shapes};
}

}  // namespace core
}  // namespace onedof_sim
