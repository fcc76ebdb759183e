// The surface a fragment shades: normal maps and colour encodings. Part of
// render_scene.frag.

// The normal map's normal in world space. With the file's TANGENT (vTangent.w
// = +-1) the frame is its tangent and w cross(n, t), turned with the normal
// to the side seen (side = -1 when n was flipped to face the viewer), as the
// glTF sample viewer does. Without it the tangent is the direction of +u on
// the surface, from screen-space derivatives of the position and the UVs,
// and the bitangent cross(n, t), glTF's convention for tangent.w = 1
// (mirrored UVs are not detected). Scene::shadingNormal is the C++ twin.
vec3 perturbNormal(vec3 n, vec3 p, vec2 uv, float side) {
  if (abs(vTangent.w) > 0.5) {
    vec3 n0 = n * side;
    vec3 t0 = vTangent.xyz - n0 * dot(n0, vTangent.xyz);
    if (dot(t0, t0) > 1e-20) {
      t0 = normalize(t0);
      vec3 b0 = cross(n0, t0) * sign(vTangent.w);
      vec3 m = texture(uNormalTexture, uv).rgb * 2.0 - 1.0;
      m.xy *= uNormalScale;
      return normalize((t0 * m.x + b0 * m.y) * side + n * m.z);
    }
  }
  vec3 dpdx = dFdx(p), dpdy = dFdy(p);
  vec2 duvdx = dFdx(uv), duvdy = dFdy(uv);
  float det = duvdx.x * duvdy.y - duvdy.x * duvdx.y;
  if (abs(det) < 1e-20) return n;
  vec3 t = (duvdy.y * dpdx - duvdx.y * dpdy) / det;
  t = t - n * dot(n, t);
  if (dot(t, t) < 1e-20) return n;
  t = normalize(t);
  vec3 b = cross(n, t);
  vec3 m = texture(uNormalTexture, uv).rgb * 2.0 - 1.0;
  m.xy *= uNormalScale;
  return normalize(mat3(t, b, n) * m);
}

vec3 srgbDecode(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

vec3 srgbEncode(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}
