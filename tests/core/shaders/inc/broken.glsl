// line 1
// line 2
vec3 broken() {
    return undefined_symbol;
}
