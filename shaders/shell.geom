// Geometry stage (thesis Fig. 5.8): a triangle with a cut edge (|h_i - h_j| above
// u_cut_threshold and a sign change of h) is emitted once per side of the cut; on each
// copy the vertices on the other side are extrapolated with that side's value of h, so
// x = base + h_side * A continues the side's displacement field across the cut. h_side
// of a vertex is the value of the nearest texel on that side (other_side_value): a
// function of the vertex alone, so neighbouring cut triangles move a shared vertex to the
// same place (no cracks between their copies where h varies along a side), and where h
// changes sign without a cut (behind a partial cut's tip) the copies meet near h = 0.
// The fragment stage then discards what lies on the other side.
//
// The element's enrichment slots are looped over here (not carried as varyings): only
// slots whose sign differs between the vertices (sign_bits from the vertex stage) are
// tested for a cut. With several cutting enrichments, one copy per combination of their
// sides, the others keep each vertex's own value. A triangle crossed by more than
// MAX_CUTS_PER_TRIANGLE cuts is not drawn (a hole of one tessellation triangle where that
// many cuts meet; a finer tessellation separates them).
layout(triangles) in;
layout(triangle_strip, max_vertices = GEOMETRY_MAX_VERTICES) out;

uniform mat4 u_view_projection;
uniform float u_cut_threshold;
#if MAX_ENRICHMENTS > 0 && CUT_METHOD == CUT_GEOMETRY_SHADER
uniform int u_tessellation;  // subdivisions per element edge
#endif

in VertexData {
  vec2 xi;
  vec3 base;
  vec3 position;
  vec3 normal;
  flat int element;
#if MAX_ENRICHMENTS > 0
  flat uint sign_bits;
#endif
} v[];

out FragmentData {
  vec2 xi;
  vec3 world;
  vec3 normal;
  flat int element;
  flat uint side_bits;  // bit k: this copy shows the side h_k >= 0 of enrichment slot k
  flat uint cut_bits;   // bit k: enrichment slot k cuts this triangle
#if WIREFRAME
  // Barycentric coordinates: the fragment stage reads its distance to each edge in pixels
  // from their screen derivatives. (Heights computed here from the projected corners, and
  // interpolated noperspective, painted triangles the viewport clipped solid red.)
  vec3 barycentric;
#endif
} g;

void emit_triangle(vec3 p[3], uint side_bits, uint cut_bits) {
  vec4 clip[3];
  for (int i = 0; i < 3; ++i) clip[i] = u_view_projection * vec4(p[i], 1.0);
  vec3 face_normal = cross(p[1] - p[0], p[2] - p[0]);
  for (int i = 0; i < 3; ++i) {
    gl_Position = clip[i];
    g.xi = v[i].xi;
    g.world = p[i];
#if SMOOTH_SHADING
    g.normal = v[i].normal;
#else
    g.normal = face_normal;
#endif
    g.element = v[i].element;
    g.side_bits = side_bits;
    g.cut_bits = cut_bits;
#if WIREFRAME
    g.barycentric = vec3(0.0);
    g.barycentric[i] = 1.0;
#endif
    EmitVertex();
  }
  EndPrimitive();
}

#if MAX_ENRICHMENTS > 0 && CUT_METHOD == CUT_GEOMETRY_SHADER
bool valid_texel(int T, ivec2 ij) {
#if ELEMENT_QUAD8
  return all(greaterThanEqual(ij, ivec2(0))) && all(lessThan(ij, ivec2(T)));
#else
  return all(greaterThanEqual(ij, ivec2(0))) && ij.x + ij.y <= T - 1;
#endif
}

// The value of the texel nearest to parameter point xi (Euclidean distance to texel
// centres, ties to the first found) whose sign differs from `value`; `value` itself if
// none lies within the search radius. The radius covers the longest edge of a
// tessellation triangle (sqrt(2) T / tessellation texels), so a cut triangle always finds
// the other side: depends on the vertex only, never on the triangle.
float other_side_value(int slot, vec2 xi, float value) {
  ivec4 tile = texelFetch(u_slot_tiles, slot);
  int T = tile.w;
#if ELEMENT_QUAD8
  vec2 p = 0.5 * (xi + 1.0) * float(T);
#else
  vec2 p = xi * float(T);
#endif
  ivec2 c = enrichment_texel(T, xi);
  int radius = min(int(ceil(1.4143 * float(T) / float(u_tessellation))) + 1, T);
  bool positive = value >= 0.0;
  float best_d2 = 1e30, best = value;
  for (int r = 1; r <= radius; ++r) {
    // Texel centres of ring r lie at least r - 0.5 from p (p lies in texel c or on its border).
    float reach = float(r) - 0.5;
    if (reach * reach > best_d2) break;
    for (int t = -r; t <= r; ++t) {
      ivec2 candidates[4] = ivec2[4](c + ivec2(t, -r), c + ivec2(t, r), c + ivec2(-r, t), c + ivec2(r, t));
      for (int n = 0; n < 4; ++n) {
        if (n >= 2 && abs(t) == r) continue;  // corners come with the rows
        ivec2 ij = candidates[n];
        if (!valid_texel(T, ij)) continue;
        float h = enrichment_texel_value(tile, ij);
        if ((h >= 0.0) == positive) continue;
        vec2 d = vec2(ij) + 0.5 - p;
        float d2 = dot(d, d);
        if (d2 < best_d2) {
          best_d2 = d2;
          best = h;
        }
      }
    }
  }
  return best;
}
#endif

