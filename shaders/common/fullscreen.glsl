// The corner of the one triangle that covers the screen, for vertex gl_VertexID of
// drawFullscreenTriangle (3 vertices, no buffers): (0,0), (2,0), (0,2) in uv.
vec2 fullscreenCorner() { return vec2((gl_VertexID << 1) & 2, gl_VertexID & 2); }
