/// @file material/bsdf.cpp
/// @brief The tracers' glTF material: dielectric (diffuse base and specular
/// layer, evaluated by material/gltf_brdf.h), GGX metal, Fresnel glass.

#include "material/bsdf.h"

#include "material/gltf_brdf.h"

#include <material_brdf.h>

#include <algorithm>
#include <cmath>

namespace lo {

namespace {

/// Smith Lambda for GGX, w in the local frame (z = normal): the renderer's
/// text (shaders/material_brdf.h).
float smithLambda(const Vec3& w, float alpha) { return brdf::loGgxLambda(w.z, alpha); }

/// GGX normal distribution D(m), m in the local frame; 0 below the surface.
float ggxD(const Vec3& m, float alpha) { return m.z > 0 ? brdf::loGgxD(m.z, alpha) : 0.0f; }

/// GGX visible-normal sample (Heitz 2018) for local outgoing direction wo (wo.z > 0).
Vec3 sampleGgxVisibleNormal(const Vec3& wo, float alpha, float u1, float u2) {
  Vec3 vh = normalize(Vec3{alpha * wo.x, alpha * wo.y, wo.z});
  float lensq = vh.x * vh.x + vh.y * vh.y;
  Vec3 t1 = lensq > 0 ? Vec3{-vh.y, vh.x, 0} / std::sqrt(lensq) : Vec3{1, 0, 0};
  Vec3 t2 = cross(vh, t1);
  float r = std::sqrt(u1);
  float phi = 2.0f * kPi * u2;
  float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  Vec3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2));
  return normalize(Vec3{alpha * nh.x, alpha * nh.y, std::max(0.0f, nh.z)});
}

Vec3 reflect(const Vec3& wo, const Vec3& n) { return n * (2.0f * dot(wo, n)) - wo; }

/// Solid-angle density of a VNDF-sampled reflection wi of local wo through
/// the half vector m (local): D_wo(m) / (4 wo.m) = G1(wo) D(m) / (4 cos(wo)).
float vndfReflectionPdf(const Vec3& woL, const Vec3& m, float alpha) {
  float g1 = 1.0f / (1.0f + smithLambda(woL, alpha));
  return g1 * ggxD(m, alpha) / (4.0f * woL.z);
}

/// The probability with which the dielectric lobe samples its specular
/// layer rather than the cosine: the layer's expected share of the light
/// leaving towards wo (Schlick's F at n.wo against the base's (1 - F)
/// albedo), kept away from 0 and 1 so that neither density vanishes.
float specularLayerProbability(const BsdfLobes& lobes, const Vec3& albedo, float cosO) {
  if (!(lobes.layerWeight > 0)) return 0;
  float c = 1.0f - std::clamp(cosO, 0.0f, 1.0f);
  float fresnel =
      lobes.layerWeight * (lobes.dielectricF0 + (1.0f - lobes.dielectricF0) * (c * c * c * c * c));
  float base = (1.0f - fresnel) * (0.2126f * albedo.x + 0.7152f * albedo.y + 0.0722f * albedo.z);
  return std::clamp(fresnel / std::max(fresnel + base, 1e-6f), 0.1f, 0.9f);
}

/// The dielectric lobe, f(wo, wi) cos(wi) (wi above the surface): the
/// glTF BRDF at metallic 0 (both layers), or the Lambert base alone.
Vec3 dielectricCos(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& wi,
                   const Vec3& n, float cosI) {
  if (!(lobes.layerWeight > 0)) return albedo * (kInvPi * cosI);
  const GltfBrdfLobes l = gltfBrdfLobes(
      {albedo, 0.0f, lobes.roughness, 0.0f, lobes.dielectricF0, lobes.layerWeight}, n, wo, wi);
  return (l.diffuse + l.specular) * cosI;
}

/// The metal lobe's f(wo, wi) cos(wi) (non-delta, wi above the surface).
Vec3 metalCos(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& wi,
              const Vec3& n, float cosI) {
  return gltfBrdfLobes({albedo, 1.0f, lobes.roughness, 0.0f}, n, wo, wi).specular * cosI;
}

/// The dielectric lobe's density of wi: the mixture of the cosine and the
/// specular layer's visible normals.
float dielectricPdf(const BsdfLobes& lobes, float layerProbability, const Vec3& woL,
                    const Vec3& m, float cosI) {
  float pdf = (1.0f - layerProbability) * cosI * kInvPi;
  if (layerProbability > 0) pdf += layerProbability * vndfReflectionPdf(woL, m, lobes.alpha);
  return pdf;
}

