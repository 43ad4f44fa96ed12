// Radiance → display value, shared by composite and tonemap (and so by the reference
// pipeline): one of three curves, then gamma.
const int kTonemapAces = 0, kTonemapReinhard = 1, kTonemapClamp = 2;

vec3 tonemapCurve(vec3 x, int curve) {
    if (curve == kTonemapAces)  // ACES filmic fit (Narkowicz 2015)
        return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    if (curve == kTonemapReinhard) return x / (1.0 + x);
    return clamp(x, 0.0, 1.0);
}

vec3 displayEncode(vec3 radiance, int curve, float gamma) {
    return pow(tonemapCurve(max(radiance, vec3(0.0)), curve), vec3(1.0 / gamma));
}
