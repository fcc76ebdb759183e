// Direct light of the scene pass: punctual lights, emitter VPLs and area
// lights (render/lights.cpp fills the block). Part of render_scene.frag, after
// render_lights.h, material_brdf.h and render_scene_shadows.glsl;
// LO_DIRECT_LIGHT only.

// Irradiance on the surface (p, n) from a Lambertian triangle (a, b, c) of
// unit radiance: the projected solid angle of the triangle clipped to the
// surface's upper hemisphere, 1/2 sum_i theta_i n.unit(u_i x u_i+1) over its
// edges (Lambert's formula; Arvo 1995), exact. `lightCentre` is the clipped
// polygon's vertex mean, the direction the BRDF is evaluated in.
float polygonIrradiance(vec3 p, vec3 n, vec3 a, vec3 b, vec3 c, out vec3 lightCentre) {
  vec3 q[3] = vec3[3](a - p, b - p, c - p);
  vec3 poly[4];
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    vec3 s = q[i], e = q[(i + 1) % 3];
    float ds = dot(n, s), de = dot(n, e);
    if (ds >= 0.0 && count < 4) {
      poly[count] = s;
      ++count;
    }
    if ((ds >= 0.0) != (de >= 0.0) && count < 4) {
      poly[count] = mix(s, e, ds / (ds - de));
      ++count;
    }
  }
  lightCentre = p;
  if (count < 3) return 0.0;
  float sum = 0.0;
  vec3 mean = vec3(0.0);
  for (int i = 0; i < count; ++i) {
    vec3 u0 = normalize(poly[i]), u1 = normalize(poly[(i + 1) % count]);
    vec3 cr = cross(u0, u1);
    float s = length(cr);
    if (s > 1e-9) sum += atan(s, dot(u0, u1)) * dot(cr, n) / s;
    mean += poly[i];
  }
  lightCentre = p + mean / float(count);
  return 0.5 * abs(sum);
}

// The point of triangle (a, b, c) nearest p (Ericson, Real-Time Collision
// Detection, 5.1.5).
vec3 closestOnTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  vec3 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  vec3 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  float denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Light reflected towards v from area light i: the exact irradiance of each
// of its triangles through the BRDF, shadowed once for the group
// (areaShadow, towards the irradiance-weighted centre of what p sees of it).
vec3 areaLight(int i, vec3 p, vec3 n, vec3 v, vec3 baseColor, float metallic, float roughness) {
#define L uLights[i]
  const vec3 kLuminance = vec3(0.2126, 0.7152, 0.0722);
  int first = int(L.corner2.x);
  int end = first + int(L.corner2.y);
  float a = loBrdfAlpha(roughness);
  vec3 r = reflect(-v, n);
  vec3 f = vec3(0.0);
  vec3 towards = vec3(0.0);
  for (int k = first; k < end; ++k) {
    vec4 t0 = uAreaTriangles[3 * k], t1 = uAreaTriangles[3 * k + 1], t2 = uAreaTriangles[3 * k + 2];
    vec3 cr = cross(t1.xyz - t0.xyz, t2.xyz - t0.xyz);
    float twiceArea = length(cr);
    vec3 nE = cr / twiceArea;
    // One-sided Lambertian emitter: nothing behind its plane is lit, and a
    // point in the plane (the ceiling around a ceiling light) sees it at
    // grazing incidence: nothing either (the clipped edge sum would be all
    // rounding there).
    float side = sqrt(0.5 * twiceArea);
    if (dot(p - t0.xyz, nE) <= 1e-3 * side) continue;
    vec3 lightCentre;
    float solid = polygonIrradiance(p, n, t0.xyz, t1.xyz, t2.xyz, lightCentre);
    if (solid <= 0.0) continue;
    vec3 radiance = vec3(t0.w, t1.w, t2.w);
    vec3 la = normalize(lightCentre - p);
    towards += la * (solid * dot(radiance, kLuminance));
    // Diffuse: the lobe in the direction of the triangle's visible part
    // times its exact projected solid angle.
    vec3 diffuse, specular;
    loBrdfLobes(n, v, la, baseColor, metallic, a, uTransmission, uDielectric, diffuse, specular);
    if (!uSpecular) diffuse = loBrdfDiffuseOnly(baseColor, metallic, uTransmission);
    vec3 c = diffuse * solid;
    if (uSpecular) {
      // Specular: a representative point (Karis 2013): the point of the
      // triangle nearest the reflected ray, the GGX lobe evaluated towards
      // it with its own alpha and scaled by (alpha / alpha')^2, alpha'
      // widened by the triangle's angular radius: a glossy surface shows
      // the light's shape, not a highlight of the lobe's size at its centre.
      float facing = dot(r, nE);
      vec3 q = lightCentre;
      if (facing < -1e-4) q = p + r * max(dot(t0.xyz - p, nE) / facing, 0.0);
      q = closestOnTriangle(q, t0.xyz, t1.xyz, t2.xyz);
      vec3 ls = normalize(q - p);
      float nls = dot(n, ls);
      if (nls > 0.0) {
        float distance = length(lightCentre - p);
        float radius = side * 0.5641896;  // sqrt(area / pi)
        float wide = clamp(a + radius / (2.0 * distance), a, 1.0);
        vec3 dRep, sRep;
        loBrdfLobes(n, v, ls, baseColor, metallic, a, uTransmission, uDielectric, dRep, sRep);
        float omega = solid / max(dot(n, la), 1e-4);  // the triangle's solid angle
        c += sRep * (a * a / (wide * wide)) * nls * omega;
      }
    }
    f += c * radiance;
  }
  if (dot(towards, towards) <= 0.0) return vec3(0.0);
  return f * areaShadow(i, p, gGeometricNormal, normalize(towards));
#undef L
}

