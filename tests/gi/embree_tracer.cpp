#include "gi/embree_tracer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include <embree3/rtcore.h>

namespace kiln::test {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kInf = std::numeric_limits<float>::infinity();

// SplitMix64: a stream per pixel and sample.
struct Random {
    uint64_t state;
    float next() {
        uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        return float(z >> 40) * (1.0f / 16777216.0f);
    }
};

struct Material {
    glm::vec3 albedo{1.0f}, emission{0.0f};
};

struct Scene {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<Material> materialOf;  // per triangle
    ~Scene() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

glm::vec3 cosineSample(glm::vec3 n, Random& rng) {
    const float u = rng.next(), v = rng.next();
    const float r = std::sqrt(u), phi = 2.0f * kPi * v;
    const glm::vec3 a = std::abs(n.x) > 0.5f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 t = glm::normalize(glm::cross(a, n)), b = glm::cross(n, t);
    return glm::normalize(t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1.0f - u)));
}

struct Hit {
    float t = kInf;
    unsigned triangle = 0;
    glm::vec3 normal{0.0f};  // unit, facing the ray's origin
};

bool intersect(const Scene& s, glm::vec3 o, glm::vec3 d, Hit& hit) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh{};
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f, rh.ray.tfar = kInf, rh.ray.mask = 0xFFFFFFFFu;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(s.scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = rh.ray.tfar;
    hit.triangle = rh.hit.primID;
    glm::vec3 n = glm::normalize(glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
    hit.normal = glm::dot(n, d) > 0.0f ? -n : n;
    return true;
}

bool occluded(const Scene& s, glm::vec3 o, glm::vec3 d, float tFar) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray{};
    ray.org_x = o.x, ray.org_y = o.y, ray.org_z = o.z;
    ray.dir_x = d.x, ray.dir_y = d.y, ray.dir_z = d.z;
    ray.tnear = 0.0f, ray.tfar = tFar, ray.mask = 0xFFFFFFFFu;
    rtcOccluded1(s.scene, &context, &ray);
    return ray.tfar < 0.0f;
}

// KHR_lights_punctual's irradiance at p on a surface facing the light: the direction to
// it, its distance and the irradiance.
glm::vec3 punctual(const model::Light& light, glm::vec3 p, glm::vec3& l, float& dist) {
    const glm::vec3 color = light.color * light.intensity;
    if (light.type == model::Light::Type::Directional) {
        l = -light.direction, dist = kInf;
        return color;
    }
    const glm::vec3 toLight = light.position - p;
    const float d2 = glm::dot(toLight, toLight);
    dist = std::sqrt(d2), l = toLight / dist;
    float falloff = 1.0f / d2;
    if (light.range > 0.0f) {
        const float r = dist / light.range;
        const float w = std::clamp(1.0f - r * r * r * r, 0.0f, 1.0f);
        falloff *= w * w;
    }
    if (light.type == model::Light::Type::Spot) {
        const float cosOuter = std::cos(light.outerCone), cosInner = std::cos(light.innerCone);
        const float t = std::clamp((glm::dot(-l, light.direction) - cosOuter) / std::max(cosInner - cosOuter, 1e-4f),
                                   0.0f, 1.0f);
        falloff *= t * t;
    }
    return color * falloff;
}

glm::vec3 tracePath(const Scene& s, const model::Model& m, glm::vec3 o, glm::vec3 d, const CpuTraceSettings& settings,
                    Random& rng) {
    glm::vec3 total(0.0f), throughput(1.0f);
    for (int depth = 0; depth <= settings.maxBounces; ++depth) {
        Hit h;
        if (!intersect(s, o, d, h)) break;
        const glm::vec3 p = o + h.t * d;
        const Material& mat = s.materialOf[h.triangle];
        total += throughput * mat.emission;
        if (mat.albedo == glm::vec3(0.0f) || depth == settings.maxBounces) break;
        const float scale = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z), 1.0f});
        const glm::vec3 start = p + h.normal * (1e-4f * scale);
        if (!m.lights.empty()) {
            const size_t k = std::min(m.lights.size() - 1, size_t(rng.next() * float(m.lights.size())));
            glm::vec3 l;
            float dist;
            const glm::vec3 e = punctual(m.lights[k], p, l, dist);
            const float cosine = glm::dot(h.normal, l);
            if (cosine > 0.0f && !occluded(s, start, l, dist))
                total += throughput * mat.albedo / kPi * e * cosine * float(m.lights.size());
        }
        d = cosineSample(h.normal, rng);
        o = start;
        throughput *= mat.albedo;
        if (depth >= settings.rouletteStart) {
            const float keep = std::clamp(std::max({throughput.r, throughput.g, throughput.b}), 0.05f, 1.0f);
            if (rng.next() >= keep) break;
            throughput /= keep;
        }
    }
    return total;
}

}  // namespace

