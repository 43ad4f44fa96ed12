// Luminance of linear Rec. 709 / sRGB-primaries radiance (the Y of CIE XYZ): how bright a
// colour looks, for thresholds, error scales and choosing among lights.
float kilnLuminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
