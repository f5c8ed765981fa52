#include "lens_distortion.h"

#include <algorithm>
#include <cmath>

namespace onedof_sim {
namespace render {
namespace {

// Newton's method stops once a step moves the point less than this (normalised units: a
// millionth of a pixel at a focal length of a thousand pixels), or after so many steps.
constexpr double kTolerance = 1e-9;
constexpr int kMaxSteps = 60;

// The model's value and Jacobian at (x, y).
struct Distorted {
  double x, y;
  double dx_dx, dx_dy, dy_dx, dy_dy;
  double radial;
};

Distorted evaluate(const DistortionCoefficients& lens, double x, double y) {
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (lens.k1 + r2 * (lens.k2 + r2 * lens.k3));
  const double radial_r2 = lens.k1 + r2 * (2 * lens.k2 + 3 * lens.k3 * r2);  // d radial / d r^2
  Distorted d;
  d.radial = radial;
  d.x = x * radial + 2 * lens.p1 * x * y + lens.p2 * (r2 + 2 * x * x);
  d.y = y * radial + lens.p1 * (r2 + 2 * y * y) + 2 * lens.p2 * x * y;
  const double cross = 2 * x * y * radial_r2;
  d.dx_dx = radial + 2 * x * x * radial_r2 + 2 * lens.p1 * y + 6 * lens.p2 * x;
  d.dx_dy = cross + 2 * lens.p1 * x + 2 * lens.p2 * y;
  d.dy_dx = cross + 2 * lens.p1 * x + 2 * lens.p2 * y;
  d.dy_dy = radial + 2 * y * y * radial_r2 + 6 * lens.p1 * y + 2 * lens.p2 * x;
  return d;
}

// The normalised point the lens shows at (x_d, y_d); false where there is none: Newton's method
// does not settle, or settles on a point the lens shows turned over or through its centre
// (the Jacobian's determinant or the radial factor not positive: past a fold).
bool undistort(const DistortionCoefficients& lens, double x_d, double y_d, double* x,
               double* y) {
  double u = x_d, v = y_d;
  for (int step = 0; step < kMaxSteps; ++step) {
    const Distorted d = evaluate(lens, u, v);
    const double det = d.dx_dx * d.dy_dy - d.dx_dy * d.dy_dx;
    if (!std::isfinite(det) || det == 0) return false;
    const double ex = d.x - x_d, ey = d.y - y_d;
    const double du = (d.dy_dy * ex - d.dx_dy * ey) / det;
    const double dv = (d.dx_dx * ey - d.dy_dx * ex) / det;
    u -= du, v -= dv;
    if (std::abs(du) + std::abs(dv) < kTolerance) {
      const Distorted at = evaluate(lens, u, v);
      if (!(at.dx_dx * at.dy_dy - at.dx_dy * at.dy_dx > 0 && at.radial > 0)) return false;
      *x = u, *y = v;
      return true;
    }
  }
  return false;
}

}  // namespace

void distortNormalised(const DistortionCoefficients& lens, double x, double y, double* x_d,
                       double* y_d) {
  const Distorted d = evaluate(lens, x, y);
  *x_d = d.x, *y_d = d.y;
}

LensDistortion::LensDistortion(const DistortionCoefficients& lens, int width, int height,
                               double focal_pixels, long max_render_pixels)
    : width_(width), height_(height), focal_(focal_pixels) {
  // The lens centre in pixel coordinates (pixel i's centre at i).
  const double cx = lens.center_x * width - 0.5, cy = lens.center_y * height - 0.5;
  const size_t pixels = static_cast<size_t>(width) * height;
  std::vector<double> from_x(pixels), from_y(pixels);
  std::vector<bool> seen(pixels);
  double low_x = 0, high_x = width - 1, low_y = 0, high_y = height - 1;
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) {
      const size_t p = static_cast<size_t>(row) * width + col;
      double x, y;
      if (!undistort(lens, (col - cx) / focal_pixels, (row - cy) / focal_pixels, &x, &y))
        continue;
      seen[p] = true;
      from_x[p] = cx + focal_pixels * x;
      from_y[p] = cy + focal_pixels * y;
      low_x = std::min(low_x, from_x[p]), high_x = std::max(high_x, from_x[p]);
      low_y = std::min(low_y, from_y[p]), high_y = std::max(high_y, from_y[p]);
    }
  // The margins the rays need (one more pixel for the interpolation), within the bounds.
  const auto margin = [](double low, double high, int size) {
    const double beyond = std::max(-low, high - (size - 1));
    const double wanted = beyond > 0 ? std::ceil(beyond) + 1 : 0;
    return static_cast<int>(std::min<double>(
        wanted, std::min(size / 2, (Renderer::kMaxSide - size) / 2)));
  };
  margin_x_ = margin(low_x, high_x, width);
  margin_y_ = margin(low_y, high_y, height);
  while (static_cast<long>(renderWidth()) * renderHeight() > max_render_pixels &&
         (margin_x_ > 0 || margin_y_ > 0)) {
    if (margin_x_ * height >= margin_y_ * width)
      --margin_x_;
    else
      --margin_y_;
  }

