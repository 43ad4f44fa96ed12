vec3 b() { return vec3(1.0); }
