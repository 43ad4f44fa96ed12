// The punctual lights' diffuse irradiance (GpuFrame::punctual, glTF KHR_lights_punctual):
// inverse-square falloff with the range window and the spot cone as KHR_lights_punctual
// gives them, each of the first shadowed lights tested against its tile of the `lights`
// pass's shadow atlas (2×2 bilinear depth tests, taken a texel and a half off the
// surface along its normal). Needs common/frame.glsl; the atlas is bound at unit 11 and
// read only where the input KILN_HAS_LIGHT_SHADOWS says it is.
layout(binding = 11) uniform sampler2D u_lightShadows;

float punctualVisibility(KilnPunctualLight light, vec3 p, vec3 n) {
#if KILN_HAS_LIGHT_SHADOWS
    if (light.color.w < 0.0) return 1.0;
    ivec2 size = textureSize(u_lightShadows, 0);
    int side = size.y;
    // A texel's footprint at p: 2·w / (side · the clip x scale), orthographic or perspective.
    vec4 c0 = light.shadowViewProj * vec4(p, 1.0);
    float xScale = length(vec3(light.shadowViewProj[0][0], light.shadowViewProj[1][0], light.shadowViewProj[2][0]));
    float texelWorld = 2.0 * abs(c0.w) / (float(side) * max(xScale, 1e-12));
    vec4 c = light.shadowViewProj * vec4(p + n * (1.5 * texelWorld), 1.0);
    if (c.w <= 0.0) return 1.0;
    vec3 ndc = c.xyz / c.w;
    if (any(greaterThan(abs(ndc.xy), vec2(1.0))) || ndc.z > 1.0) return 1.0;  // outside its view: lit
    float depth = ndc.z * 0.5 + 0.5;
    int x0 = int(light.color.w) * side;
    vec2 texel = (ndc.xy * 0.5 + 0.5) * float(side) - 0.5;
    ivec2 base = ivec2(floor(texel));
    vec2 f = texel - vec2(base);
    float s[4];
    for (int k = 0; k < 4; ++k) {
        ivec2 q = clamp(base + ivec2(k & 1, k >> 1), ivec2(0), ivec2(side - 1));
        s[k] = depth <= texelFetch(u_lightShadows, ivec2(x0 + q.x, q.y), 0).r ? 1.0 : 0.0;
    }
    return mix(mix(s[0], s[1], f.x), mix(s[2], s[3], f.x), f.y);
#else
    return 1.0;
#endif
}

vec3 punctualIrradiance(vec3 p, vec3 n) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < int(u_punctualCount.x); ++i) {
        KilnPunctualLight light = u_punctual[i];
        vec3 l = -light.direction.xyz;
        float falloff = 1.0;
        if (light.position.w > 0.5) {  // point or spot
            vec3 d = light.position.xyz - p;
            float dist2 = max(dot(d, d), 1e-8);
            l = d * inversesqrt(dist2);
            falloff = 1.0 / dist2;
            if (light.direction.w > 0.0) {
                float r2 = dist2 / (light.direction.w * light.direction.w);
                float window = clamp(1.0 - r2 * r2, 0.0, 1.0);
                falloff *= window * window;
            }
            if (light.position.w > 1.5) {
                float t = clamp((dot(-l, light.direction.xyz) - light.cone.x) * light.cone.y, 0.0, 1.0);
                falloff *= t * t;
            }
        }
        float nl = dot(n, l);
        if (nl > 0.0 && falloff > 0.0) sum += light.color.rgb * (falloff * nl) * punctualVisibility(light, p, n);
    }
    return sum;
}
