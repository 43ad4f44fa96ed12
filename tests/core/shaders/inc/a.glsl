// a.glsl includes its sibling by a relative path
#include "b.glsl"
vec3 a() { return b() * 0.5; }
