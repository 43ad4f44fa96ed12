// Radiance → display value, shared by composite and tonemap (and so by the reference
// pipeline): one of three curves, then gamma.
const int kTonemapAces = 0, kTonemapReinhard = 1, kTonemapClamp = 2;

vec3 tonemapCurve(vec3 x, int curve) {
    if (curve == kTonemapAces)  // ACES filmic fit (Narkowicz 2015)
        return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    if (curve == kTonemapReinhard) return x / (1.0 + x);
    return clamp(x, 0.0, 1.0);
}

// KILN_GAMMA_FIT 1: x^(1/γ) as u_gammaFit · (s, s², s³, s⁴), s = x^(1/4), fitted on the
// CPU (kiln/gamma_fit.hpp: within 1e-3 of pow where the includer uses it); 0: pow.
#ifndef KILN_GAMMA_FIT
#define KILN_GAMMA_FIT 0
#endif
#if KILN_GAMMA_FIT
uniform vec4 u_gammaFit;
#endif

vec3 displayEncode(vec3 radiance, int curve, float gamma) {
    vec3 x = tonemapCurve(max(radiance, vec3(0.0)), curve);
#if KILN_GAMMA_FIT
    vec3 s = sqrt(sqrt(x));
    return s * (u_gammaFit.x + s * (u_gammaFit.y + s * (u_gammaFit.z + s * u_gammaFit.w)));
#else
    return pow(x, vec3(1.0 / gamma));
#endif
}
