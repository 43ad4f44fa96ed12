#version 450 core
// A progressive path tracer over the analytic scene (reference/shapes.glsl) with the
// rasterizer's materials: Lambert, the instances' albedos, the floor's procedural wood.
// Each dispatch adds u_samples paths per pixel to a running mean.
//   - the placed meshes' triangles through the host's BVH, with their materials (base
//     colour and emissive textures, normal maps, cut-outs, one- and two-sided);
//   - next-event estimation toward the lamp's sphere (uniform in its cone of
//     directions; a direction whose first hit is the ceiling, not the dome, is simply
//     occluded), the fireballs, the punctual lights (a shadow ray each) and the
//     emitting triangles (one by power, a point on it uniformly), one light picked
//     per vertex;
//   - BSDF (cosine) sampling, combined with NEE by the power heuristic for the lights
//     NEE can pick; particles are reached by BSDF sampling only;
//   - Russian roulette from bounce u_rouletteStart on, so no depth bias below
//     u_maxBounces.
// Outputs: radiance = the full estimate; direct = what the rasterizer computes
// directly: emission seen by the camera plus the lamp's light on the first surface.
// Deterministic: every random number is a hash of (pixel, sample index, seed).
layout(local_size_x = 8, local_size_y = 8) in;

#include "common/light.glsl"
#include "common/wood.glsl"
#include "reference/shapes.glsl"

layout(binding = 0, rgba32f) uniform image2D u_radiance;
layout(binding = 1, rgba32f) uniform image2D u_direct;
layout(binding = 2, r32f) uniform image2D u_rays;

uniform uint u_seed;
uniform int u_sampleBase;     // paths already in the mean
uniform int u_samples;        // paths to add now
uniform int u_maxBounces;
uniform int u_rouletteStart;
uniform bool u_jitter;        // pixel-area integration (the rasterizer samples centres)
uniform int u_rowOffset;      // the band of rows this dispatch covers starts here

const float kPi = 3.14159265358979;
const float kEpsilon = 1e-4;

