// back to the first: a cycle
#include "cycle_1.glsl"
