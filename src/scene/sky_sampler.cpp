/// @file scene/sky_sampler.cpp
/// @brief Light sampling of the sky: texels by radiance, or the hemisphere.

#include "scene/sky_sampler.h"

#include <algorithm>
#include <cmath>

namespace lo {

SkySampler::SkySampler(const Sky& sky, const std::function<float(const Vec3&)>& weight) {
  if (!sky.present()) return;
  if (!sky.image) {
    sky_ = &sky;
    return;
  }
  const Texture& image = *sky.image;
  width_ = image.width;
  height_ = image.height;
  for (int y = 0; y < height_; ++y) {
    const float omega = skyPixelSolidAngle(y, width_, height_);
    if (!(omega > 0)) break;
    for (int x = 0; x < width_; ++x) {
      const Vec3 d = skyPixelDirection(float(x) + 0.5f, float(y) + 0.5f, width_, height_);
      const Vec3 l = sky.radiance * image.texel(x, y);
      const double w = weight ? double(weight(d)) : 1.0;
      texels_.add(double(average(l)) * double(omega) * w);
    }
  }
  if (texels_.total() > 0) sky_ = &sky;
}

bool SkySampler::sample(double u0, float u1, float u2, Vec3& towards, float& pdf) const {
  if (!sky_) return false;
  if (width_ == 0) {
    // Uniform over the upper hemisphere: y = cos theta uniform.
    const float y = u1, r = std::sqrt(std::max(0.0f, 1.0f - y * y)), phi = 2.0f * kPi * u2;
    towards = {r * std::cos(phi), y, r * std::sin(phi)};
    pdf = 1.0f / (2.0f * kPi);
    return y > 0;
  }
  const size_t k = texels_.sample(u0);
  const int x = int(k % size_t(width_)), y = int(k / size_t(width_));
  const float top = kPi * float(y) / float(height_);
  const float bottom = std::min(kPi * float(y + 1) / float(height_), 0.5f * kPi);
  const float cosTheta = std::cos(top) - u1 * (std::cos(top) - std::cos(bottom));
  const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  const float phi = 2.0f * kPi * ((float(x) + u2) / float(width_) - 0.5f);
  towards = {sinTheta * std::sin(phi), cosTheta, -sinTheta * std::cos(phi)};
  pdf = float(texels_.pmf(k) / double(skyPixelSolidAngle(y, width_, height_)));
  return cosTheta > 0 && pdf > 0;
}

float SkySampler::pdf(const Vec3& towards) const {
  if (!sky_ || !(towards.y > 0)) return 0.0f;
  if (width_ == 0) return 1.0f / (2.0f * kPi);
  int x = 0, y = 0;
  skyPixelOf(towards, width_, height_, x, y);
  const float omega = skyPixelSolidAngle(y, width_, height_);
  const size_t k = size_t(y) * size_t(width_) + size_t(x);
  if (!(omega > 0) || k >= texels_.size()) return 0.0f;
  return float(texels_.pmf(k) / double(omega));
}

}  // namespace lo