  const int render_width = renderWidth(), render_height = renderHeight();
  sources_.assign(pixels, Source());
  for (size_t p = 0; p < pixels; ++p) {
    const double sx = from_x[p] + margin_x_, sy = from_y[p] + margin_y_;
    if (!seen[p] || sx < 0 || sy < 0 || sx > render_width - 1 || sy > render_height - 1) {
      ++black_pixels_;
      continue;
    }
    // The top left of the four, kept inside the render: at its last column or row the weight
    // towards the next is 1 (or, one pixel wide, 0 towards itself).
    const int x0 = std::max(0, std::min(static_cast<int>(sx), render_width - 2));
    const int y0 = std::max(0, std::min(static_cast<int>(sy), render_height - 2));
    sources_[p].pixel = y0 * render_width + x0;
    sources_[p].weight_x = static_cast<uint16_t>(std::lround((sx - x0) * kWeightOne));
    sources_[p].weight_y = static_cast<uint16_t>(std::lround((sy - y0) * kWeightOne));
  }
}

double LensDistortion::renderHorizontalFov() const {
  return 2 * std::atan(renderWidth() / (2 * focal_));
}

template <class Channel>
void LensDistortion::remap(const std::vector<Channel>& from, std::vector<Channel>* to) const {
  const int render_width = renderWidth();
  const size_t right = render_width > 1 ? 3 : 0;
  const size_t down = renderHeight() > 1 ? static_cast<size_t>(render_width) * 3 : 0;
  // Weights of kWeightOne^2 in all: a 16-bit channel's sum stays within 32 bits.
  constexpr uint32_t kOne = kWeightOne, kHalf = kWeightOne * kWeightOne / 2;
  static_assert(65535ull * kWeightOne * kWeightOne + kHalf <= 0xffffffffull, "overflow");
  to->resize(sources_.size() * 3);
  Channel* out = to->data();
  for (const Source& source : sources_) {
    if (source.pixel < 0) {
      out[0] = out[1] = out[2] = 0;
      out += 3;
      continue;
    }
    const uint32_t wx = source.weight_x, wy = source.weight_y;
    const Channel* a = &from[static_cast<size_t>(source.pixel) * 3];
    const Channel* b = a + right;
    const Channel* c = a + down;
    const Channel* d = c + right;
    for (int k = 0; k < 3; ++k) {
      const uint32_t top = a[k] * (kOne - wx) + b[k] * wx;
      const uint32_t bottom = c[k] * (kOne - wx) + d[k] * wx;
      *out++ = static_cast<Channel>((top * (kOne - wy) + bottom * wy + kHalf) /
                                    (kOne * kOne));
    }
  }
}

void LensDistortion::apply(const Frame& rendered, Frame* out) const {
  const int render_width = renderWidth();
  out->width = width_, out->height = height_;
  if (!rendered.rgb16.empty()) {
    remap(rendered.rgb16, &out->rgb16);
    out->rgb.clear();
  } else {
    remap(rendered.rgb, &out->rgb);
    out->rgb16.clear();
  }
  out->depth.resize(static_cast<size_t>(width_) * height_);
  for (int row = 0; row < height_; ++row)
    std::copy_n(rendered.depth.data() +
                    static_cast<size_t>(row + margin_y_) * render_width + margin_x_,
                width_, out->depth.data() + static_cast<size_t>(row) * width_);
}

}  // namespace render
}  // namespace onedof_sim