Vec3 schlick(const Vec3& f0, float cosine) {
  float c = 1.0f - std::max(0.0f, cosine);
  return f0 + (Vec3{1, 1, 1} - f0) * (c * c * c * c * c);
}

}  // namespace

BsdfLobes bsdfLobes(const Material& m) { return bsdfLobes(m, m.metallic, m.roughness); }

BsdfLobes bsdfLobes(const Material& m, float metallicIn, float roughnessIn) {
  BsdfLobes info;
  float metallic = std::clamp(metallicIn, 0.0f, 1.0f);
  float transmission = std::clamp(m.transmission, 0.0f, 1.0f);
  float roughness = std::clamp(roughnessIn, 0.0f, 1.0f);
  info.metalWeight = metallic;
  info.transmissionWeight = (1.0f - metallic) * transmission;
  info.diffuseWeight = (1.0f - metallic) * (1.0f - transmission);
  info.roughness = roughness;
  info.alpha = std::max(roughness * roughness, kMirrorAlpha);
  info.dielectricF0 = m.dielectricF0();
  info.layerWeight = std::clamp(m.specular, 0.0f, 1.0f);
  info.ior = m.ior > 0 ? m.ior : 1.5f;
  info.thinWalled = !(m.thickness > 0);
  info.storesPhotons = info.diffuseWeight > 0 || (metallic > 0 && roughness > kGlossyRoughness);
  return info;
}

Vec3 hemisphericalReflectance(const BsdfLobes& lobes, const Vec3& albedo) {
  auto meanSchlick = [](float f0) { return f0 + (1.0f - f0) / 21.0f; };
  const float layer = lobes.layerWeight * meanSchlick(lobes.dielectricF0);
  const Vec3 dielectric = albedo * (1.0f - layer) + Vec3(layer);
  const Vec3 metal{meanSchlick(albedo.x), meanSchlick(albedo.y), meanSchlick(albedo.z)};
  const float f0 = (lobes.ior - 1.0f) / (lobes.ior + 1.0f);
  const float glass = meanSchlick(f0 * f0);
  return dielectric * lobes.diffuseWeight + metal * lobes.metalWeight +
         Vec3(glass * lobes.transmissionWeight);
}

float fresnelDielectric(float cosI, float n1, float n2, float& cosT) {
  float eta = n1 / n2;
  float sin2T = eta * eta * std::max(0.0f, 1.0f - cosI * cosI);
  if (sin2T >= 1.0f) {
    cosT = 0;
    return 1.0f;
  }
  cosT = std::sqrt(1.0f - sin2T);
  float rs = (n1 * cosI - n2 * cosT) / (n1 * cosI + n2 * cosT);
  float rp = (n2 * cosI - n1 * cosT) / (n2 * cosI + n1 * cosT);
  return 0.5f * (rs * rs + rp * rp);
}

