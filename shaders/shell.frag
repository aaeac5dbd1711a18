// Fragment stage: keeps a fragment of a duplicated cut triangle only where the texel of
// every cutting enrichment's texture lies on the copy's side (texel-resolution cut
// boundary), then shades it with a headlight (two-sided).
uniform vec3 u_camera_position;
uniform vec3 u_surface_color;  // smooth shading
#if CUT_METHOD == CUT_KILL_PIXELS
uniform int u_kill_radius;     // texels
#endif

in FragmentData {
  vec2 xi;
  vec3 world;
  vec3 normal;
  flat int element;
  flat uint side_bits;
  flat uint cut_bits;
#if WIREFRAME
  vec3 barycentric;
#endif
} g;

out vec4 out_color;

// A distinct colour per element (hashed hue), so flat shading shows the elements.
vec3 element_color(int element) {
  uint x = uint(element) * 2654435761u;
  x ^= x >> 15;
  x *= 2246822519u;
  x ^= x >> 13;
  float hue = float(x & 0xFFFFu) / 65536.0;
  vec3 rgb = clamp(abs(mod(hue * 6.0 + vec3(0.0, 4.0, 2.0), 6.0) - 3.0) - 1.0, 0.0, 1.0);
  return mix(vec3(1.0), rgb, 0.55) * 0.9;
}

#if MAX_ENRICHMENTS > 0 && CUT_METHOD == CUT_KILL_PIXELS
// Whether a texel within u_kill_radius of the fragment's texel lies on the other side.
bool near_cut(int slot, vec2 xi) {
  ivec4 tile = texelFetch(u_slot_tiles, slot);
  ivec2 ij = enrichment_texel(tile.w, xi);
  bool positive = enrichment_texel_value(tile, ij) >= 0.0;
  for (int dj = -u_kill_radius; dj <= u_kill_radius; ++dj)
    for (int di = -u_kill_radius; di <= u_kill_radius; ++di) {
      ivec2 n = clamp(ij + ivec2(di, dj), ivec2(0), ivec2(tile.w - 1));
      if ((enrichment_texel_value(tile, n) >= 0.0) != positive) return true;
    }
  return false;
}
#endif

void main() {
#if MAX_ENRICHMENTS > 0
  if (g.cut_bits != 0u) {
    uint remaining = g.cut_bits;
    for (int k = 0; k < MAX_ENRICHMENTS && remaining != 0u; ++k) {
      uint bit = 1u << uint(k);
      if ((remaining & bit) == 0u) continue;
      remaining &= ~bit;
      int slot = element_slot(g.element, k);
#if CUT_METHOD == CUT_KILL_PIXELS
      if (near_cut(slot, g.xi)) discard;
#else
      int side = enrichment_value(slot, g.xi) >= 0.0 ? 1 : 0;
      if (side != ((g.side_bits & bit) != 0u ? 1 : 0)) discard;
#endif
    }
  }
#endif
  vec3 to_eye = normalize(u_camera_position - g.world);
  vec3 n = g.normal;
  float len = length(n);
  n = len > 0.0 ? n / len : to_eye;
  float diffuse = abs(dot(n, to_eye));
#if SMOOTH_SHADING
  vec3 base_color = u_surface_color;
#else
  vec3 base_color = element_color(g.element);
#endif
  vec3 color = base_color * (0.3 + 0.7 * diffuse);
#if WIREFRAME
  // Pixels to the nearest edge: each barycentric coordinate over its screen gradient.
  vec3 gradient = sqrt(dFdx(g.barycentric) * dFdx(g.barycentric) + dFdy(g.barycentric) * dFdy(g.barycentric));
  vec3 pixels = g.barycentric / max(gradient, vec3(1e-9));
  float d = min(pixels.x, min(pixels.y, pixels.z));
  color = mix(vec3(0.85, 0.05, 0.05), color, clamp(d - 0.5, 0.0, 1.0));
#endif
  out_color = vec4(color, 1.0);
}
