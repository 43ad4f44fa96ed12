#include "cycle_2.glsl"
