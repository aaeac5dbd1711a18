// Shared by all stages of the shell renderer. The renderer prepends
//   #version 330 core
//   #define NODES_PER_ELEMENT  8 (quad8) or 6 (tri6)
//   #define ELEMENT_QUAD8      1 or 0
//   #define MAX_ENRICHMENTS    0..4   enrichment slots per element (0 for the draw of unenriched elements)
//   #define CUT_METHOD         0, 1 or 2 (CUT_GEOMETRY_SHADER, CUT_DROP_TRIANGLES, CUT_KILL_PIXELS)
//   #define SMOOTH_SHADING     0 or 1
//   #define WIREFRAME          0 or 1
//   #define GEOMETRY_MAX_VERTICES  3 * 2^MAX_ENRICHMENTS for CUT_GEOMETRY_SHADER, else 3
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
