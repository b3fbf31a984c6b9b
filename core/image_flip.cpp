// LDR-FLIP: see image_flip.h. Constants are the paper's (§4.1 CSF, §4.2 colour metric,
// §4.3 feature detection); filters are direct 2-D convolutions with edge clamping.
#include "core/image_flip.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/error.h"

namespace speculum {

namespace {

constexpr double kPi = 3.14159265358979323846;

using Plane = std::vector<float>;

glm::vec3 linear_rgb_to_xyz(glm::vec3 c) {
  return {0.4124564f * c.x + 0.3575761f * c.y + 0.1804375f * c.z,
          0.2126729f * c.x + 0.7151522f * c.y + 0.0721750f * c.z,
          0.0193339f * c.x + 0.1191920f * c.y + 0.9503041f * c.z};
}
glm::vec3 xyz_to_linear_rgb(glm::vec3 c) {
  return {3.2404542f * c.x - 1.5371385f * c.y - 0.4985314f * c.z,
          -0.9692660f * c.x + 1.8760108f * c.y + 0.0415560f * c.z,
          0.0556434f * c.x - 0.2040259f * c.y + 1.0572252f * c.z};
}
const glm::vec3 kWhite = linear_rgb_to_xyz(glm::vec3(1.0f));  // D65 reference white

// YCxCz: a linear opponent space (§4.1).
glm::vec3 xyz_to_ycxcz(glm::vec3 c) {
  const glm::vec3 n = c / kWhite;
  return {116.0f * n.y - 16.0f, 500.0f * (n.x - n.y), 200.0f * (n.y - n.z)};
}
glm::vec3 ycxcz_to_xyz(glm::vec3 c) {
  const float y = (c.x + 16.0f) / 116.0f;
  return glm::vec3(c.y / 500.0f + y, y, y - c.z / 200.0f) * kWhite;
}
float lab_f(float t) {
  constexpr float d = 6.0f / 29.0f;
  return t > d * d * d ? std::cbrt(t) : t / (3.0f * d * d) + 4.0f / 29.0f;
}
glm::vec3 xyz_to_lab(glm::vec3 c) {
  const glm::vec3 n = c / kWhite;
  const float fx = lab_f(n.x), fy = lab_f(n.y), fz = lab_f(n.z);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}
// Hunt effect: chroma scales with lightness (§4.2).
glm::vec3 hunt(glm::vec3 lab) { return {lab.x, 0.01f * lab.x * lab.y, 0.01f * lab.x * lab.z}; }
float hyab(glm::vec3 a, glm::vec3 b) {
  const glm::vec3 d = a - b;
  return std::abs(d.x) + std::sqrt(d.y * d.y + d.z * d.z);
}

// Square kernel of side 2r+1 from f(x, y) in pixels.
struct Kernel {
  int r = 0;
  std::vector<float> w;
  float at(int x, int y) const { return w[std::size_t((y + r) * (2 * r + 1) + (x + r))]; }
};

Plane convolve(const Plane& in, int width, int height, const Kernel& k) {
  Plane out(in.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double sum = 0;
      for (int dy = -k.r; dy <= k.r; ++dy) {
        const int yy = std::clamp(y + dy, 0, height - 1);
        for (int dx = -k.r; dx <= k.r; ++dx) {
          const int xx = std::clamp(x + dx, 0, width - 1);
          sum += double(k.at(dx, dy)) * in[std::size_t(yy) * width + xx];
        }
      }
      out[std::size_t(y) * width + x] = float(sum);
    }
  return out;
}

// The contrast sensitivity filter of one YCxCz channel: a sum of two Gaussians in visual
// degrees, normalised to unit sum (§4.1, Table 1).
Kernel csf_kernel(double a1, double b1, double a2, double b2, double ppd) {
  const double bmax = std::max(b1, b2);
  Kernel k;
  k.r = int(std::ceil(3.0 * std::sqrt(bmax / (2.0 * kPi * kPi)) * ppd));
  const int n = 2 * k.r + 1;
  k.w.resize(std::size_t(n) * n);
  double sum = 0;
  for (int y = -k.r; y <= k.r; ++y)
    for (int x = -k.r; x <= k.r; ++x) {
      const double d2 = (double(x) * x + double(y) * y) / (ppd * ppd);
      auto g = [&](double a, double b) {
        return a * std::sqrt(kPi / b) * std::exp(-kPi * kPi * d2 / b);
      };
      const double v = g(a1, b1) + (a2 > 0 ? g(a2, b2) : 0.0);
      k.w[std::size_t((y + k.r) * n + (x + k.r))] = float(v);
      sum += v;
    }
  for (float& w : k.w) w = float(w / sum);
  return k;
}

// Edge (first derivative of a Gaussian along x) or point (second derivative) detector,
// positive and negative weights each normalised to ±1 (§4.3).
Kernel feature_kernel(bool point, double ppd) {
  const double sigma = 0.5 * 0.082 * ppd;
  Kernel k;
  k.r = int(std::ceil(3.0 * sigma));
  const int n = 2 * k.r + 1;
  k.w.resize(std::size_t(n) * n);
  double pos = 0, neg = 0;
  for (int y = -k.r; y <= k.r; ++y)
    for (int x = -k.r; x <= k.r; ++x) {
      const double g = std::exp(-(double(x) * x + double(y) * y) / (2.0 * sigma * sigma));
      const double v = point ? (double(x) * x / (sigma * sigma) - 1.0) * g : -double(x) * g;
      k.w[std::size_t((y + k.r) * n + (x + k.r))] = float(v);
      (v > 0 ? pos : neg) += v;
    }
  for (float& w : k.w) w = float(w > 0 ? w / pos : (w < 0 ? w / -neg : 0.0));
  return k;
}

// The kernel for the y direction.
Kernel transposed(const Kernel& k) {
  Kernel t = k;
  const int n = 2 * k.r + 1;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) t.w[std::size_t(y * n + x)] = k.w[std::size_t(x * n + y)];
  return t;
}

struct Features {
  Plane edge, point;
};

Features features(const ImageRGBA& img, const Kernel& ex, const Kernel& ey, const Kernel& px,
                  const Kernel& py) {
  Plane lum(img.size());
  for (std::size_t i = 0; i < img.size(); ++i) {
    const glm::vec3 c = glm::clamp(glm::vec3(img.pixels[i]), 0.0f, 1.0f);
    lum[i] = (xyz_to_ycxcz(linear_rgb_to_xyz(c)).x + 16.0f) / 116.0f;  // in [0, 1]
  }
  const Plane gx = convolve(lum, img.width, img.height, ex), gy = convolve(lum, img.width, img.height, ey);
  const Plane qx = convolve(lum, img.width, img.height, px), qy = convolve(lum, img.width, img.height, py);
  Features f{Plane(lum.size()), Plane(lum.size())};
  for (std::size_t i = 0; i < lum.size(); ++i) {
    f.edge[i] = std::sqrt(gx[i] * gx[i] + gy[i] * gy[i]);
    f.point[i] = std::sqrt(qx[i] * qx[i] + qy[i] * qy[i]);
  }
  return f;
}

// CSF-filtered image as Hunt-adjusted L*a*b*.
std::vector<glm::vec3> filtered_lab(const ImageRGBA& img, const Kernel (&csf)[3]) {
  Plane ch[3];
  for (auto& c : ch) c.resize(img.size());
  for (std::size_t i = 0; i < img.size(); ++i) {
    const glm::vec3 c = glm::clamp(glm::vec3(img.pixels[i]), 0.0f, 1.0f);
    const glm::vec3 o = xyz_to_ycxcz(linear_rgb_to_xyz(c));
    ch[0][i] = o.x, ch[1][i] = o.y, ch[2][i] = o.z;
  }
  for (int c = 0; c < 3; ++c) ch[c] = convolve(ch[c], img.width, img.height, csf[c]);
  std::vector<glm::vec3> out(img.size());
  for (std::size_t i = 0; i < img.size(); ++i) {
    const glm::vec3 rgb = glm::clamp(xyz_to_linear_rgb(ycxcz_to_xyz({ch[0][i], ch[1][i], ch[2][i]})), 0.0f, 1.0f);
    out[i] = hunt(xyz_to_lab(linear_rgb_to_xyz(rgb)));
  }
  return out;
}

}  // namespace

