// Vertex stage: one vertex of the static tessellation (parameter point a_xi) of the
// element drawn as instance gl_InstanceID. Evaluates the deformed position split as
// x = base + sum_k h_k A_k (see dgtex/deformed_shell.h) and passes on base and x with the
// vertex's own values h_k = H_k(xi); the geometry stage re-evaluates A_k only for the
// (rare) triangles a cut crosses, so the varyings do not grow with the enrichment count.
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
#endif

out VertexData {
  vec2 xi;
  vec3 base;      // x without the enrichments' h_k A_k terms
  vec3 position;  // x with the vertex's own values h_k
  vec3 normal;
  flat int element;
#if MAX_ENRICHMENTS > 0
  flat uint sign_bits;  // bit k: h_k >= 0 (the geometry stage tests only slots whose sign changes)
#endif
} v;

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
  vec3 position = base;
#if MAX_ENRICHMENTS > 0
  // An element's slots are packed from k = 0; the first unused one ends the list.
  vec3 A[MAX_ENRICHMENTS];
  float h[MAX_ENRICHMENTS];
  uint sign_bits = 0u;
  int count = 0;
  for (int k = 0; k < MAX_ENRICHMENTS; ++k) {
    int slot = element_slot(e, k);
    if (slot < 0) break;
    A[k] = vec3(0.0);
    for (int a = 0; a < NODES_PER_ELEMENT; ++a) {
      vec3 q = texelFetch(u_slot_dofs, slot * NODES_PER_ELEMENT + a).xyz;
      float node_value = texelFetch(u_slot_node_values, slot * NODES_PER_ELEMENT + a).r;
      A[k] += N[a] * q;
      base -= N[a] * node_value * q;
    }
    h[k] = enrichment_value(slot, a_xi);
    if (h[k] >= 0.0) sign_bits |= 1u << uint(k);
    count = k + 1;
  }
  // Summed after base is complete, in slot order: the geometry stage's copies of cut
  // triangles repeat exactly these operations.
  position = base;
  for (int k = 0; k < count; ++k) position += h[k] * A[k];
  v.sign_bits = sign_bits;
#endif
  v.xi = a_xi;
  v.base = base;
  v.position = position;
  v.normal = normal;
  v.element = e;
}