bool sampleBsdf(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& n,
                bool frontFace, Rng& rng, BsdfSample& out) {
  float lobe = rng.uniform();
  out.delta = false;
  out.passThrough = false;
  if (lobe < lobes.transmissionWeight) {
    // Smooth dielectric: reflect with the Fresnel probability, else refract.
    // Flux needs no eta^2 factor; radiance would, but the path tracer follows
    // importance from the camera, where the two factors cancel over a
    // round trip, so none is applied in either direction.
    // A thin wall is entered and left at once: the interface seen from the
    // air on either side.
    const bool entering = frontFace || lobes.thinWalled;
    float n1 = entering ? 1.0f : lobes.ior, n2 = entering ? lobes.ior : 1.0f;
    float cosI = std::min(1.0f, dot(wo, n)), cosT = 0;
    float f = fresnelDielectric(cosI, n1, n2, cosT);
    out.delta = true;
    if (rng.uniform() < f) {
      out.wi = reflect(wo, n);
      out.weight = Vec3{1, 1, 1};
    } else if (lobes.thinWalled) {
      out.wi = -wo;
      out.weight = albedo;
      out.passThrough = true;
    } else {
      float eta = n1 / n2;
      out.wi = -wo * eta + n * (eta * cosI - cosT);
      out.weight = albedo;  // KHR_materials_transmission tints transmitted light by baseColor
    }
    return true;
  }
  if (lobe < lobes.transmissionWeight + lobes.metalWeight) {
    // Metal: GGX reflection, Schlick Fresnel with F0 = baseColor.
    if (lobes.mirrorMetal()) {
      out.wi = reflect(wo, n);
      out.weight = schlick(albedo, dot(wo, n));
      out.delta = true;
      return true;
    }
    Vec3 tt, bb;
    orthonormalBasis(n, tt, bb);
    Vec3 woLocal{dot(wo, tt), dot(wo, bb), std::max(1e-6f, dot(wo, n))};
    float u1 = rng.uniform(), u2 = rng.uniform();
    Vec3 m = sampleGgxVisibleNormal(woLocal, lobes.alpha, u1, u2);
    Vec3 wiLocal = reflect(woLocal, m);
    if (wiLocal.z <= 0) return false;
    // f cos / pdf of VNDF sampling = F * G2 / G1(wo) (height-correlated Smith).
    float lo = smithLambda(woLocal, lobes.alpha), li = smithLambda(wiLocal, lobes.alpha);
    out.weight = schlick(albedo, dot(woLocal, m)) * ((1.0f + lo) / (1.0f + lo + li));
    out.wi = fromLocal(wiLocal, tt, bb, n);
    return true;
  }
  Vec3 tt, bb;
  orthonormalBasis(n, tt, bb);
  const float cosO = std::max(1e-6f, dot(wo, n));
  const float layer = specularLayerProbability(lobes, albedo, cosO);
  if (layer <= 0) {
    float u1 = rng.uniform(), u2 = rng.uniform();
    out.wi = fromLocal(cosineHemisphere(u1, u2), tt, bb, n);
    out.weight = albedo;
    return true;
  }
  // The dielectric: one direction from the mixture, weighted by the whole
  // lobe over the mixture's density (one-sample MIS, balance heuristic).
  const Vec3 woL{dot(wo, tt), dot(wo, bb), cosO};
  float choice = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  Vec3 wiL = choice < layer ? reflect(woL, sampleGgxVisibleNormal(woL, lobes.alpha, u1, u2))
                            : cosineHemisphere(u1, u2);
  if (wiL.z <= 0) return false;
  wiL = normalize(wiL);
  const Vec3 m = normalize(woL + wiL);
  const float pdf = dielectricPdf(lobes, layer, woL, m, wiL.z);
  if (!(pdf > 0)) return false;
  out.wi = fromLocal(wiL, tt, bb, n);
  out.weight = dielectricCos(lobes, albedo, wo, normalize(out.wi), n, wiL.z) / pdf;
  return true;
}

Vec3 evalBsdf(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& wi,
              const Vec3& n) {
  float cosI = dot(wi, n), cosO = dot(wo, n);
  if (cosI <= 0 || cosO <= 0) return Vec3{0, 0, 0};
  Vec3 f{0, 0, 0};
  if (lobes.diffuseWeight > 0) {
    f += dielectricCos(lobes, albedo, wo, wi, n, cosI) * lobes.diffuseWeight;
  }
  if (lobes.metalWeight > 0 && !lobes.mirrorMetal()) {
    f += metalCos(lobes, albedo, wo, wi, n, cosI) * lobes.metalWeight;
  }
  return f;
}

float pdfBsdf(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& wi,
              const Vec3& n) {
  float cosI = dot(wi, n), cosO = dot(wo, n);
  if (cosI <= 0 || cosO <= 0) return 0;
  Vec3 tt, bb;
  orthonormalBasis(n, tt, bb);
  const Vec3 woL{dot(wo, tt), dot(wo, bb), cosO};
  const Vec3 h = normalize(wo + wi);
  const Vec3 m{dot(h, tt), dot(h, bb), dot(h, n)};
  float pdf = 0;
  if (lobes.diffuseWeight > 0) {
    const float layer = specularLayerProbability(lobes, albedo, std::max(1e-6f, cosO));
    pdf += lobes.diffuseWeight * dielectricPdf(lobes, layer, woL, m, cosI);
  }
  if (lobes.metalWeight > 0 && !lobes.mirrorMetal()) {
    pdf += lobes.metalWeight * vndfReflectionPdf(woL, m, lobes.alpha);
  }
  return pdf;
}

}  // namespace lo
