#version 330 core
// Thick glass (KHR_materials_volume): the nearest back face of the volumes at
// each pixel, where the scene pass's refracted rays leave the glass
// (render_scene.frag, volumeExit): its render-space position, and in w its
// outward normal, octahedral, 10 bits a side, plus 1 (0: no back face; a
// float holds the 20 bits exactly). A face is a back face by its normal
// turned from the eye, not by winding: scene files do not agree on winding
// (the scene pass's rule).
in vec3 vPosition;
in vec3 vNormal;
uniform vec3 uEye;
layout(location = 0) out vec4 backFace;
void main() {
  vec3 n = normalize(vNormal);
  if (dot(n, uEye - vPosition) > 0.0) discard;
  vec2 o = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
  if (n.z < 0.0) o = (1.0 - abs(o.yx)) * vec2(o.x >= 0.0 ? 1.0 : -1.0, o.y >= 0.0 ? 1.0 : -1.0);
  vec2 q = floor(clamp(o * 0.5 + 0.5, 0.0, 1.0) * 1023.0 + 0.5);
  backFace = vec4(vPosition, q.x * 1024.0 + q.y + 1.0);
}