#if MAX_ENRICHMENTS > 0
// Bit k set where enrichment slot k cuts the triangle: an edge with a sign change and a
// jump above u_cut_threshold.
uint cut_slots(int element) {
  uint changed = (v[0].sign_bits ^ v[1].sign_bits) | (v[1].sign_bits ^ v[2].sign_bits);
  uint cut_bits = 0u;
  for (int k = 0; k < MAX_ENRICHMENTS && changed != 0u; ++k) {
    uint bit = 1u << uint(k);
    if ((changed & bit) == 0u) continue;
    changed &= ~bit;
    int slot = element_slot(element, k);
    float h[3];
    for (int i = 0; i < 3; ++i) h[i] = enrichment_value(slot, v[i].xi);
    for (int i = 0; i < 3; ++i) {
      float a = h[i], b = h[(i + 1) % 3];
      if (abs(a - b) > u_cut_threshold && (a >= 0.0) != (b >= 0.0)) cut_bits |= bit;
    }
  }
  return cut_bits;
}
#endif

void main() {
  uint cut_bits = 0u;
#if MAX_ENRICHMENTS > 0
  cut_bits = cut_slots(v[0].element);
#endif
  vec3 p[3];
  if (cut_bits == 0u || CUT_METHOD == CUT_KILL_PIXELS) {
    for (int i = 0; i < 3; ++i) p[i] = v[i].position;
    emit_triangle(p, 0u, cut_bits);
    return;
  }
#if MAX_ENRICHMENTS > 0 && CUT_METHOD == CUT_GEOMETRY_SHADER
  // The cutting slots, ascending; copy c shows side (c >> j) & 1 of cut j.
  int cut_slot[MAX_CUTS_PER_TRIANGLE];
  int cuts = 0;
  for (int k = 0; k < MAX_ENRICHMENTS; ++k) {
    if ((cut_bits & (1u << uint(k))) == 0u) continue;
    if (cuts == MAX_CUTS_PER_TRIANGLE) return;  // too many cuts meet here: drop the triangle
    cut_slot[cuts++] = k;
  }
  int copies = 1 << cuts;
  int element = v[0].element;
  // x of every copy's vertices: base + sum_k h_k A_k in slot order (as the vertex stage
  // sums), h_k the vertex's own value, or for a cutting slot the copy's side's value.
  vec3 x[3 * (1 << MAX_CUTS_PER_TRIANGLE)];
  for (int i = 0; i < 3; ++i) {
    float N[NODES_PER_ELEMENT];
    shape_functions(v[i].xi, N);
    for (int c = 0; c < copies; ++c) x[3 * c + i] = v[i].base;
    int j = 0;  // next cutting slot
    for (int k = 0; k < MAX_ENRICHMENTS; ++k) {
      int slot = element_slot(element, k);
      if (slot < 0) break;
      vec3 A = vec3(0.0);
      for (int a = 0; a < NODES_PER_ELEMENT; ++a) A += N[a] * texelFetch(u_slot_dofs, slot * NODES_PER_ELEMENT + a).xyz;
      float h = enrichment_value(slot, v[i].xi);
      if (j < cuts && cut_slot[j] == k) {
        float other = other_side_value(slot, v[i].xi, h);
        int own_side = h >= 0.0 ? 1 : 0;
        for (int c = 0; c < copies; ++c) x[3 * c + i] += (((c >> j) & 1) == own_side ? h : other) * A;
        ++j;
      } else {
        for (int c = 0; c < copies; ++c) x[3 * c + i] += h * A;
      }
    }
  }
  for (int c = 0; c < copies; ++c) {
    uint side_bits = 0u;
    for (int j = 0; j < cuts; ++j)
      if (((c >> j) & 1) != 0) side_bits |= 1u << uint(cut_slot[j]);
    for (int i = 0; i < 3; ++i) p[i] = x[3 * c + i];
    emit_triangle(p, side_bits, cut_bits);
  }
#endif
  // CUT_DROP_TRIANGLES: a cut triangle is not emitted at all.
}