bool traceWithEmbree(const model::Model& model, const CpuTraceSettings& settings, FloatImage& out, std::string& error) {
    Scene s;
    s.device = rtcNewDevice(nullptr);
    if (!s.device) return error = "Embree: no device", false;
    s.scene = rtcNewScene(s.device);
    std::vector<glm::vec3> vertices;
    std::vector<uint32_t> indices;
    for (const model::Instance& inst : model.instances) {
        const model::Mesh& mesh = model.meshes[size_t(inst.mesh)];
        const uint32_t base = uint32_t(vertices.size());
        for (const model::Vertex& v : mesh.vertices) vertices.push_back(glm::vec3(inst.transform * glm::vec4(v.position, 1)));
        Material mat;
        if (mesh.material >= 0) {
            const model::Material& src = model.materials[size_t(mesh.material)];
            mat.albedo = glm::vec3(src.baseColorFactor);
            mat.emission = src.emissiveFactor * src.emissiveStrength;
        }
        for (uint32_t i : mesh.indices) indices.push_back(base + i);
        s.materialOf.insert(s.materialOf.end(), mesh.indices.size() / 3, mat);
    }
    RTCGeometry geometry = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), vertices.size()));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), indices.size() / 3));
    if (!v || !t) return error = "Embree: no buffers", rtcReleaseGeometry(geometry), false;
    for (size_t i = 0; i < vertices.size(); ++i) v[3 * i] = vertices[i].x, v[3 * i + 1] = vertices[i].y, v[3 * i + 2] = vertices[i].z;
    std::copy(indices.begin(), indices.end(), t);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(s.scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(s.scene);
    if (rtcGetDeviceError(s.device) != RTC_ERROR_NONE) return error = "Embree: the scene did not build", false;

    out.width = settings.width, out.height = settings.height, out.channels = 4;
    out.pixels.assign(size_t(out.width) * size_t(out.height) * 4, 0.0f);
    auto rows = [&](int first, int step) {
        for (int y = first; y < settings.height; y += step)
            for (int x = 0; x < settings.width; ++x) {
                glm::vec3 sum(0.0f);
                for (int k = 0; k < settings.samples; ++k) {
                    Random rng{(uint64_t(settings.seed) << 40) ^ (uint64_t(y * settings.width + x) << 20) ^ uint64_t(k)};
                    const glm::vec2 ndc = (glm::vec2(x, y) + glm::vec2(rng.next(), rng.next())) /
                                              glm::vec2(settings.width, settings.height) * 2.0f - 1.0f;
                    const glm::vec4 near = settings.invViewProj * glm::vec4(ndc, -1.0f, 1.0f);
                    const glm::vec4 far = settings.invViewProj * glm::vec4(ndc, 1.0f, 1.0f);
                    const glm::vec3 o = glm::vec3(near) / near.w;
                    sum += tracePath(s, model, o, glm::normalize(glm::vec3(far) / far.w - o), settings, rng);
                }
                float* px = out.at(x, y);
                const glm::vec3 mean = sum / float(settings.samples);
                px[0] = mean.r, px[1] = mean.g, px[2] = mean.b, px[3] = float(settings.samples);
            }
    };
    const int threads = int(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (int i = 0; i < threads; ++i) pool.emplace_back(rows, i, threads);
    for (std::thread& th : pool) th.join();
    return true;
}

}  // namespace kiln::test
