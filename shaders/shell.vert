// Vertex stage: one vertex of the static tessellation (parameter point a_xi) of the
// element drawn as instance gl_InstanceID. Evaluates the deformed position split as x = base + sum_k h_k A_k
// (see dgtex/deformed_shell.h) so the geometry stage can move vertices to either side
// of a cut.
layout(location = 0) in vec2 a_xi;

uniform isamplerBuffer u_instance_elements;  // element of each instance, from u_first_instance on
uniform int u_first_instance;
uniform samplerBuffer u_rest_positions;  // #nodes: X (xyz)
uniform samplerBuffer u_displacements;   // #nodes: u (xyz)
uniform isamplerBuffer u_element_nodes;  // #elements * NODES_PER_ELEMENT
#if SMOOTH_SHADING
uniform samplerBuffer u_node_normals;    // #nodes: normals averaged at nodes
#endif
#if MAX_ENRICHMENTS > 0
uniform samplerBuffer u_slot_node_values;  // #slots * NODES_PER_ELEMENT: H(xi^a)
uniform samplerBuffer u_slot_dofs;         // #slots * NODES_PER_ELEMENT: q^a (xyz)
#endif

out VertexData {
  vec2 xi;
  vec3 base;
  vec3 normal;
  flat int element;
#if MAX_ENRICHMENTS > 0
  vec3 A[MAX_ENRICHMENTS];
  float h[MAX_ENRICHMENTS];
#endif
} v;

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

void main() {
  int e = texelFetch(u_instance_elements, u_first_instance + gl_InstanceID).r;
  float N[NODES_PER_ELEMENT];
  shape_functions(a_xi, N);
  vec3 base = vec3(0.0);
  vec3 normal = vec3(0.0);
  for (int a = 0; a < NODES_PER_ELEMENT; ++a) {
    int node = texelFetch(u_element_nodes, e * NODES_PER_ELEMENT + a).r;
    base += N[a] * (texelFetch(u_rest_positions, node).xyz + texelFetch(u_displacements, node).xyz);
#if SMOOTH_SHADING
    normal += N[a] * texelFetch(u_node_normals, node).xyz;
#endif
  }
#if MAX_ENRICHMENTS > 0
  for (int k = 0; k < MAX_ENRICHMENTS; ++k) {
    v.A[k] = vec3(0.0);
    v.h[k] = 0.0;
    int slot = element_slot(e, k);
    if (slot < 0) continue;
    for (int a = 0; a < NODES_PER_ELEMENT; ++a) {
      vec3 q = texelFetch(u_slot_dofs, slot * NODES_PER_ELEMENT + a).xyz;
      float node_value = texelFetch(u_slot_node_values, slot * NODES_PER_ELEMENT + a).r;
      v.A[k] += N[a] * q;
      base -= N[a] * node_value * q;
    }
    v.h[k] = enrichment_value(slot, a_xi);
  }
#endif
  v.xi = a_xi;
  v.base = base;
  v.normal = normal;
  v.element = e;
}