// Light reflected towards v from punctual light or VPL i, shadowed.
vec3 punctualLight(int i, vec3 p, vec3 n, vec3 v, vec3 baseColor, float metallic,
                   float roughness) {
  // The light read in place (a copy of the 7-vec4 struct is dear on llvmpipe).
#define L uLights[i]
  int type = int(L.positionType.w);
  vec3 l;
  vec3 E = L.colorFar.rgb;  // irradiance on a surface facing the light, W/m^2
  if (type == LO_LIGHT_DIRECTIONAL) {
    l = -L.directionRange.xyz;
  } else {
    vec3 tl = L.positionType.xyz - p;
    float dist2 = dot(tl, tl);
    float dist = sqrt(dist2);
    l = tl / dist;
    // Near-field clamp for emitter VPLs: never closer than the patch allows.
    E /= max(dist2, L.params.w);
    float range = L.directionRange.w;
    if (range > 0.0) {
      float r = dist / range;
      E *= pow(clamp(1.0 - r * r * r * r, 0.0, 1.0), 2.0);
    }
    float cd = dot(-l, L.directionRange.xyz);
    if (type == LO_LIGHT_SPOT) {
      // glTF's cone falloff (KHR_lights_punctual), as the tracers apply it
      // (material/bsdf.h spotFalloff): ((cos - cosOuter) / (cosInner - cosOuter))^2.
      float t = clamp((cd - L.params.x) / max(L.params.y - L.params.x, 1e-3), 0.0, 1.0);
      E *= t * t;
    } else if (type == LO_LIGHT_EMITTER) {
      E *= max(cd, 0.0);  // Lambertian emitter patch: intensity falls with the cosine
    }
  }
  if (dot(n, l) <= 0.0 || max(E.r, max(E.g, E.b)) <= 0.0) return vec3(0.0);
  float visible = type == LO_LIGHT_DIRECTIONAL ? sunShadow(i, p, gGeometricNormal, l)
                                                 : shadow(i, p, gGeometricNormal, l);
  return loBrdfCos(n, v, l, baseColor, metallic, roughness, uTransmission, uDielectric, uSpecular) * E *
         visible;
#undef L
}

vec3 direct(vec3 p, vec3 n, vec3 v, vec3 baseColor, float metallic, float roughness) {
  vec3 sum = vec3(0.0);
  // Area lights come last in the block (uLightCount.y of the uLightCount.x):
  // their own loop keeps the other lights' loop small, which llvmpipe runs
  // several times faster.
  for (int i = uLightCount.x - uLightCount.y; i < uLightCount.x; ++i) {
    sum += areaLight(i, p, n, v, baseColor, metallic, roughness);
  }
  for (int i = 0; i < uLightCount.x - uLightCount.y; ++i) {
    sum += punctualLight(i, p, n, v, baseColor, metallic, roughness);
  }
  return sum;
}
