// Shared by all stages of the shell renderer. The renderer prepends
//   #version 330 core
//   #define NODES_PER_ELEMENT  8 (quad8) or 6 (tri6)
//   #define ELEMENT_QUAD8      1 or 0
//   #define MAX_ENRICHMENTS    0..32  enrichment slots per element (0 for the draw of unenriched elements)
//   #define MAX_CUTS_PER_TRIANGLE  min(MAX_ENRICHMENTS, 4) for CUT_GEOMETRY_SHADER, else 0:
//                              enrichments whose cut one tessellation triangle may cross
//   #define CUT_METHOD         0, 1 or 2 (CUT_GEOMETRY_SHADER, CUT_DROP_TRIANGLES, CUT_KILL_PIXELS)
//   #define SMOOTH_SHADING     0 or 1
//   #define WIREFRAME          0 or 1
//   #define GEOMETRY_MAX_VERTICES  3 * 2^MAX_CUTS_PER_TRIANGLE
// and then this file, then the stage's own file (shell.vert / shell.geom / shell.frag).
#define CUT_GEOMETRY_SHADER 0
#define CUT_DROP_TRIANGLES 1
#define CUT_KILL_PIXELS 2

#if MAX_ENRICHMENTS > 0
// Enrichment slot s of the whole state; an element's slots are
// u_element_slots[e * MAX_ENRICHMENTS + k], -1 where unused.
uniform isamplerBuffer u_element_slots;
// Per slot: (atlas layer, tile origin x, tile origin y, resolution T).
uniform isamplerBuffer u_slot_tiles;
// The enrichment textures H, one T x T tile per slot (R32F).
uniform sampler2DArray u_atlas;
// Per slot and local node: q^a (xyz); read by the vertex stage, and by the geometry stage
// to re-evaluate A_k at the vertices of cut triangles.
uniform samplerBuffer u_slot_dofs;

// Texel of the tile containing parameter point xi (twin of dgtex::enrichment_texel).
ivec2 enrichment_texel(int T, vec2 xi) {
#if ELEMENT_QUAD8
  vec2 uv = 0.5 * (xi + 1.0);
#else
  vec2 uv = xi;
#endif
  ivec2 ij = clamp(ivec2(floor(uv * float(T))), ivec2(0), ivec2(T - 1));
#if !ELEMENT_QUAD8
  int excess = ij.x + ij.y - (T - 1);
  if (excess > 0) {
    int back_i = min(ij.x, (excess + 1) / 2);
    ij.x -= back_i;
    ij.y -= excess - back_i;
  }
#endif
  return ij;
}

float enrichment_texel_value(ivec4 tile, ivec2 ij) {
  return texelFetch(u_atlas, ivec3(tile.yz + ij, tile.x), 0).r;
}

float enrichment_value(int slot, vec2 xi) {
  ivec4 tile = texelFetch(u_slot_tiles, slot);
  return enrichment_texel_value(tile, enrichment_texel(tile.w, xi));
}

int element_slot(int element, int k) {
  return texelFetch(u_element_slots, element * MAX_ENRICHMENTS + k).r;
}
#endif

// Quadratic basis, twin of dgtex::kernels::evaluate_shape (same node order).
void shape_functions(vec2 xi, out float N[NODES_PER_ELEMENT]) {
  float r = xi.x, s = xi.y;
#if ELEMENT_QUAD8
  const vec2 corner[4] = vec2[4](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, 1));
  for (int a = 0; a < 4; ++a) {
    float p = r * corner[a].x, q = s * corner[a].y;
    N[a] = 0.25 * (1.0 + p) * (1.0 + q) * (p + q - 1.0);
  }
  N[4] = 0.5 * (1.0 - r * r) * (1.0 - s);
  N[5] = 0.5 * (1.0 - s * s) * (1.0 + r);
  N[6] = 0.5 * (1.0 - r * r) * (1.0 + s);
  N[7] = 0.5 * (1.0 - s * s) * (1.0 - r);
#else
  float l = 1.0 - r - s;
  N[0] = l * (2.0 * l - 1.0);
  N[1] = r * (2.0 * r - 1.0);
  N[2] = s * (2.0 * s - 1.0);
  N[3] = 4.0 * r * l;
  N[4] = 4.0 * r * s;
  N[5] = 4.0 * s * l;
#endif
}
