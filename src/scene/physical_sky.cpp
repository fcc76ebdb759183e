/// @file scene/physical_sky.cpp
/// @brief The daylight sky of the scene's sun (scene.h, physicalSky): Preetham,
/// Shirley and Smits, "A Practical Analytic Model for Daylight" (SIGGRAPH
/// 1999), its luminance and chromaticity per direction, scaled so that the
/// sky stands to the scene's sun as the model's sky to the sun through the
/// same atmosphere (Kasten's Rayleigh optical depth with the turbidity as
/// Linke's).

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace lo {

namespace {

/// Perez et al.'s luminance distribution: (1 + A e^(B / cos theta)) (1 + C
/// e^(D gamma) + E cos^2 gamma), theta from the zenith, gamma from the sun.
struct Perez {
  double a, b, c, d, e;
  double operator()(double cosTheta, double gamma) const {
    const double cosGamma = std::cos(gamma);
    return (1.0 + a * std::exp(b / std::max(cosTheta, 1e-3))) *
           (1.0 + c * std::exp(d * gamma) + e * cosGamma * cosGamma);
  }
};

/// The model's coefficients for luminance Y and chromaticities x, y
/// (Preetham et al. 1999, appendix A.2), linear in the turbidity.
Perez perezY(double t) {
  return {0.1787 * t - 1.4630, -0.3554 * t + 0.4275, -0.0227 * t + 5.3251, 0.1206 * t - 2.5771,
          -0.0670 * t + 0.3703};
}
Perez perezX(double t) {
  return {-0.0193 * t - 0.2592, -0.0665 * t + 0.0008, -0.0004 * t + 0.2125, -0.0641 * t - 0.8989,
          -0.0033 * t + 0.0452};
}
Perez perezy(double t) {
  return {-0.0167 * t - 0.2608, -0.0950 * t + 0.0092, -0.0079 * t + 0.2102, -0.0441 * t - 1.6537,
          -0.0109 * t + 0.0529};
}

/// CIE xyY to linear Rec. 709 RGB (the renderer's primaries, D65 white).
Vec3 rgbOfxyY(double x, double y, double Y) {
  if (!(y > 0)) return {0, 0, 0};
  const double X = x / y * Y, Z = (1.0 - x - y) / y * Y;
  const double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
  const double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
  const double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
  return {float(std::max(r, 0.0)), float(std::max(g, 0.0)), float(std::max(b, 0.0))};
}

}  // namespace

DaylightZenith daylightZenith(double sunZenith, double turbidity) {
  const double t = turbidity, s = sunZenith;
  const double chi = (4.0 / 9.0 - t / 120.0) * (kPi - 2.0 * s);
  DaylightZenith z;
  z.luminance = 1000.0 * ((4.0453 * t - 4.9710) * std::tan(chi) - 0.2155 * t + 2.4192);
  const double s2 = s * s, s3 = s2 * s, t2 = t * t;
  z.x = t2 * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * s) +
        t * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * s + 0.00394) +
        (0.11693 * s3 - 0.21196 * s2 + 0.06052 * s + 0.25886);
  z.y = t2 * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * s) +
        t * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * s + 0.00516) +
        (0.15346 * s3 - 0.26756 * s2 + 0.06670 * s + 0.26688);
  return z;
}

double directSunIlluminance(double sunZenith, double turbidity) {
  // Kasten and Young's relative air mass, Kasten's Rayleigh optical depth,
  // the turbidity as Linke's (ESRA: B_n = E0 exp(-0.8662 T_L m dR(m))).
  const double elevation = 90.0 - sunZenith * 180.0 / kPi;
  const double m = 1.0 / (std::cos(sunZenith) + 0.50572 * std::pow(elevation + 6.07995, -1.6364));
  const double rayleigh =
      m > 20.0 ? 1.0 / (10.4 + 0.718 * m)
               : 1.0 / (6.6296 + m * (1.7513 + m * (-0.1202 + m * (0.0065 - m * 0.00013))));
  return kSolarIlluminance * std::exp(-0.8662 * turbidity * m * rayleigh);
}

void physicalSky(Scene& scene, float turbidity, int width) {
  const std::string where = scene.sourcePath.empty() ? "scene" : scene.sourcePath;
  if (!(turbidity >= kMinTurbidity && turbidity <= kMaxTurbidity)) {
    throw InputError(where + ": turbidity " + std::to_string(turbidity) + " is outside [" +
                     std::to_string(kMinTurbidity).substr(0, 3) + ", " +
                     std::to_string(int(kMaxTurbidity)) + "] (2: very clear, 3: clear, 6: hazy)");
  }
  if (width < 8 || width > 16384 || width % 2 != 0) {
    throw InputError(where + ": physical sky image width " + std::to_string(width) +
                     " must be even, from 8 to 16384");
  }
  const Light* sun = nullptr;
  for (const Light& l : scene.lights) {
    if (l.type == Light::Type::Directional) {
      sun = &l;
      break;
    }
  }
  if (!sun) {
    throw InputError(where + ": a physical sky is the sky of the scene's sun: the scene has no "
                             "directional light");
  }
  const Vec3 towardsSun = normalize(sun->direction) * -1.0f;
  if (!(towardsSun.y > 0.01f)) {
    throw InputError(where + ": the sun ('" + sun->name +
                     "') is at or below the horizon: the daylight model holds above it");
  }
  const double sunZenith = std::acos(double(towardsSun.y));
  const double t = turbidity;
  const DaylightZenith zenith = daylightZenith(sunZenith, t);
  const Perez fY = perezY(t), fx = perezX(t), fy = perezy(t);
  const double gY = fY(1.0, sunZenith), gx = fx(1.0, sunZenith), gy = fy(1.0, sunZenith);
  // The scene's sun in lux (1 lx = 1 W/m^2), against the model's: the sky
  // keeps the model's ratio to it.
  const Vec3 sunRgb = sun->color * sun->intensity;
  const double sunLux = 0.2126 * sunRgb.x + 0.7152 * sunRgb.y + 0.0722 * sunRgb.z;
  const double scale = sunLux / directSunIlluminance(sunZenith, t);

  const int w = width, h = width / 2;
  std::vector<Vec3> radiance(size_t(w) * size_t(h), Vec3{0, 0, 0});
  for (int y = 0; y < h / 2; ++y) {
    for (int x = 0; x < w; ++x) {
      const Vec3 d = skyPixelDirection(float(x) + 0.5f, float(y) + 0.5f, w, h);
      const double cosTheta = double(d.y);
      const double gamma = std::acos(std::clamp(double(dot(d, towardsSun)), -1.0, 1.0));
      const double Y = zenith.luminance * fY(cosTheta, gamma) / gY;
      const double cx = zenith.x * fx(cosTheta, gamma) / gx;
      const double cy = zenith.y * fy(cosTheta, gamma) / gy;
      radiance[size_t(y) * size_t(w) + size_t(x)] = rgbOfxyY(cx, cy, std::max(Y, 0.0) * scale);
    }
  }
  auto image = std::make_shared<Texture>(Texture::fromLinear(w, h, radiance));
  image->name = "physical sky (turbidity " + std::to_string(turbidity).substr(0, 4) + ")";
  scene.sky.image = std::move(image);
  scene.sky.radiance = Vec3{1, 1, 1};
}

}  // namespace lo