FlipResult flip_error(const ImageRGBA& reference, const ImageRGBA& test, const FlipOptions& options,
                      const std::string& what) {
  if (reference.width != test.width || reference.height != test.height)
    throw InputError(what, "sizes differ: " + std::to_string(reference.width) + "x" +
                               std::to_string(reference.height) + " vs " + std::to_string(test.width) +
                               "x" + std::to_string(test.height));
  if (!(options.pixels_per_degree > 0) || options.pixels_per_degree > 1000)
    throw InputError(what, "pixels per degree must be in (0, 1000]");
  FlipResult r;
  r.error = ImageF(reference.width, reference.height);
  if (reference.empty()) return r;
  const double ppd = options.pixels_per_degree;
  const Kernel csf[3] = {csf_kernel(1.0, 0.0047, 0.0, 1e-5, ppd), csf_kernel(1.0, 0.0053, 0.0, 1e-5, ppd),
                         csf_kernel(34.1, 0.04, 13.5, 0.025, ppd)};
  const std::vector<glm::vec3> a = filtered_lab(reference, csf), b = filtered_lab(test, csf);
  const Kernel ex = feature_kernel(false, ppd), px = feature_kernel(true, ppd);
  const Kernel ey = transposed(ex), py = transposed(px);
  const Features fa = features(reference, ex, ey, px, py), fb = features(test, ex, ey, px, py);

  // Colour error normalised by the largest difference (pure green vs pure blue) after the
  // power 0.7, then compressed so that errors above pc·cmax share the top (1 − pt) (§4.2).
  constexpr double kQc = 0.7, kPc = 0.4, kPt = 0.95, kQf = 0.5;
  const double cmax = std::pow(
      hyab(hunt(xyz_to_lab(linear_rgb_to_xyz({0, 1, 0}))), hunt(xyz_to_lab(linear_rgb_to_xyz({0, 0, 1})))), kQc);
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double dc = std::pow(double(hyab(a[i], b[i])), kQc);
    const double ec = dc < kPc * cmax ? kPt / (kPc * cmax) * dc
                                      : kPt + (dc - kPc * cmax) / (cmax - kPc * cmax) * (1.0 - kPt);
    const double df = std::pow(std::max(std::abs(fa.edge[i] - fb.edge[i]), std::abs(fa.point[i] - fb.point[i])) /
                                   std::sqrt(2.0), kQf);
    const double e = std::clamp(std::pow(std::min(ec, 1.0), 1.0 - std::min(df, 1.0)), 0.0, 1.0);
    r.error.pixels[i] = float(e);
    sum += e;
    r.max = std::max(r.max, e);
  }
  r.mean = sum / double(a.size());
  return r;
}

}  // namespace speculum