// PCG hash (O'Neill; Jarzynski & Olano 2020): one 32-bit state per path.
uint g_rng;
uint pcg(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
float rand() {
    g_rng = pcg(g_rng);
    return float(g_rng >> 8) * (1.0 / 16777216.0);
}

void basis(vec3 n, out vec3 t, out vec3 b) {  // Duff et al. 2017
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

vec3 cosineSample(vec3 n) {
    float u = rand(), v = rand();
    float r = sqrt(u), phi = 2.0 * kPi * v;
    vec3 t, b;
    basis(n, t, b);
    return normalize(t * (r * cos(phi)) + b * (r * sin(phi)) + n * sqrt(max(0.0, 1.0 - u)));
}

vec3 albedoAt(int instance, vec3 p) {
    vec4 a = kiln_instances[instance].albedo;
    return a.a > 0.5 ? woodGrain(p) : a.rgb;
}
vec3 emissionOf(int instance) { return kiln_instances[instance].emissive.rgb; }

// What a path needs of the surface it hit: the material's albedo and emission there, the
// shading normal and the geometric one, both facing the ray's origin.
struct Surface {
    vec3 albedo;
    vec3 emission;
    vec3 normal;
    vec3 geometric;
};
Surface surfaceAt(Hit h, vec3 p, vec3 d) {
    Surface s;
    if (!h.onMesh) {
        s.normal = s.geometric = dot(h.normal, d) > 0.0 ? -h.normal : h.normal;  // two-sided walls
        s.albedo = albedoAt(h.instance, p);
        s.emission = emissionOf(h.instance);
        return s;
    }
    // A placed mesh: the G-buffer's material (gbuffer/textured.frag), read at the finest level.
    KilnMeshSurface m = kilnMeshSurface(h.mesh);
    KilnInstance inst = kiln_instances[m.instance];
    vec4 base = inst.baseColor;
    vec3 emission = inst.emission.rgb;
    if (inst.layers.x >= 0.0) base *= textureLod(kiln_rayColorLayers, vec3(m.uv, inst.layers.x), 0.0);
    if (inst.layers.y >= 0.0) emission *= textureLod(kiln_rayColorLayers, vec3(m.uv, inst.layers.y), 0.0).rgb;
    bool back = dot(m.geometricNormal, d) > 0.0;
    s.geometric = back ? -m.geometricNormal : m.geometricNormal;
    vec3 n = back ? -m.normal : m.normal;
    if (inst.layers.z >= 0.0) {
        vec3 t = m.tangent.xyz - n * dot(n, m.tangent.xyz);
        if (dot(t, t) > 1e-12) {
            vec3 mapped = textureLod(kiln_rayDataLayers, vec3(m.uv, inst.layers.z), 0.0).xyz * 2.0 - 1.0;
            t = normalize(t);
            vec3 b = cross(n, t) * (m.tangent.w < 0.0 ? -1.0 : 1.0);
            n = normalize(mapped.x * t + mapped.y * b + mapped.z * n);
        }
    }
    s.normal = n;
    s.albedo = base.rgb;
    s.emission = emission;
    return s;
}

// Lights NEE samples: 0 = the lamp, 1..F = fireball F−1 (the spheres), then the punctual
// lights. Probability of each.
int sphereLightCount() { return (u_count[kLamp] > 0 ? 1 : 0) + u_count[kFireballs]; }
int lightCount() { return sphereLightCount() + int(u_punctualCount.x) + (u_rayEmitterCount > 0u ? 1 : 0); }
bool isEmitterLight(int k) { return u_rayEmitterCount > 0u && k == lightCount() - 1; }
float lightPick() { return 1.0 / float(max(lightCount(), 1)); }
void lightSphere(int k, out vec3 c, out float r, out int instance) {
    if (u_count[kLamp] > 0 && k == 0) {
        c = u_lightPos.xyz, r = u_lightPos.w, instance = u_first[kLamp];
        return;
    }
    instance = u_first[kFireballs] + k - (u_count[kLamp] > 0 ? 1 : 0);
    mat4 m = kiln_instances[instance].model;
    c = m[3].xyz, r = length(m[0].xyz);
}
bool isNeeLight(int instance) {
    return (instance == u_first[kLamp] && u_count[kLamp] > 0) ||
           (instance >= u_first[kFireballs] && instance < u_first[kFireballs] + u_count[kFireballs]);
}
// Solid angle density of uniform cone sampling toward the sphere (c, r) from p.
float coneDensity(vec3 p, vec3 c, float r) {
    float d2 = dot(c - p, c - p);
    if (d2 <= r * r) return 0.0;
    float cosMax = sqrt(1.0 - r * r / d2);
    return 1.0 / (2.0 * kPi * (1.0 - cosMax));
}
float powerHeuristic(float a, float b) { return a * a / (a * a + b * b); }

// A punctual light seen from p (common/punctual.glsl's radiometry, its visibility by a
// shadow ray): the unit direction to it, how far it is (directional: unbounded) and the
// irradiance it gives a surface facing it.
void punctualToward(KilnPunctualLight light, vec3 p, out vec3 l, out float dist, out vec3 irradiance) {
    l = -light.direction.xyz;
    dist = kNoHit;
    float falloff = 1.0;
    if (light.position.w > 0.5) {
        vec3 toLight = light.position.xyz - p;
        float dist2 = max(dot(toLight, toLight), 1e-8);
        dist = sqrt(dist2);
        l = toLight / dist;
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
    irradiance = light.color.rgb * falloff;
}

// Where a ray leaving a mesh's surface starts: off it along the geometric normal by a
// margin that grows with the distance from the origin (float spacing), so it does not
// hit the triangle it left. The analytic shapes keep the ray's own tMin.
vec3 leaving(Hit h, vec3 p, vec3 geometric) {
    if (!h.onMesh) return p;
    float scale = max(max(abs(p.x), abs(p.y)), max(abs(p.z), 1.0));
    return p + geometric * (2e-5 * scale);
}

void tracePath(vec3 o, vec3 d, out vec3 total, out vec3 direct) {
    total = vec3(0.0), direct = vec3(0.0);
    vec3 throughput = vec3(1.0);
    float bsdfPdf = 0.0;      // of the direction that led here (0: camera ray)
    vec3 previous = o;
    for (int depth = 0; depth <= u_maxBounces; ++depth) {
        Hit h = traceScene(o, d, depth == 0 ? 0.0 : kEpsilon);
        if (h.instance < 0) break;
        vec3 p = o + h.t * d;
        Surface surface = surfaceAt(h, p, d);
        vec3 n = surface.normal;
        vec3 e = surface.emission;
        if (any(greaterThan(e, vec3(0.0)))) {
            float w = 1.0;
            if (depth > 0 && isNeeLight(h.instance)) {
                vec3 c = h.instance == u_first[kLamp] ? u_lightPos.xyz : kiln_instances[h.instance].model[3].xyz;
                float r = h.instance == u_first[kLamp] ? u_lightPos.w : length(kiln_instances[h.instance].model[0].xyz);
                w = powerHeuristic(bsdfPdf, lightPick() * coneDensity(previous, c, r));
            } else if (depth > 0 && h.onMesh && u_rayEmitterCount > 0u) {
                // An emitting triangle next-event estimation could have picked: its
                // density per solid angle from where the path came.
                float cosLight = abs(dot(surface.geometric, d));
                float density = kilnEmitterDensity(uint(h.instance));
                if (density > 0.0 && cosLight > 0.0)
                    w = powerHeuristic(bsdfPdf, lightPick() * density * h.t * h.t / cosLight);
            }
            vec3 contribution = throughput * e * w;
            total += contribution;
            if (depth == 0 || (depth == 1 && h.instance == u_first[kLamp] && u_count[kLamp] > 0)) direct += contribution;
        }
        vec3 albedo = surface.albedo;
        if (all(equal(albedo, vec3(0.0))) || depth == u_maxBounces) break;
        vec3 start = leaving(h, p, surface.geometric);

        // Next-event estimation: one light, a direction toward it, one shadow ray.
        int lights = lightCount();
        if (lights > 0) {
            int k = min(int(rand() * float(lights)), lights - 1);
            float u = rand(), v = rand();
            if (isEmitterLight(k)) {
                KilnEmitterSample es = kilnSampleEmitter(u, v, rand());
                vec3 toLight = es.position - start;
                float dist2 = dot(toLight, toLight);
                vec3 l = toLight * inversesqrt(max(dist2, 1e-20));
                float cosLight = abs(dot(es.normal, l));
                float cosSurface = dot(n, l);
                if (cosSurface > 0.0 && dot(surface.geometric, l) > 0.0 && cosLight > 1e-6 && es.areaDensity > 0.0) {
                    Hit s = traceScene(start, l, kEpsilon);
                    if (s.onMesh && s.mesh.rayInstance == es.hit.rayInstance && s.mesh.triangle == es.hit.triangle) {
                        vec3 emitted = surfaceAt(s, start + s.t * l, l).emission;
                        float lightPdf = lightPick() * es.areaDensity * dist2 / cosLight;
                        float w = powerHeuristic(lightPdf, cosSurface / kPi);
                        total += throughput * albedo / kPi * emitted * cosSurface * w / lightPdf;
                    }
                }
            } else if (k < sphereLightCount()) {
                vec3 c;
                float r;
                int instance;
                lightSphere(k, c, r, instance);
                float density = coneDensity(p, c, r);
                if (density > 0.0) {
                    vec3 axis = normalize(c - p);
                    float cosMax = sqrt(1.0 - r * r / dot(c - p, c - p));
                    float cosT = 1.0 - u * (1.0 - cosMax), sinT = sqrt(max(0.0, 1.0 - cosT * cosT));
                    vec3 t, b;
                    basis(axis, t, b);
                    vec3 l = normalize(t * (sinT * cos(2.0 * kPi * v)) + b * (sinT * sin(2.0 * kPi * v)) + axis * cosT);
                    float cosSurface = dot(n, l);
                    if (cosSurface > 0.0 && dot(surface.geometric, l) > 0.0) {
                        Hit s = traceScene(start, l, kEpsilon);
                        if (s.instance == instance) {
                            float lightPdf = lightPick() * density;
                            float w = powerHeuristic(lightPdf, cosSurface / kPi);
                            vec3 contribution = throughput * albedo / kPi * emissionOf(instance) * cosSurface * w / lightPdf;
                            total += contribution;
                            if (depth == 0 && k == 0 && u_count[kLamp] > 0) direct += contribution;
                        }
                    }
                }
            } else {
                vec3 l, irradiance;
                float dist;
                punctualToward(u_punctual[k - sphereLightCount()], p, l, dist, irradiance);
                float cosSurface = dot(n, l);
                if (cosSurface > 0.0 && dot(surface.geometric, l) > 0.0 && any(greaterThan(irradiance, vec3(0.0)))) {
                    Hit s = traceScene(start, l, kEpsilon);
                    if (s.instance < 0 || s.t >= dist) {
                        vec3 contribution = throughput * albedo / kPi * irradiance * cosSurface / lightPick();
                        total += contribution;
                        if (depth == 0) direct += contribution;
                    }
                }
            }
        }

        // Continue: cosine sampling makes the Lambert weight exactly the albedo. A
        // direction below the true surface (a shading normal tilted past it) ends the path.
        vec3 next = cosineSample(n);
        if (h.onMesh && dot(next, surface.geometric) <= 0.0) break;
        bsdfPdf = max(dot(n, next), 0.0) / kPi;
        throughput *= albedo;
        if (depth >= u_rouletteStart) {
            float keep = clamp(max(throughput.r, max(throughput.g, throughput.b)), 0.05, 1.0);
            if (rand() >= keep) break;
            throughput /= keep;
        }
        previous = p;
        o = start;
        d = next;
    }
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, u_rowOffset);
    ivec2 size = imageSize(u_radiance);
    if (any(greaterThanEqual(pixel, size))) return;
    vec3 sumTotal = vec3(0.0), sumDirect = vec3(0.0);
    for (int s = 0; s < u_samples; ++s) {
        uint index = uint(u_sampleBase + s);
        g_rng = pcg(uint(pixel.x) ^ pcg(uint(pixel.y) ^ pcg(index ^ pcg(u_seed))));
        vec2 offset = u_jitter ? vec2(rand(), rand()) : vec2(0.5);
        vec2 ndc = (vec2(pixel) + offset) / vec2(size) * 2.0 - 1.0;
        vec4 nearPoint = u_invViewProj * vec4(ndc, -1.0, 1.0);
        vec4 farPoint = u_invViewProj * vec4(ndc, 1.0, 1.0);
        vec3 o = nearPoint.xyz / nearPoint.w;
        vec3 d = normalize(farPoint.xyz / farPoint.w - o);
        vec3 total, direct;
        tracePath(o, d, total, direct);
        sumTotal += total;
        sumDirect += direct;
    }
    // Running mean; alpha carries the sample count.
    float before = float(u_sampleBase), after = float(u_sampleBase + u_samples);
    vec4 meanTotal = u_sampleBase == 0 ? vec4(0.0) : imageLoad(u_radiance, pixel);
    vec4 meanDirect = u_sampleBase == 0 ? vec4(0.0) : imageLoad(u_direct, pixel);
    imageStore(u_radiance, pixel, vec4((meanTotal.rgb * before + sumTotal) / after, after));
    imageStore(u_direct, pixel, vec4((meanDirect.rgb * before + sumDirect) / after, after));
    float raysBefore = u_sampleBase == 0 ? 0.0 : imageLoad(u_rays, pixel).r;
    imageStore(u_rays, pixel, vec4(raysBefore + float(g_rays)));
}
