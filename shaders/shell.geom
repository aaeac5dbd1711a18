// Geometry stage (thesis Fig. 5.8): a triangle with a cut edge (|h_i - h_j| above
// u_cut_threshold and a sign change of h) is emitted once per side of the cut; on each
// copy the vertices on the other side are extrapolated with that side's value of h (the
// mean over the copy's own vertices), so x = base + h_side * A continues the side's
// displacement field linearly across the cut. The fragment stage then discards what lies
// on the other side. With several cut enrichments, one copy per combination of sides.
layout(triangles) in;
layout(triangle_strip, max_vertices = GEOMETRY_MAX_VERTICES) out;

uniform mat4 u_view_projection;
uniform vec2 u_viewport_size;
uniform float u_cut_threshold;

in VertexData {
  vec2 xi;
  vec3 base;
  vec3 normal;
  flat int element;
#if MAX_ENRICHMENTS > 0
  vec3 A[MAX_ENRICHMENTS];
  float h[MAX_ENRICHMENTS];
#endif
} v[];

out FragmentData {
  vec2 xi;
  vec3 world;
  vec3 normal;
  flat int element;
  flat int side_bits;  // bit k: this copy shows the side h_k >= 0 of enrichment k
  flat int cut_bits;   // bit k: enrichment k cuts this triangle
#if WIREFRAME
  noperspective vec3 edge_distance;  // pixels to the three edges
#endif
} g;

void emit_triangle(vec3 p[3], int side_bits, int cut_bits) {
  vec4 clip[3];
  for (int i = 0; i < 3; ++i) clip[i] = u_view_projection * vec4(p[i], 1.0);
  vec3 face_normal = cross(p[1] - p[0], p[2] - p[0]);
#if WIREFRAME
  vec2 screen[3];
  for (int i = 0; i < 3; ++i) screen[i] = 0.5 * u_viewport_size * clip[i].xy / clip[i].w;
  float twice_area = abs((screen[1].x - screen[0].x) * (screen[2].y - screen[0].y) -
                         (screen[2].x - screen[0].x) * (screen[1].y - screen[0].y));
  float height[3];
  for (int i = 0; i < 3; ++i)
    height[i] = twice_area / max(length(screen[(i + 2) % 3] - screen[(i + 1) % 3]), 1e-6);
#endif
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
    g.edge_distance = vec3(0.0);
    g.edge_distance[i] = height[i];
#endif
    EmitVertex();
  }
  EndPrimitive();
}

void main() {
  int cut_bits = 0;
#if MAX_ENRICHMENTS > 0
  for (int k = 0; k < MAX_ENRICHMENTS; ++k)
    for (int i = 0; i < 3; ++i) {
      float a = v[i].h[k], b = v[(i + 1) % 3].h[k];
      if (abs(a - b) > u_cut_threshold && (a >= 0.0) != (b >= 0.0)) cut_bits |= 1 << k;
    }
#endif
  vec3 p[3];
  if (cut_bits == 0 || CUT_METHOD == CUT_KILL_PIXELS) {
    for (int i = 0; i < 3; ++i) {
      p[i] = v[i].base;
#if MAX_ENRICHMENTS > 0
      for (int k = 0; k < MAX_ENRICHMENTS; ++k) p[i] += v[i].h[k] * v[i].A[k];
#endif
    }
    emit_triangle(p, 0, cut_bits);
    return;
  }
#if MAX_ENRICHMENTS > 0 && CUT_METHOD == CUT_GEOMETRY_SHADER
  // Side values: mean h over the vertices on each side, per enrichment.
  float side_value[2 * MAX_ENRICHMENTS];
  for (int k = 0; k < MAX_ENRICHMENTS; ++k) {
    vec2 sum = vec2(0.0), count = vec2(0.0);
    for (int i = 0; i < 3; ++i) {
      int side = v[i].h[k] >= 0.0 ? 1 : 0;
      sum[side] += v[i].h[k];
      count[side] += 1.0;
    }
    side_value[2 * k] = sum[0] / max(count[0], 1.0);
    side_value[2 * k + 1] = sum[1] / max(count[1], 1.0);
  }
  for (int copy = 0; copy < (1 << MAX_ENRICHMENTS); ++copy) {
    if ((copy & ~cut_bits) != 0) continue;
    for (int i = 0; i < 3; ++i) {
      p[i] = v[i].base;
      for (int k = 0; k < MAX_ENRICHMENTS; ++k) {
        float h = v[i].h[k];
        if ((cut_bits & (1 << k)) != 0) {
          int side = (copy >> k) & 1;
          if ((h >= 0.0 ? 1 : 0) != side) h = side_value[2 * k + side];
        }
        p[i] += h * v[i].A[k];
      }
    }
    emit_triangle(p, copy, cut_bits);
  }
#endif
  // CUT_DROP_TRIANGLES: a cut triangle is not emitted at all.
}
